#include "c3po/method/certificate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "c3po/method/auto_threshold.hpp"
#include "c3po/base/error.hpp"

namespace c3po {

int OutlierBudget::Resolve(Eigen::Index points) const {
  if (fraction > 0.0) return static_cast<int>(std::floor(fraction * static_cast<double>(points) + 1e-9));
  return count;
}

std::string OutlierBudget::ToString() const {
  if (fraction > 0.0) {
    char text[64];
    std::snprintf(text, sizeof text, "%g%%", 100.0 * fraction);
    return text;
  }
  return std::to_string(count);
}

void OutlierBudget::Check() const {
  if (count < 0) throw std::invalid_argument("max_outliers count must be >= 0");
  if (!(std::isfinite(fraction) && fraction >= 0.0 && fraction < 1.0)) {
    throw std::invalid_argument("max_outliers fraction must be in [0, 1)");
  }
  if (count > 0 && fraction > 0.0) throw std::invalid_argument("max_outliers: a count or a fraction, not both");
}

OutlierBudget ParseOutlierBudget(const std::string& text) {
  auto fail = [&]() -> OutlierBudget {
    throw InputError("--max-outliers", "'" + text + "' must be a count (10) or a percentage below 100 (2%)");
  };
  if (text.empty()) return fail();
  OutlierBudget budget;
  const bool percent = text.back() == '%';
  const std::string number = percent ? text.substr(0, text.size() - 1) : text;
  if (number.empty() || number.find_first_not_of("0123456789.") != std::string::npos) return fail();
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(number, &used);
  } catch (const std::exception&) {
    return fail();
  }
  if (used != number.size() || !std::isfinite(value) || value < 0) return fail();
  if (percent) {
    if (!(value < 100.0)) return fail();
    budget.fraction = value / 100.0;
  } else {
    if (value != std::floor(value) || value > 1e9) return fail();
    budget.count = static_cast<int>(value);
  }
  return budget;
}

void CertificateOptions::Check() const {
  if (!(std::isfinite(eps_oc) && eps_oc > 0)) throw std::invalid_argument("eps_oc must be > 0");
  if (!(std::isfinite(delta_nd) && delta_nd > 0)) throw std::invalid_argument("delta_nd must be > 0");
  max_outliers.Check();
  local.Check();
  global.Check();
  free_space.Check();
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

// The oc_m decision and its outlier evidence from the per-point distances
// (they do not depend on eps_oc: `--eps-oc auto` decides again with this).
void RethresholdObservableCorrectness(ObservableCorrectness* oc, double eps_oc, bool check_keypoint_agreement) {
  oc->eps_oc = eps_oc;
  oc->outlier_indices.clear();
  oc->max_inlier_distance = 0.0;
  const Eigen::VectorXd& d = oc->point_distances;
  for (Eigen::Index j = 0; j < d.size(); ++j) {
    if (d(j) < eps_oc) {
      oc->max_inlier_distance = std::max(oc->max_inlier_distance, d(j));
    } else {
      oc->outlier_indices.push_back(static_cast<int>(j));   // NaN is never accepted
    }
  }
  oc->outlier_count = static_cast<int>(oc->outlier_indices.size());
  oc->points_passed = d.size() > 0 && oc->outlier_count <= oc->max_outliers;
  oc->keypoints_passed = !check_keypoint_agreement || oc->max_keypoint_distance < eps_oc;
  oc->passed = oc->points_passed && oc->keypoints_passed;
}

ObservableCorrectness CheckObservableCorrectness(const ObjectModel& object, const PointSet& cloud,
                                                 const Pose& scene_from_model,
                                                 const PointSet& corrected_keypoints,
                                                 const CertificateOptions& options) {
  options.Check();
  ObservableCorrectness oc;
  oc.eps_oc = options.eps_oc;
  oc.max_outliers = options.max_outliers.Resolve(cloud.cols());
  if (cloud.cols() == 0 || !cloud.allFinite() || !scene_from_model.IsFinite()) {
    oc.max_point_distance = std::numeric_limits<double>::infinity();
    oc.budget_distance = oc.max_point_distance;
    return oc;
  }
  Eigen::VectorXd squared;
  object.NearestInPosedModel(cloud, scene_from_model, &oc.nearest_model_point, &squared);
  oc.point_distances = squared.cwiseSqrt();
  Eigen::Index worst = 0;
  oc.max_point_distance = oc.point_distances.maxCoeff(&worst);
  oc.worst_point = static_cast<int>(worst);
  std::vector<double> sorted(oc.point_distances.data(), oc.point_distances.data() + oc.point_distances.size());
  oc.quantile50 = SampleQuantile(sorted, 0.5);
  oc.quantile90 = SampleQuantile(sorted, 0.9);
  oc.quantile99 = SampleQuantile(sorted, 0.99);
  if (oc.max_outliers >= static_cast<int>(sorted.size())) {
    oc.budget_distance = 0.0;
  } else {
    std::nth_element(sorted.begin(), sorted.end() - 1 - oc.max_outliers, sorted.end());
    oc.budget_distance = *(sorted.end() - 1 - oc.max_outliers);
  }
  const PointSet posed_keypoints = scene_from_model * object.keypoints();
  if (corrected_keypoints.cols() == posed_keypoints.cols()) {
    oc.max_keypoint_distance = (corrected_keypoints - posed_keypoints).colwise().norm().maxCoeff();
  } else {
    oc.max_keypoint_distance = std::numeric_limits<double>::infinity();
  }
  RethresholdObservableCorrectness(&oc, options.eps_oc, options.check_keypoint_agreement);
  return oc;
}

NonDegeneracy CheckNonDegeneracy(const ObjectModel& object, const PointSet& cloud,
                                 const Pose& scene_from_model, const ObservableCorrectness& oc,
                                 const CertificateOptions& options) {
  options.Check();
  NonDegeneracy nd;
  nd.delta_nd = options.delta_nd;
  nd.max_outliers = oc.max_outliers;
  const PointSet posed_keypoints = scene_from_model * object.keypoints();
  nd.keypoint_distances = DistancesToCloud(posed_keypoints, cloud);
  // Accepted points: within eps_oc of the posed model (oc_m's inliers).
  std::vector<char> accepted(cloud.cols(), 0);
  if (oc.point_distances.size() == cloud.cols()) {
    for (Eigen::Index j = 0; j < cloud.cols(); ++j) accepted[j] = oc.point_distances(j) < oc.eps_oc;
  }
  // Support of each posed keypoint: points within delta_nd (accepted ones for m > 0).
  const double delta2 = options.delta_nd * options.delta_nd;
  nd.keypoint_support.assign(object.num_keypoints(), 0);
  for (int i = 0; i < object.num_keypoints(); ++i) {
    for (Eigen::Index j = 0; j < cloud.cols(); ++j) {
      if (nd.max_outliers > 0 && !accepted[j]) continue;
      if ((cloud.col(j) - posed_keypoints.col(i)).squaredNorm() < delta2) ++nd.keypoint_support[i];
    }
  }
  static const std::vector<std::vector<int>> kNoSets;
  const auto& sets = options.use_indicator_sets ? object.spec().indicator_sets : kNoSets;
  nd.sets_used = !sets.empty();
  for (std::size_t s = 0; s < sets.size(); ++s) {
    double worst = 0.0;
    int support = std::numeric_limits<int>::max();
    for (int index : sets[s]) {
      worst = std::max(worst, nd.keypoint_distances(index));
      support = std::min(support, nd.keypoint_support[index]);
    }
    if (sets[s].empty()) support = 0;
    nd.set_worst_distance.push_back(worst);
    nd.set_min_support.push_back(support);
    // m = 0: the paper's eq. 21 verbatim (every keypoint within delta_nd of X).
    const bool passes = nd.max_outliers == 0 ? worst < options.delta_nd : !sets[s].empty() && support > nd.max_outliers;
    if (passes && nd.passing_set < 0) nd.passing_set = static_cast<int>(s);
  }
  nd.sets_passed = sets.empty() ? cloud.cols() > 0 : nd.passing_set >= 0;
  bool local_ok = true;
  if (options.local_nondegeneracy) {
    nd.local_checked = true;
    if (oc.nearest_model_point.size() == cloud.cols()) {
      nd.local = CheckLocalNonDegeneracy(object, oc.nearest_model_point, accepted, nd.max_outliers, options.local);
    }
    local_ok = nd.local.passed;
  }
  nd.passed = nd.sets_passed && local_ok;
  return nd;
}

NonDegeneracy CheckNonDegeneracy(const ObjectModel& object, const PointSet& cloud,
                                 const Pose& scene_from_model, const CertificateOptions& options) {
  CertificateOptions no_keypoints = options;
  no_keypoints.check_keypoint_agreement = false;
  const ObservableCorrectness oc =
      CheckObservableCorrectness(object, cloud, scene_from_model, scene_from_model * object.keypoints(), no_keypoints);
  return CheckNonDegeneracy(object, cloud, scene_from_model, oc, options);
}

Certificate Certify(const ObjectModel& object, const PointSet& cloud, const Pose& scene_from_model,
                    const PointSet& corrected_keypoints, const CertificateOptions& options) {
  Certificate certificate;
  certificate.oc = CheckObservableCorrectness(object, cloud, scene_from_model, corrected_keypoints, options);
  certificate.nd = CheckNonDegeneracy(object, cloud, scene_from_model, certificate.oc, options);
  return certificate;
}

}  // namespace c3po
