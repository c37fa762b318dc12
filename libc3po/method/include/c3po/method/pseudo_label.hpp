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
#include "c3po/method/global_uniqueness.hpp"
#include "c3po/method/pipeline.hpp"

namespace c3po {

struct PseudoLabelOptions {
  bool check_ambiguity = true;
  double residual_ratio = 1.25;   // rival RMS residual <= ratio * chosen => near-equal
  void Check() const;             // ratio >= 1 and finite
};

struct PseudoLabelCheck {
  bool ambiguous = false;
  double residual = 0.0;             // RMS distance of the input points to T̂·B̂
  double rival_residual = -1.0;      // best distinct second basin (-1: none found)
  bool rival_passes_oc = false;
  double rival_keypoint_distance = 0.0;   // max_i ||y*_i - y'_i|| of that rival
  int rival_axis = -1;               // principal axis (0 = largest extent) of the flip
};

// RMS distance of the cloud's points to the model sample posed by `pose`.
double FitResidual(const ObjectModel& object, const PointSet& cloud, const Pose& scene_from_model);

// `estimate` must be ok(); with check_ambiguity false only `residual` is filled.
PseudoLabelCheck CheckPseudoLabel(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                  const PipelineOptions& pipeline, const PseudoLabelOptions& options,
                                  const PrincipalFrame& frame);

}  // namespace c3po
