// The JSON lines of `c3po certify` (schema in certify_batch.hpp).
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "c3po/base/json.hpp"
#include "c3po/method/certify_batch.hpp"
#include "c3po/method/refusal.hpp"

namespace c3po {
namespace {

nlohmann::ordered_json FiniteOrNull(double value) {
  return std::isfinite(value) ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr);
}

nlohmann::ordered_json RotationJson(const Eigen::Matrix3d& R) {
  return {{R(0, 0), R(0, 1), R(0, 2)}, {R(1, 0), R(1, 1), R(1, 2)}, {R(2, 0), R(2, 1), R(2, 2)}};
}

// "cloud", then the provenance keys of image inputs.
nlohmann::ordered_json SourceKeys(const CloudSource& source, const CloudOutcome& outcome) {
  nlohmann::ordered_json line;
  line["cloud"] = source.name;
  if (source.provenance) {
    const CloudProvenance& p = *source.provenance;
    line["scene_id"] = p.scene_id;
    line["im_id"] = p.im_id;
    line["gt_id"] = p.gt_id;
    line["obj_id"] = p.obj_id;
    if (p.detection_score) line["detection_score"] = *p.detection_score;
  }
  if (outcome.segment) {
    const SegmentCloud& s = *outcome.segment;
    line["pixels"] = s.mask_pixels;
    line["no_depth"] = s.no_depth;
    line["removed_erosion"] = s.removed_by_erosion;
    line["erode_pixels"] = s.erode_pixels;
    line["removed_discontinuity"] = s.removed_by_discontinuity;
    line["removed_plane"] = s.removed_by_plane;
    line["removed_subsampling"] = s.removed_by_subsampling;
    line["points"] = s.pixels.size();
    line["evidence_points"] = s.evidence_points;
  }
  if (source.provenance && source.scene_from_model_truth) {
    const Pose& G = *source.scene_from_model_truth;
    line["gt_R"] = RotationJson(G.R);
    line["gt_t"] = {G.t(0), G.t(1), G.t(2)};
  }
  if (outcome.truth_hausdorff) line["gt_hausdorff"] = FiniteOrNull(*outcome.truth_hausdorff);
  return line;
}

// The pose, the decisions, the paper's evidence, the corrector's and the re-estimation's keys.
void AddPoseAndDecisionKeys(const PoseEstimate& e, nlohmann::ordered_json* out) {
  nlohmann::ordered_json& line = *out;
  const Pose& T = e.scene_from_model;
  SetPoseJson(T, &line);
  line["keypoints"] = PointsToJson(e.keypoints);
  line["oc"] = e.certificate.oc.passed;
  line["nd"] = e.certificate.nd.passed;
  line["certified"] = e.certified();
  line["refused_by"] = RefusedByNames(e);
  line["oc_distance"] = FiniteOrNull(e.certificate.oc.max_point_distance);
  line["keypoint_distance"] = e.certificate.oc.max_keypoint_distance;
  line["nd_set"] = e.certificate.nd.passing_set;
  line["nd_set_distances"] = e.certificate.nd.set_worst_distance;
  line["eps_oc"] = e.certificate.oc.eps_oc;
  line["delta_nd"] = e.certificate.nd.delta_nd;
  line["iterations"] = e.correction.iterations;
  line["cost_before"] = FiniteOrNull(e.correction.cost_before);
  line["cost_after"] = FiniteOrNull(e.correction.cost_after);
  line["status"] = ToString(e.correction.registration);
  // Re-estimation (GlobalUniquenessOptions::reestimate): the turn whose restart replaced a refuted estimate.
  line["restarts_tried"] = e.restarts_tried;
  line["restart_axis"] = e.restart_axis;
  line["restart_angle_deg"] = e.restart_angle_deg;
  // Centring (GlobalUniquenessOptions::centre): the pose is the centre of this many fits.
  line["centred"] = e.centred;
  line["centred_fits"] = e.centred_fits;
}

// Outlier-robust evidence (docs/method.md "Outlier-robust certificates"): oc_m and nd_m's support and local test.
void AddRobustKeys(const PoseEstimate& e, nlohmann::ordered_json* out) {
  nlohmann::ordered_json& line = *out;
  const ObservableCorrectness& oc = e.certificate.oc;
  const NonDegeneracy& nd = e.certificate.nd;
  line["max_outliers"] = oc.max_outliers;
  line["robust_loss"] = ToString(e.correction.robust_loss);
  line["robust_scale"] = e.correction.robust_scale;
  line["outliers"] = oc.outlier_count;
  // The share of the judged points the pose leaves unexplained (at >= eps_oc).
  line["unexplained_fraction"] = oc.point_distances.size() > 0
                                     ? nlohmann::ordered_json(static_cast<double>(oc.outlier_count) /
                                                              static_cast<double>(oc.point_distances.size()))
                                     : nlohmann::ordered_json(nullptr);
  const std::size_t listed = std::min(oc.outlier_indices.size(), kMaxListedOutliers);
  line["outlier_indices"] = std::vector<int>(oc.outlier_indices.begin(), oc.outlier_indices.begin() + listed);
  line["outlier_indices_truncated"] = listed < oc.outlier_indices.size();
  line["distance_quantiles"] = {FiniteOrNull(oc.quantile50), FiniteOrNull(oc.quantile90),
                                FiniteOrNull(oc.quantile99), FiniteOrNull(oc.max_point_distance)};
  line["max_inlier_distance"] = oc.max_inlier_distance;
  line["keypoint_support"] = nd.keypoint_support;
  line["nd_set_support"] = nd.set_min_support;
  line["nd_sets"] = nd.sets_passed;
  line["nd_sets_used"] = nd.sets_used;
  line["nd_local"] = nd.local_checked ? nlohmann::ordered_json(nd.local.passed) : nlohmann::ordered_json(nullptr);
  line["nd_local_eigenvalue"] = FiniteOrNull(nd.local.min_eigenvalue);
  line["nd_local_motion"] = {nd.local.motion(0), nd.local.motion(1), nd.local.motion(2),
                             nd.local.motion(3), nd.local.motion(4), nd.local.motion(5)};
  line["nd_local_rank"] = nd.local.model_rank;
  line["nd_local_weak_motions"] = nd.local.weak_motions;
}

// The finite check of a single weak motion (global_uniqueness.hpp); null when not run.
void AddWeakMotionKeys(const NonDegeneracy& nd, nlohmann::ordered_json* out) {
  nlohmann::ordered_json& line = *out;
  const WeakMotionCheck& w = nd.weak_motion;
  line["nd_weak_motion"] = nd.weak_motion_checked ? nlohmann::ordered_json(w.passed) : nlohmann::ordered_json(nullptr);
  line["weak_motion_starts"] = w.starts;
  line["weak_motion_rivals"] = w.rivals_found;
  line["weak_motion_rival_step"] = w.rivals_found > 0 ? nlohmann::ordered_json(w.rival_step) : nlohmann::ordered_json(nullptr);
  line["weak_motion_rival_hausdorff"] =
      w.rivals_found > 0 ? nlohmann::ordered_json(w.rival_hausdorff) : nlohmann::ordered_json(nullptr);
}

// Global rival search (global_uniqueness.hpp); null when not run.
void AddRivalKeys(const PoseEstimate& e, nlohmann::ordered_json* out) {
  nlohmann::ordered_json& line = *out;
  const NonDegeneracy& nd = e.certificate.nd;
  const GlobalUniqueness& g = nd.global;
  line["nd_global"] = nd.global_checked ? nlohmann::ordered_json(g.passed) : nlohmann::ordered_json(nullptr);
  line["rivals_tried"] = g.rivals_tried;
  line["rivals_found"] = g.rivals_found;
  line["rival_distance"] = g.rival_distance;
  // What a certificate promises (docs/method.md "Tolerance"): the truth within rival_distance + eps_oc (+ eps_w)
  // of the pose -- the tolerance; null when not certified or when no rival search ran.
  line["certified_bound"] = e.certified() && nd.global_checked
                                ? nlohmann::ordered_json(g.rival_distance + e.certificate.oc.eps_oc)
                                : nlohmann::ordered_json(nullptr);
  // How many more points the reported rival leaves unexplained than the pose (null: no rival reported).
  line["rival_margin"] = g.rival_axis >= 0 && g.rival_outliers >= 0
                             ? nlohmann::ordered_json(g.rival_outliers - e.certificate.oc.outlier_count)
                             : nlohmann::ordered_json(nullptr);
  line["rival_hausdorff"] = g.rival_axis >= 0 ? nlohmann::ordered_json(g.rival_hausdorff) : nlohmann::ordered_json(nullptr);
  line["rival_outliers"] = g.rival_outliers;
  line["rival_axis"] = g.rival_axis;
  line["rival_angle_deg"] = g.rival_angle_deg;
  line["rival_passes_oc"] = g.rival_passes_oc;
  line["rival_free_space_violations"] = g.rival_free_space_violations;
  line["rival_counts"] = g.rival_counts;
  // The reported rival's pose (scene_from_model, like R and t): the second explanation to look at.
  const Pose& rival = g.rival_scene_from_model;
  line["rival_R"] = g.rival_axis >= 0 ? RotationJson(rival.R) : nlohmann::ordered_json(nullptr);
  line["rival_t"] = g.rival_axis >= 0 ? nlohmann::ordered_json({rival.t(0), rival.t(1), rival.t(2)})
                                      : nlohmann::ordered_json(nullptr);
}

// Free space (depth-image inputs, free_space.hpp); null when not checked.
void AddFreeSpaceKeys(const FreeSpace& f, nlohmann::ordered_json* out) {
  nlohmann::ordered_json& line = *out;
  const auto if_checked = [](bool checked, auto value) {
    return checked ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr);
  };
  line["free_space"] = if_checked(f.checked, f.passed);
  line["free_space_violations"] = f.violations;
  line["free_space_measured"] = f.measured;
  line["free_space_silhouette"] = f.silhouette;
  line["free_space_tolerance"] = f.tolerance;
  line["free_space_limit"] = f.limit;
  line["free_space_shift_px"] = {f.shift_u, f.shift_v};
  line["through_support"] = if_checked(f.support_checked, f.through_support);
  line["seen_surface"] = f.seen_surface;
  line["seen_outside_mask"] = if_checked(f.mask_checked, f.seen_outside_mask);
  line["outside_mask_limit"] = if_checked(f.mask_checked, f.mask_limit);
  line["mask_at_depth"] = if_checked(f.mask_checked, f.mask_at_depth);
  line["mask_uncovered"] = if_checked(f.mask_checked, f.mask_uncovered);
  line["uncovered_mask_limit"] = if_checked(f.mask_checked, f.uncovered_limit);
}

// Identity among known objects (identity_check.hpp); null when not checked.
void AddIdentityKeys(const IdentityCheck& i, nlohmann::ordered_json* out) {
  nlohmann::ordered_json& line = *out;
  const bool rival = !i.rival.empty();
  const nlohmann::ordered_json none(nullptr);
  line["identity"] = i.checked ? nlohmann::ordered_json(i.passed) : none;
  line["identity_objects"] = i.objects_tried;
  line["identity_rival"] = rival ? nlohmann::ordered_json(i.rival) : none;
  line["identity_rival_oc_distance"] = rival ? nlohmann::ordered_json(i.rival_oc_distance) : none;
  const Pose& pose = i.rival_scene_from_model;
  line["identity_rival_R"] = rival ? RotationJson(pose.R) : none;
  line["identity_rival_t"] = rival ? nlohmann::ordered_json({pose.t(0), pose.t(1), pose.t(2)}) : none;
}

// Every key of an estimate, in the documented order.
void AddEstimateKeys(const PoseEstimate& e, nlohmann::ordered_json* out) {
  AddPoseAndDecisionKeys(e, out);
  AddRobustKeys(e, out);
  AddWeakMotionKeys(e.certificate.nd, out);
  AddRivalKeys(e, out);
  AddFreeSpaceKeys(e.certificate.free_space, out);
  AddIdentityKeys(e.certificate.identity, out);
  (*out)["ms"] = e.milliseconds;
  const StageTimes& t = e.ms_stages;
  (*out)["ms_stages"] = {{"load", t.load},
                         {"detect", t.detect},
                         {"corrector", t.corrector},
                         {"certificate", t.certificate},
                         {"free_space", t.free_space},
                         {"weak_motion", t.weak_motion},
                         {"rival_search", t.rival_search},
                         {"reestimation", t.reestimation},
                         {"centring", t.centring},
                         {"identity", t.identity}};
}

}  // namespace

std::string CertifyJsonLine(const std::string& cloud, const PoseEstimate& estimate) {
  nlohmann::ordered_json line;  // keys in the documented order, "cloud" first
  line["cloud"] = cloud;
  AddEstimateKeys(estimate, &line);
  return line.dump();
}

std::string CertifyJsonLine(const CloudSource& source, const CloudOutcome& outcome) {
  nlohmann::ordered_json line = SourceKeys(source, outcome);
  if (!outcome.processed()) {
    line["error"] = outcome.error;
  } else {
    AddEstimateKeys(outcome.estimate, &line);
  }
  return line.dump();
}

std::string CertifyErrorJsonLine(const std::string& cloud, const std::string& error) {
  return nlohmann::json{{"cloud", cloud}, {"error", error}}.dump();
}

}  // namespace c3po
