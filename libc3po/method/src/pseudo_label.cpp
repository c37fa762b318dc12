#include "c3po/method/pseudo_label.hpp"

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

PseudoLabelCheck CheckPseudoLabel(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                  const PipelineOptions& pipeline, const PseudoLabelOptions& options,
                                  const PrincipalFrame& frame) {
  PseudoLabelCheck check;
  check.residual = FitResidual(object, cloud, estimate.scene_from_model);
  if (!options.check_ambiguity || !estimate.ok()) return check;
  const double eps_oc = pipeline.certificate.eps_oc;
  const std::vector<std::pair<int, double>> half_turns = {{0, M_PI}, {1, M_PI}, {2, M_PI}};
  // This rule judges rivals by exactly oc_m (no slack: the residual ratio
  // below is its own margin).
  PipelineOptions exact = pipeline;
  exact.certificate.global.rival_extra_fraction = 0.0;
  exact.certificate.global.rival_extra_min = 0;
  for (const RivalFit& rival : RefineRivals(object, cloud, estimate, exact, frame, half_turns)) {
    if (!rival.ok) continue;
    if (rival.keypoint_distance <= eps_oc) continue;   // the same basin
    const double residual = FitResidual(object, cloud, rival.scene_from_model);
    if (check.rival_residual < 0 || residual < check.rival_residual) {
      check.rival_residual = residual;
      check.rival_passes_oc = rival.passes_oc;
      check.rival_keypoint_distance = rival.keypoint_distance;
      check.rival_axis = rival.axis;
    }
    if (rival.passes_oc || residual <= options.residual_ratio * check.residual) {
      check.ambiguous = true;
    }
  }
  return check;
}

}  // namespace c3po
