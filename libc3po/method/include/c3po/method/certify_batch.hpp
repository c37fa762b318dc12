#pragma once
// Batch certification: the one loop "cloud -> keypoints (detector or given)
// -> EstimateAndCertify (pipeline.hpp) -> outcome" behind `c3po certify`,
// `c3po eval` (evaluation.hpp) and self-training (selftrain.hpp), with
// progress, parallelism over clouds (ParallelFor), cancellation (interrupt.hpp)
// and the single `--eps-oc auto` decision (docs/method.md "Automatic ε_oc").
//
// A batch is a list of CloudSource: each yields a point cloud (read from a
// file, a dataset entry, or already in memory) with its provenance and, when
// known, given keypoints and the ground-truth pose. New kinds of input (depth
// images, BOP scenes) are new CloudSource factories; the loop does not change.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/io/segment.hpp"
#include "c3po/method/auto_threshold.hpp"
#include "c3po/method/detector.hpp"
#include "c3po/method/identity_check.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

// Where an image-derived cloud came from (a BOP instance, docs/camera_inputs.md):
// gt_id is the index in that image's scene_gt.json list, or the detection's
// index in a detections file.
struct CloudProvenance {
  int scene_id = 0, im_id = 0, gt_id = 0, obj_id = 0;
  std::optional<double> detection_score;   // masks from --detections
};

struct CloudSource {
  std::string name;                          // how outputs name the cloud (path, manifest entry)
  std::string path;                          // file it is read from ("" = in memory)
  std::size_t dataset_index = 0;             // entry of its dataset (dataset sources)
  std::function<PointSet()> load;            // reads the cloud; throws InputError naming the file
  std::optional<PointSet> given_keypoints;   // e.g. a manifest's detected_keypoints, 3 x N
  std::optional<Pose> scene_from_model_truth;   // ground truth, when known
  // Image inputs (depth + mask): reads and back-projects the segment
  // (segment.hpp); used instead of `load`, and the outcome keeps its counts.
  std::function<SegmentCloud()> load_segment;
  std::optional<CloudProvenance> provenance;   // BOP instances
  // A cloud read by `load` that came from a depth frame (self-training's
  // camera inputs and their augmented copies in memory; eval --bop's dataset
  // written from BOP instances): reads the frame, for the free-space test.
  // Empty: no frame. Called in the worker thread; throws InputError naming
  // the file when the frame cannot be read (a per-cloud failure).
  std::function<DepthView()> load_frame;
};

// The depth frame a dataset entry's cloud came from (an invalid view: none).
using DatasetFrames = std::function<DepthView(const DatasetEntry& entry)>;

// Cloud files given by path (named by their path).
std::vector<CloudSource> CloudFileSources(const std::vector<std::string>& paths);
// Every entry of a dataset (named by the manifest's "cloud"), with its
// detected_keypoints and ground-truth pose when the manifest has them, and
// its depth frame when `frames` is given.
std::vector<CloudSource> DatasetSources(const Dataset& dataset, const DatasetFrames& frames = {});
// Clouds already in memory (named "#i"), optionally with given keypoints
// (keypoints.size() == clouds.size() or empty) and the depth frame each came
// from (frames: nullptr, or one per cloud; an invalid view = none). The
// clouds are referenced, not copied: they must outlive the batch.
std::vector<CloudSource> InMemorySources(const std::vector<PointSet>& clouds,
                                         const std::vector<PointSet>& keypoints = {},
                                         const std::vector<DepthView>* frames = nullptr);

// Reads one source's cloud as CertifyBatch does: `load`, or `load_segment`
// (image inputs) whose preprocessing counts go to `segment_counts` (when not
// null; without the depth image) before a segment too small to use is
// refused; `frame` (when not null) receives the segment's depth image and
// camera for the free-space test (free_space.hpp), or the source's
// load_frame(); `evidence` (when not null) receives the cloud the
// certificate judges when it is not the returned one: the segment's evidence
// (segment.hpp: the mask eroded by evidence_erode_mask) or the frame's
// (DepthView::evidence); nullopt = the returned cloud itself. Throws
// InputError naming the source (unreadable file, empty or too small segment).
PointSet LoadSourceCloud(const CloudSource& source, std::optional<SegmentCloud>* segment_counts = nullptr,
                         DepthView* frame = nullptr, std::optional<PointSet>* evidence = nullptr);

struct CertifyBatchOptions {
  PipelineOptions pipeline;           // corrector + certificate thresholds (absolute)
  // --eps-oc auto: after every cloud is certified, eps_oc is estimated from
  // the clouds and the oc distances of their estimates (EstimateEpsOc) and
  // every oc decision is taken again with it (the distances do not depend on
  // eps_oc). The one place that decides `auto`.
  bool auto_eps_oc = false;
  AutoEpsOcOptions auto_eps_oc_options;
  // Also certify the plain registration T(ỹ) of the detected keypoints
  // (eval's "KeyPo" rows) besides the pipeline's estimate.
  bool also_uncorrected = false;
  // Identity among known objects (identity_check.hpp): every pose certified
  // is checked against these objects' certifiers on the same cloud
  // (certificate.identity). Not with auto_eps_oc (its decision comes after
  // the loop, when the frames are gone).
  std::vector<KnownObject> other_objects;
  void Check() const;                 // throws std::invalid_argument / InputError
};

struct CloudOutcome {
  enum class Failure { kNone, kLoad, kDetect };
  Failure failure = Failure::kNone;
  std::string error;                  // why (failure != kNone): the InputError's text
  PointSet detected_keypoints;        // ỹ (given or detected)
  PoseEstimate estimate;              // pipeline.correct as given
  std::optional<PoseEstimate> uncorrected;   // also_uncorrected: T(ỹ), certified
  // Image inputs: the preprocessing counts (segment.hpp; `cloud` emptied),
  // also when the segment was too small to use (failure kLoad).
  std::optional<SegmentCloud> segment;
  // Hausdorff(T*·B̂, T̂·B̂) when the source has a ground-truth pose (the
  // correctness measure of docs/method.md: symmetries cost nothing).
  std::optional<double> truth_hausdorff;
  double seconds = 0.0;               // reading + preprocessing + detection + estimate
  bool processed() const { return failure == Failure::kNone; }
  bool certified() const { return processed() && estimate.certified(); }
};

struct CertifyBatchResult {
  std::vector<CloudOutcome> outcomes;        // in source order
  CertificateOptions certificate;            // the thresholds the decisions used
  std::optional<AutoEpsOcResult> auto_eps_oc;   // the decision and its evidence (auto_eps_oc)
  int certified = 0, oc = 0, nd = 0, errors = 0;
};

// Called in the worker thread right after cloud `index` is certified, while
// the cloud is in memory (eval refines with ICP there; the cloud the
// certificate judged, LoadSourceCloud's evidence), with the frame's
// free-space test the estimate was certified with (nullptr: none). Not
// called for clouds that failed to load.
using CloudVisitor = std::function<void(std::size_t index, const PointSet& cloud, const FreeSpaceTest* free_space,
                                        CloudOutcome* outcome)>;

// Certifies every source (in parallel over clouds). `detector` nullptr: every
// source must carry given keypoints (InputError naming the first that does
// not). A cloud that cannot be read or whose detection fails (or returns the
// wrong number of keypoints) is a per-cloud failure, not an exception.
// Throws Interrupted when an interrupt is requested (interrupt.hpp).
CertifyBatchResult CertifyBatch(const ObjectModel& object, const std::vector<CloudSource>& sources,
                                const Detector* detector, const CertifyBatchOptions& options,
                                const ProgressCallback& progress = {}, const CloudVisitor& visit = {});

// The JSON-lines schema of `c3po certify --json` / `-o` (docs/architecture.md
// "Output schemas"): one object per cloud, keys in this order:
//   cloud, R (3 rows), t, keypoints (N x 3, corrected), oc, nd, certified,
//   refused_by (the failed parts, refusal.hpp: "oc", "oc_keypoints",
//   "free_space", "support", "mask", "uncovered", "nd_sets", "nd_local", "nd_weak_motion",
//   "nd_global"; [] when certified, ["registration"] without a pose),
//   oc_distance (null when not finite), keypoint_distance, nd_set,
//   nd_set_distances, eps_oc, delta_nd, iterations, cost_before, cost_after
//   (null when not finite), status (registration), restarts_tried,
//   restart_axis and restart_angle_deg (re-estimation: axis -1 when the
//   detector's estimate was kept; global_uniqueness.hpp), centred and
//   centred_fits (the pose is the centre of that many fits: the refused
//   estimate and its near rivals; GlobalUniquenessOptions::centre), then the outlier-robust
//   evidence (docs/method.md "Outlier-robust certificates"): max_outliers (m
//   for this cloud), robust_loss and robust_scale (the corrector's kernel and
//   its truncation c, 0 without a kernel), outliers (count at >= eps_oc), outlier_indices (the first
//   kMaxListedOutliers, ascending), outlier_indices_truncated,
//   distance_quantiles (50/90/99/100 %, null when not finite),
//   max_inlier_distance, keypoint_support (per keypoint), nd_set_support (per
//   set), nd_sets, nd_local (null when the local test is off),
//   nd_local_eigenvalue, nd_local_motion (6: rotation, translation),
//   nd_local_rank, nd_local_weak_motions; the finite check of a single weak
//   motion (global_uniqueness.hpp): nd_weak_motion (null when not run; true:
//   nd's local part passes although nd_local is false), weak_motion_starts,
//   weak_motion_rivals, weak_motion_rival_step and weak_motion_rival_hausdorff
//   (null without a rival); the global rival search (global_uniqueness.hpp): nd_global
//   (null when not run: something else failed, or --no-global-check),
//   rivals_tried, rivals_found, rival_distance, rival_hausdorff (null: no
//   distinct rival), rival_outliers, rival_axis, rival_angle_deg,
//   rival_passes_oc, rival_free_space_violations (-1: not checked),
//   rival_counts (the reported rival is one that refuses), rival_R
//   and rival_t (the reported rival's pose; null without one); free space
//   (free_space.hpp; depth-image inputs): free_space (null when not checked),
//   free_space_violations, free_space_measured, free_space_silhouette,
//   free_space_tolerance, free_space_limit, free_space_shift_px,
//   through_support (null without a support plane), seen_surface,
//   seen_outside_mask, outside_mask_limit, mask_at_depth, mask_uncovered and
//   uncovered_mask_limit (null without a mask; the mask tests,
//   free_space.hpp); identity among known objects (identity_check.hpp):
//   identity (null when not checked), identity_objects (tried),
//   identity_rival (the other object certified too; null: none),
//   identity_rival_oc_distance, identity_rival_R and identity_rival_t (null
//   without a rival); ms; and last ms_stages, an object of the
//   milliseconds of each stage (StageTimes, pipeline.hpp: load, detect,
//   corrector, certificate, free_space, weak_motion, rival_search,
//   reestimation, centring, identity). Image-source lines also carry
//   gt_hausdorff after gt_t (Hausdorff(T*·B̂, T̂·B̂), metres) when the
//   ground truth is known.
constexpr std::size_t kMaxListedOutliers = 100;
std::string CertifyJsonLine(const std::string& cloud, const PoseEstimate& estimate);
// {"cloud": ..., "error": ...} for a cloud that could not be processed.
std::string CertifyErrorJsonLine(const std::string& cloud, const std::string& error);
// The same for a batch outcome, with the provenance keys of image inputs
// after "cloud" (docs/camera_inputs.md "JSON line keys"): scene_id, im_id,
// gt_id, obj_id (detection_score), then pixels, no_depth, removed_erosion,
// removed_discontinuity, removed_plane, removed_subsampling, points,
// evidence_points (the certificate's cloud), then gt_R, gt_t (BOP
// ground truth, metres); error lines carry them too.
std::string CertifyJsonLine(const CloudSource& source, const CloudOutcome& outcome);

}  // namespace c3po
