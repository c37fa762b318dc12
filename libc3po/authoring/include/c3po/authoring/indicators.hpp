#pragma once
// Indicator sets (paper Section V, Definition "Indicator Set", eq. 21):
// editing and validation, coverage on a labelled dataset, and automatic
// learning from rendered depth views (the paper's Remark "Learning Indicator
// Sets", named there as future work).
//
// Automatic learning, in two steps:
// 1. Label views. For each rendered view X of the object at a known pose T*,
//    search for other poses T' that fit X as well (max_x dist(x, T'·B̂) <
//    eps_oc): ICP from many starting poses around T* (a grid on SO(3) in the
//    object's principal frame, rotations about the principal axes, shifts
//    along the viewing ray and the principal axes). The view is degenerate
//    when some fitting pose is far from the truth: Hausdorff(T*·B̂, T'·B̂) >
//    tolerance (the cover-set condition, eq. 20). Hausdorff on posed models
//    makes exact symmetries harmless (a can turned about its axis is no error).
// 2. Choose sets. Keypoint i is "seen" in a view when T*·b_i is within
//    delta_nd of a cloud point. A candidate subset G is admissible when no
//    degenerate (or borderline, see LabelledView) training view sees all of G;
//    greedy set cover picks the
//    admissible candidate that accepts most not-yet-accepted non-degenerate
//    views (ties: smaller sets first), until nothing new is accepted.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/method/icp.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

using IndicatorSet = std::vector<int>;
// Called from worker threads as views complete: must be thread-safe.
using IndicatorProgress = std::function<void(std::size_t done, std::size_t total)>;

// ---------------------------------------------------------------- editing

// "0,1,3" -> {0, 1, 3}. Throws InputError(what + ": ...") on anything else.
IndicatorSet ParseIndicatorSet(const std::string& text, const std::string& what);

// Indices in [0, num_keypoints), no index twice in a set, no empty set, no set
// listed twice (order inside a set does not matter). Throws
// InputError(where + ": indicator_sets[k]: problem").
void ValidateIndicatorSets(const std::vector<IndicatorSet>& sets, int num_keypoints,
                           const std::string& where);

struct IndicatorEdit {
  bool clear = false;              // applied first
  std::vector<int> remove;         // indices into the sets before the edit; applied second
  std::vector<IndicatorSet> add;   // appended last
};

// Applies the edit and validates the result. Throws InputError(where + ...)
// for an out-of-range --remove index or an invalid resulting family.
std::vector<IndicatorSet> ApplyIndicatorEdit(const std::vector<IndicatorSet>& sets,
                                             const IndicatorEdit& edit, int num_keypoints,
                                             const std::string& where);

// "{3 handle_top, 9 handle_middle}"
std::string DescribeIndicatorSet(const ObjectSpec& spec, const IndicatorSet& set);

// ---------------------------------------------------------------- coverage

// How often each set is seen on a dataset with ground-truth poses: per view,
// CheckNonDegeneracy at the ground-truth pose.
struct IndicatorCoverage {
  std::size_t views = 0;
  double delta_nd = 0.0;
  std::vector<std::size_t> set_seen;        // per set: views where all its keypoints are seen
  std::vector<std::size_t> keypoint_seen;   // per keypoint
  std::size_t nd_passed = 0;                // views with nd = 1
  std::vector<bool> view_nd;                // per view
};

// Throws InputError(dataset.dir + ...) when an entry has no ground-truth pose
// or a cloud cannot be read.
IndicatorCoverage MeasureIndicatorCoverage(const ObjectModel& object, const Dataset& dataset,
                                           double delta_nd, const IndicatorProgress& progress = {});

// ---------------------------------------------------------------- automatic

struct ViewSamplingOptions {
  int views = 200;
  std::uint64_t seed = 1;
  int points = 1000;            // cloud size
  double noise_sigma = -1.0;    // depth noise (object units); < 0: eps_oc / 8
  double distance_min = 0.0;    // camera distance to the object centre; 0 = default range
  double distance_max = 0.0;    // [0.5, 1.5] * fy * d / (0.4 * height) (as c3po synth)
  CameraIntrinsics camera;
  int min_points = 50;          // views with fewer points are drawn again (other roll/distance)
  void Check() const;           // throws InputError("--flag: problem")
};

struct RenderedView {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();   // model frame, object -> camera
  Pose camera_from_model;
  PointSet cloud;                                         // camera frame
};

// View i of a run: direction i of a Fibonacci sphere of `views` directions
// (covering the sphere evenly), random roll about the optical axis, random
// distance in the range, Gaussian depth noise. A pure function of
// (seed, i, options): parallel runs give the same views. `renderer` is one per
// thread, made with options.camera.
RenderedView RenderView(const ObjectModel& object, const ViewSamplingOptions& options,
                        double noise_sigma, int index, DepthRenderer* renderer);

// Views chosen to be degenerate on purpose (issue 16): random directions
// rarely look exactly face-on or edge-on (about 1 % of them), yet those are
// the views a wrong pose can explain. From the model alone:
//  - face-on: along ± each principal axis and along the outward normal of
//    every large planar patch (mesh triangles grouped by normal within
//    patch_angle_deg and by plane offset within 2 % of d; a patch counts when
//    its area is at least min_patch_fraction of the surface);
//  - edge-on: the bisector of every two face-on directions 60-120 degrees
//    apart (two faces seen, meeting at their common edge);
//  - corner: the sum of three mutually perpendicular principal directions
//    (the informative three-face view), used for the partial views;
//  - partial: a face-on or corner view with half the image occluded by a
//    plane through the object's centre containing the optical axis (the
//    points on one side dropped), once along the image's x and once along y.
// Directions closer than min_separation_deg to an earlier one are dropped.
enum class ViewKind { kRandom, kFaceOn, kEdgeOn, kCorner, kPartial };
const char* ToString(ViewKind kind);   // "random", "face-on", "edge-on", "corner", "partial"

struct DeliberateView {
  ViewKind kind = ViewKind::kFaceOn;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();   // model frame, object -> camera
  int cut_axis = -1;   // kPartial: 0 = keep image x >= centre's, 1 = keep image y >= centre's
};

struct DeliberateViewOptions {
  double min_patch_fraction = 0.03;   // planar patch area / surface area
  double patch_angle_deg = 10.0;
  double min_separation_deg = 8.0;
  int max_patches = 24;
  bool partial = true;
  void Check() const;                 // throws InputError
};

std::vector<DeliberateView> DeliberateViews(const ObjectModel& object, const DeliberateViewOptions& options);

// Renders one deliberate view (distance at the middle of the range, roll and
// noise drawn from Rng::ForItem(options.seed ^ salt, index)), with at least
// 2000 points (twice that before a partial view's cut): dense enough that the
// keypoints it sees are not missed by sampling (a degenerate view blocks
// exactly the sets it sees).
RenderedView RenderDeliberateView(const ObjectModel& object, const ViewSamplingOptions& options,
                                  double noise_sigma, const DeliberateView& view, int index,
                                  DepthRenderer* renderer);

struct DegeneracyOptions {
  double eps_oc = 0.0;          // fit threshold (absolute); <= 0: the object's
  double delta_nd = 0.0;        // "seen" threshold (absolute); <= 0: the object's
  double tolerance_factor = 2.0;   // degenerate iff Hausdorff > tolerance_factor * eps_oc
  // A degenerate view blocks every candidate set whose keypoints all lie
  // within near_factor * delta_nd of its cloud, not only those it supports
  // within delta_nd: a denser or slightly turned cloud of the same view can
  // support a keypoint the rendered one just misses (near_mask).
  double near_factor = 2.0;
  int search_points = 200;      // cloud points used by the ICP searches
  int hausdorff_points = 2000;  // model points used for the Hausdorff distances
  IcpOptions icp;               // of each search
  // Each search first runs screening_iterations ICP steps and is dropped when
  // its RMS is still above screening_factor * eps_oc (no fit is near).
  int screening_iterations = 8;
  double screening_factor = 2.0;
  void Check() const;
};

struct ViewDegeneracy {
  bool usable = false;          // the true pose itself fits within eps_oc
  bool degenerate = false;
  double true_fit = 0.0;        // max_x dist(x, T*·B̂)
  double worst_hausdorff = 0.0; // largest Hausdorff(T*·B̂, T'·B̂) over fitting poses T'
  int starts = 0;               // ICP starts tried
  int fitting_starts = 0;       // starts whose refined pose fits within eps_oc
  Pose worst_pose;              // the fitting pose achieving worst_hausdorff
  std::uint64_t seen_mask = 0;  // bit i: keypoint i within delta_nd of the cloud at T*
  std::uint64_t near_mask = 0;  // bit i: within near_factor * delta_nd (a superset of seen_mask)
};

// The starting poses of the search, as model-frame motions about the sample
// centroid: the 24 rotations of the cube group in the principal frame, the
// 45-degree rotations about each principal axis, and shifts of ±d/4 along the
// principal axes (the view-dependent shifts are added by AnalyzeViewDegeneracy).
std::vector<Pose> DegeneracySearchMotions(const ObjectModel& object);

// Decides whether `cloud` pins down the pose (see the top of this file).
ViewDegeneracy AnalyzeViewDegeneracy(const ObjectModel& object, const PointSet& cloud,
                                     const Pose& scene_from_model,
                                     const std::vector<Pose>& motions,
                                     const DegeneracyOptions& options);

// One labelled view for set learning.
struct LabelledView {
  std::uint64_t seen_mask = 0;
  bool degenerate = false;
  // Non-degenerate, but some fitting pose is beyond borderline_factor times the
  // degeneracy tolerance: such a view blocks candidates like a degenerate one
  // (a safety margin against views just on the other side of the tolerance).
  bool borderline = false;
  // Degenerate and borderline views block the candidates all within
  // seen_mask | near_mask (DegeneracyOptions::near_factor).
  std::uint64_t near_mask = 0;
};

struct SetLearningOptions {
  int max_set_size = 3;         // candidates: all subsets of 1..max_set_size keypoints
  int min_support = 2;          // a chosen set must accept at least this many new views
  int max_sets = 32;
  double borderline_factor = 1.0;    // in (0, 1]; 1 = no margin (0.75 made the mug sets far too strict)
  void Check() const;
};

struct LearnedSets {
  std::vector<IndicatorSet> sets;     // empty + accept_all: nd = 1 always suits
  bool accept_all = false;            // no degenerate training view: no sets needed
  std::vector<int> accepted_per_set;  // new views accepted when each set was chosen
  int candidates = 0;
  int admissible = 0;
};

// Greedy set cover (see the top of this file). Requires num_keypoints <= 64.
LearnedSets LearnIndicatorSets(const std::vector<LabelledView>& views, int num_keypoints,
                               const SetLearningOptions& options);

// Accepting a view = "some set is all seen" (or every view with no sets).
struct SetScore {
  int views = 0;
  int degenerate = 0;
  int accepted = 0;
  int false_accepts = 0;     // degenerate views accepted
  int true_accepts = 0;      // non-degenerate views accepted
  double precision = 1.0;    // true_accepts / accepted (1 when nothing accepted)
  double recall = 1.0;       // true_accepts / non-degenerate (1 when none)
};
SetScore ScoreIndicatorSets(const std::vector<IndicatorSet>& sets,
                            const std::vector<LabelledView>& views);

struct AutoIndicatorOptions {
  ViewSamplingOptions training;     // the views the sets are learned from
  bool deliberate = true;           // train on the DeliberateViews too (they are always labelled and scored)
  DeliberateViewOptions deliberate_views;
  std::uint64_t test_seed = 0;      // seed of the separate test views; 0 = training seed + 1000003
  int test_views = -1;              // -1: as many as the training views
  DegeneracyOptions degeneracy;
  SetLearningOptions learning;
  void Check() const;
};

struct AutoIndicatorResult {
  LearnedSets learned;
  SetScore training_score;
  SetScore test_score;
  SetScore current_test_score;      // the object's own sets on the same test views
  SetScore deliberate_score;        // the learned sets on the deliberate views
  SetScore current_deliberate_score;   // the object's own sets on them
  bool deliberate_trained = false;  // the deliberate views were training views
  int unusable_deliberate_views = 0;
  double eps_oc = 0.0;              // the resolved thresholds
  double delta_nd = 0.0;
  double noise_sigma = 0.0;
  std::uint64_t training_seed = 0;
  std::uint64_t test_seed = 0;
  int unusable_training_views = 0;  // the true pose did not fit within eps_oc
  int unusable_test_views = 0;
  std::vector<DeliberateView> deliberate_views;
  std::vector<ViewDegeneracy> deliberate_labels;  // per deliberate view
  std::vector<ViewDegeneracy> training_views;     // the random training views
  std::vector<ViewDegeneracy> test_views;
  double seconds = 0.0;
  // {"precision", "recall", "views", "test_views", "seed", "test_seed", ...}
  std::string EvidenceJson() const;
};

// Renders, labels (on all cores) and learns. `progress` counts labelled
// views over both sets. Throws Interrupted when asked to stop.
AutoIndicatorResult LearnIndicatorSetsFromViews(const ObjectModel& object,
                                                const AutoIndicatorOptions& options,
                                                const IndicatorProgress& progress = {});

}  // namespace c3po
