#include "c3po/method/pseudo_label.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>

namespace c3po {

void PseudoLabelOptions::Check() const {
  if (!(residual_ratio >= 1.0 && std::isfinite(residual_ratio))) {
    throw std::invalid_argument("ambiguity residual ratio must be >= 1");
  }
}

double FitResidual(const ObjectModel& object, const PointSet& cloud, const Pose& scene_from_model) {
  if (cloud.cols() == 0) return 0.0;
  const Eigen::VectorXd distances = object.DistancesToPosedModel(cloud, scene_from_model);
  return std::sqrt(distances.squaredNorm() / static_cast<double>(distances.size()));
}

PrincipalFrame ModelPrincipalFrame(const ObjectModel& object) {
  const PointSet& sample = object.sample();
  PrincipalFrame frame;
  frame.centroid = sample.rowwise().mean();
  const PointSet centred = sample.colwise() - frame.centroid;
  const Eigen::Matrix3d covariance = centred * centred.transpose() / std::max<double>(1.0, sample.cols());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  // Eigen sorts eigenvalues increasingly; axis 0 = largest extent.
  for (int a = 0; a < 3; ++a) frame.axes.col(a) = solver.eigenvectors().col(2 - a);
  return frame;
}

Pose HalfTurn(const PrincipalFrame& frame, int axis) {
  const Eigen::Vector3d u = frame.axes.col(axis).normalized();
  // Rotation by pi about u: 2 u u^T - I.
  Pose flip;
  flip.R = 2.0 * u * u.transpose() - Eigen::Matrix3d::Identity();
  flip.t = frame.centroid - flip.R * frame.centroid;
  return flip;
}

PseudoLabelCheck CheckPseudoLabel(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                  const PipelineOptions& pipeline, const PseudoLabelOptions& options,
                                  const PrincipalFrame& frame) {
  PseudoLabelCheck check;
  check.residual = FitResidual(object, cloud, estimate.scene_from_model);
  if (!options.check_ambiguity || !estimate.ok()) return check;
  const double eps_oc = pipeline.certificate.eps_oc;
  for (int axis = 0; axis < 3; ++axis) {
    const Pose start = estimate.scene_from_model * HalfTurn(frame, axis);
    PipelineOptions rival_options = pipeline;
    rival_options.correct = true;   // a second basin is where the corrector settles from the flip
    const PoseEstimate rival = EstimateAndCertify(object, cloud, start * object.keypoints(), rival_options);
    if (!rival.ok()) continue;
    const double keypoint_distance = (rival.keypoints - estimate.keypoints).colwise().norm().maxCoeff();
    if (keypoint_distance <= eps_oc) continue;   // the same basin
    const double residual = FitResidual(object, cloud, rival.scene_from_model);
    if (check.rival_residual < 0 || residual < check.rival_residual) {
      check.rival_residual = residual;
      check.rival_passes_oc = rival.certificate.oc.passed;
      check.rival_keypoint_distance = keypoint_distance;
      check.rival_axis = axis;
    }
    if (rival.certificate.oc.passed || residual <= options.residual_ratio * check.residual) {
      check.ambiguous = true;
    }
  }
  return check;
}

}  // namespace c3po
