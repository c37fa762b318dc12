#include "c3po/method/certificate.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace c3po {

void CertificateOptions::Check() const {
  if (!(std::isfinite(eps_oc) && eps_oc > 0)) throw std::invalid_argument("eps_oc must be > 0");
  if (!(std::isfinite(delta_nd) && delta_nd > 0)) throw std::invalid_argument("delta_nd must be > 0");
}

CertificateOptions CertificateOptions::FromObject(const ObjectSpec& spec) {
  CertificateOptions options;
  options.eps_oc = spec.eps_oc;
  options.delta_nd = spec.delta_nd;
  return options;
}

Eigen::VectorXd DistancesToCloud(const PointSet& queries, const PointSet& cloud) {
  Eigen::VectorXd distances(queries.cols());
  for (Eigen::Index i = 0; i < queries.cols(); ++i) {
    distances(i) = cloud.cols() == 0
                       ? std::numeric_limits<double>::infinity()
                       : std::sqrt((cloud.colwise() - queries.col(i)).colwise().squaredNorm().minCoeff());
  }
  return distances;
}

ObservableCorrectness CheckObservableCorrectness(const ObjectModel& object, const PointSet& cloud,
                                                 const Pose& scene_from_model,
                                                 const PointSet& corrected_keypoints,
                                                 const CertificateOptions& options) {
  options.Check();
  ObservableCorrectness oc;
  oc.eps_oc = options.eps_oc;
  if (cloud.cols() == 0 || !cloud.allFinite() || !scene_from_model.IsFinite()) {
    oc.max_point_distance = std::numeric_limits<double>::infinity();
    return oc;
  }
  oc.point_distances = object.DistancesToPosedModel(cloud, scene_from_model);
  Eigen::Index worst = 0;
  oc.max_point_distance = oc.point_distances.maxCoeff(&worst);
  oc.worst_point = static_cast<int>(worst);
  const PointSet posed_keypoints = scene_from_model * object.keypoints();
  if (corrected_keypoints.cols() == posed_keypoints.cols()) {
    oc.max_keypoint_distance = (corrected_keypoints - posed_keypoints).colwise().norm().maxCoeff();
  } else {
    oc.max_keypoint_distance = std::numeric_limits<double>::infinity();
  }
  oc.passed = oc.max_point_distance < options.eps_oc &&
              (!options.check_keypoint_agreement || oc.max_keypoint_distance < options.eps_oc);
  return oc;
}

NonDegeneracy CheckNonDegeneracy(const ObjectModel& object, const PointSet& cloud,
                                 const Pose& scene_from_model, const CertificateOptions& options) {
  options.Check();
  NonDegeneracy nd;
  nd.delta_nd = options.delta_nd;
  const PointSet posed_keypoints = scene_from_model * object.keypoints();
  nd.keypoint_distances = DistancesToCloud(posed_keypoints, cloud);
  const auto& sets = object.spec().indicator_sets;
  if (sets.empty()) {
    nd.passed = cloud.cols() > 0;
    return nd;
  }
  for (std::size_t s = 0; s < sets.size(); ++s) {
    double worst = 0.0;
    for (int index : sets[s]) worst = std::max(worst, nd.keypoint_distances(index));
    nd.set_worst_distance.push_back(worst);
    if (worst < options.delta_nd && nd.passing_set < 0) nd.passing_set = static_cast<int>(s);
  }
  nd.passed = nd.passing_set >= 0;
  return nd;
}

Certificate Certify(const ObjectModel& object, const PointSet& cloud, const Pose& scene_from_model,
                    const PointSet& corrected_keypoints, const CertificateOptions& options) {
  Certificate certificate;
  certificate.oc = CheckObservableCorrectness(object, cloud, scene_from_model, corrected_keypoints, options);
  certificate.nd = CheckNonDegeneracy(object, cloud, scene_from_model, options);
  return certificate;
}

}  // namespace c3po
