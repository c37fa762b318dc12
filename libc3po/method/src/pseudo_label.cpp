#include "c3po/method/pseudo_label.hpp"

#include <cmath>
#include <stdexcept>

namespace c3po {

void PseudoLabelOptions::Check() const {
  if (!(residual_ratio >= 1.0 && std::isfinite(residual_ratio))) {
    throw std::invalid_argument("ambiguity residual ratio must be >= 1");
  }
  if (!std::isfinite(symmetry_tolerance)) throw std::invalid_argument("symmetry tolerance must be finite");
  for (const Pose& symmetry : model_symmetries) {
    if (!symmetry.IsFinite()) throw std::invalid_argument("model symmetries must be finite");
  }
}

double PseudoLabelOptions::SymmetryTolerance(double eps_oc) const {
  return symmetry_tolerance >= 0.0 ? symmetry_tolerance : 0.25 * eps_oc;
}

const PointSet& NearestLabelling(const PointSet& detected, const PointSet& chosen, const std::vector<PointSet>& others) {
  const PointSet* nearest = &chosen;
  double best = (detected - chosen).squaredNorm();
  for (const PointSet& labelling : others) {
    const double distance = (detected - labelling).squaredNorm();
    if (distance < best) {
      best = distance;
      nearest = &labelling;
    }
  }
  return *nearest;
}

double FitResidual(const ObjectModel& object, const PointSet& cloud, const Pose& scene_from_model) {
  if (cloud.cols() == 0) return 0.0;
  const Eigen::VectorXd distances = object.DistancesToPosedModel(cloud, scene_from_model);
  return std::sqrt(distances.squaredNorm() / static_cast<double>(distances.size()));
}

PseudoLabelCheck CheckPseudoLabel(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                  const PipelineOptions& pipeline, const PseudoLabelOptions& options,
                                  const PrincipalFrame& frame, const RivalFilter* observation) {
  PseudoLabelCheck check;
  check.residual = FitResidual(object, cloud, estimate.scene_from_model);
  if (options.symmetry_aware && estimate.ok()) {
    for (const Pose& symmetry : options.model_symmetries) {
      check.symmetric_labellings.push_back((estimate.scene_from_model * symmetry) * object.keypoints());
    }
  }
  if (!options.check_ambiguity || !estimate.ok()) return check;
  const double eps_oc = pipeline.certificate.eps_oc;
  const double symmetry_tolerance = options.SymmetryTolerance(eps_oc);
  const PointSet queries = StridedColumns(object.sample(), 1000);
  const std::vector<std::pair<int, double>> half_turns = {{0, M_PI}, {1, M_PI}, {2, M_PI}};
  // This rule judges rivals by exactly oc_m (no slack: the residual ratio
  // below is its own margin).
  PipelineOptions exact = pipeline;
  exact.certificate.global.rival_extra_fraction = 0.0;
  exact.certificate.global.rival_extra_min = 0;
  Pose reported;   // the reported rival's pose (its surface distance is measured once, below)
  for (const RivalFit& rival : RefineRivals(object, cloud, estimate, exact, frame, half_turns)) {
    if (!rival.ok) continue;
    if (rival.keypoint_distance <= eps_oc) continue;   // the same basin
    int violations = -1;
    if (observation != nullptr && !observation->Passes(rival.scene_from_model, &violations)) {
      ++check.rivals_refuted;   // the frame rules this basin out
      continue;
    }
    if (options.symmetry_aware && rival.passes_oc &&
        PosedSurfaceHausdorff(object, queries, estimate.scene_from_model, rival.scene_from_model) <=
            symmetry_tolerance) {
      // The same shape placed by other keypoints: a symmetric labelling.
      check.symmetric_labellings.push_back(rival.keypoints);
      continue;
    }
    const double residual = FitResidual(object, cloud, rival.scene_from_model);
    if (check.rival_residual < 0 || residual < check.rival_residual) {
      check.rival_residual = residual;
      check.rival_passes_oc = rival.passes_oc;
      check.rival_keypoint_distance = rival.keypoint_distance;
      check.rival_axis = rival.axis;
      reported = rival.scene_from_model;
    }
    if (rival.passes_oc || residual <= options.residual_ratio * check.residual) {
      check.ambiguous = true;
    }
  }
  if (check.ambiguous) {
    check.rival_surface_distance = PosedSurfaceHausdorff(object, queries, estimate.scene_from_model, reported);
  }
  return check;
}

}  // namespace c3po
