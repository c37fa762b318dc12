#pragma once
// Is a certified output a usable pseudo-label? (self-training, method.md
// "Self-training: ambiguous pseudo-labels"). The oc certificate (paper eq. 19)
// only says that the posed model explains the cloud within eps_oc; for a flat,
// nearly two-fold symmetric object the pose turned by pi about a principal
// axis explains it too, with keypoints far from the chosen ones. Such a
// sample does not identify its keypoints, and regressing the detector onto
// whichever basin the corrector fell into teaches it the flip.
//
// Rule: from the certified pose T̂ the corrector is restarted at the three
// half-turns T̂·F_a (F_a = rotation by pi about principal axis a of B̂,
// through its centroid; RefineRivals, global_uniqueness.hpp, the one home of
// the rival restarts). A rival fit whose corrected keypoints differ from
// y* by more than eps_oc is a second basin; the sample is ambiguous when a
// second basin passes the oc certificate itself, or fits with an RMS residual
// (input points to posed model) within residual_ratio of the chosen one, or
// fits better than it.
//
// Symmetric labellings (method.md "Self-training: symmetric labellings"): a
// second basin that passes oc and whose posed model lies within
// symmetry_tolerance of the chosen one (PosedSurfaceHausdorff of T̂·B̂ and
// T'·B̂: to the surface, free of the sampling floor) places the same shape: a symmetry of the model, not a second
// explanation. It does not make the sample ambiguous; its keypoints are
// another correct labelling, and the sample is trained on with the
// symmetry-aware loss min_j ||ỹ - y_j||² over its labellings (the step's
// target is the labelling nearest the detection, NearestLabelling). The
// object's known symmetries (model_symmetries) add T̂·S·b to every sample's
// labellings, so that every sample of a symmetric object is trained with the
// same loss (a sample trained on y* alone would pull toward the average).
#include <vector>

#include "c3po/method/global_uniqueness.hpp"
#include "c3po/method/pipeline.hpp"

namespace c3po {

struct PseudoLabelOptions {
  bool check_ambiguity = true;
  double residual_ratio = 1.25;   // rival RMS residual <= ratio * chosen => near-equal
  bool symmetry_aware = true;     // symmetric labellings are trained on (min over labellings), not refused
  double symmetry_tolerance = -1.0;   // object units; < 0: SymmetryTolerance() = eps_oc / 4
  // The object's known symmetries (model_from_model, FindModelSymmetries):
  // with symmetry_aware, T̂·S·b is a labelling of every certified sample,
  // whether or not a rival fit lands in that basin.
  std::vector<Pose> model_symmetries;
  void Check() const;             // ratio >= 1 and finite; tolerance finite
  // The tolerance in force for a certificate's eps_oc.
  double SymmetryTolerance(double eps_oc) const;
};

struct PseudoLabelCheck {
  bool ambiguous = false;
  double residual = 0.0;             // RMS distance of the input points to T̂·B̂
  double rival_residual = -1.0;      // best distinct second basin (-1: none found)
  bool rival_passes_oc = false;
  double rival_keypoint_distance = 0.0;   // max_i ||y*_i - y'_i|| of that rival
  int rival_axis = -1;               // principal axis (0 = largest extent) of the flip
  // PosedSurfaceHausdorff of T̂·B̂ and that rival's posed model, measured
  // when the sample is ambiguous (-1 otherwise):
  // how far from a symmetry the second basin is. An object whose certified
  // samples are all ambiguous at a small surface distance may be symmetric
  // within it (then --symmetry-tolerance declares it).
  double rival_surface_distance = -1.0;
  int rivals_refuted = 0;            // second basins the cloud's frame refutes (free space)
  // Keypoints of the second basins that pass oc within the symmetry
  // tolerance of the chosen pose (symmetry_aware only): y* and these are the
  // sample's labellings.
  std::vector<PointSet> symmetric_labellings;
};

// The target of one step of the symmetry-aware loss min_j ||ỹ - y_j||²: the
// labelling (`chosen` or one of `others`) nearest the detection `detected`
// (ties keep the earlier; `chosen` first). Its gradient at the current
// weights is the regression onto that labelling.
const PointSet& NearestLabelling(const PointSet& detected, const PointSet& chosen, const std::vector<PointSet>& others);

// RMS distance of the cloud's points to the model sample posed by `pose`.
double FitResidual(const ObjectModel& object, const PointSet& cloud, const Pose& scene_from_model);

// `estimate` must be ok(); with check_ambiguity false only `residual` is filled.
// `observation`: the cloud's free-space test (depth-frame inputs), else
// nullptr; a second basin it refutes (the camera saw through where that pose
// puts the model) is no second explanation and does not make the sample
// ambiguous.
PseudoLabelCheck CheckPseudoLabel(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                  const PipelineOptions& pipeline, const PseudoLabelOptions& options,
                                  const PrincipalFrame& frame, const RivalFilter* observation = nullptr);

}  // namespace c3po
