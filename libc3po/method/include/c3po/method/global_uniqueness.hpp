#pragma once
// Global uniqueness: the search part of nd (issue 16, docs/method.md "Global
// uniqueness (rival search)"). The local test (local_nondegeneracy.hpp) proves
// that no *nearby* pose fits the accepted points; it cannot see a pose far
// away that fits them as well (the mustard bottle turned ~180° about its
// axis, a banana or marker flipped). From the estimate T̂ the corrector is
// restarted at rival hypotheses T̂·R_a(θ) (R_a(θ) = rotation by θ about
// principal axis a of B̂ through its centroid; θ = k·360°/steps, k = 1 ..
// steps-1, so the half-turns are always among them), and at the half-turns
// about the 10 diagonals of the principal frame (ReestimateAxes 3-12: where
// two extents are alike the principal axes are oblique to the object's own,
// and a flip about those is reached only from a diagonal), and at T̂ itself
// (a given pose the corrector would move far), and each rival is
// refined. A refined rival T' that
//   - passes oc_m with the same ε_oc and budget m as T̂ (and, for depth-image
//     inputs, the free-space test: free_space.hpp), and
//   - whose posed model is farther than `rival_distance` from T̂·B̂
//     (Hausdorff between the posed model samples: symmetries cost nothing)
// is a second explanation of the data: the input is ambiguous and nd fails.
// This is a search, not a proof: it refuses when it finds a rival; it cannot
// show that no rival exists (docs/method.md states what it guarantees).
#include <Eigen/Core>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct PipelineOptions;
struct PoseEstimate;

struct GlobalUniquenessOptions {
  bool enabled = true;
  // Re-estimation: when the corrected estimate fails oc_m or free space (it
  // is refuted), the corrector is restarted from T̂ turned by
  // k·360°/reestimate_steps (k = 1 .. steps-1) about 13 axes through the
  // centroid (ReestimateStarts: the 3 principal axes, their 6 face diagonals
  // and 4 body diagonals), and the fit with the fewest points beyond eps_oc
  // that passes oc_m and free space replaces it (and is certified in full,
  // rival search included). Choosing which pose to certify cannot make a
  // certificate unsound; and when another restart that counts as a rival
  // (the rivals' oc, free space) lies beyond rival_distance of the chosen
  // one, the search itself found a second explanation: nd.global fails.
  bool reestimate = false;
  int reestimate_steps = 12;   // even, in [2, 36]
  // Centring (docs/method.md "Centring a valley of fits"): when the estimate
  // passes everything except the rivals (the global search's or the weak
  // motion's) and every rival lies within 2·rival_distance of it, the fits
  // found are one flat valley of explanations, not two: the pose at their
  // centre (CentreOfFits) is certified in full instead, rival search included,
  // and replaces the estimate when it passes and every fit found lies within
  // rival_distance of it. Choosing which pose to certify cannot make a
  // certificate unsound (every test is applied to the pose reported).
  bool centre = true;
  // Rotations by k·360°/steps about each principal axis, k = 1 .. steps-1
  // (even: the half-turns are included). 4: 90°, 180°, 270° (9 rivals; with
  // the 10 diagonal half-turns and T̂'s own refit, 20).
  int steps = 4;
  // The accuracy the user needs (object units): a certified pose lies within
  // `tolerance` (+ the sensor noise eps_w) of the truth, as far as the search
  // reaches (docs/method.md "Tolerance"). A second fit that explains the
  // evidence counts as a rival when it lies farther than rho = tolerance -
  // eps_oc from the estimate (Hausdorff between the posed models): the truth,
  // if it is such a fit, is then within rho of the estimate and the estimate
  // within rho + eps_oc = tolerance of it. 0 = the default (Tolerance()):
  // 10 % of the object's diameter -- the accuracy pose
  // benchmarks call correct (ADD(-S) < 0.1 d since Hinterstoisser et al. 2012;
  // BOP's MSSD counts 5-50 % of d), here as a Hausdorff distance, which is
  // stricter -- and at least 3 eps_oc: two fits within 2 eps_oc of each other
  // may both be the truth's (each within eps_oc + eps_w of it), so rho below
  // 2 eps_oc would refuse the truth's own valley.
  double tolerance = 0.0;
  // Expert: rho itself (> 0 overrides the tolerance; the bound is then
  // rival_distance + eps_oc).
  double rival_distance = 0.0;
  // `tolerance` when given, else max(kDefaultToleranceFraction·diameter, 3·eps_oc).
  double Tolerance(double eps_oc, double diameter) const;
  // rho (see above).
  double RivalDistance(double eps_oc, double diameter) const;
  // Rivals are judged with a looser oc than the estimate: at most m +
  // max(floor(rival_extra_fraction·n), rival_extra_min) points beyond eps_oc
  // (n = cloud size). The estimate must beat every far pose by more than a
  // few noisy points can explain (measured: a large marker whose true,
  // flipped pose had 3 points beyond eps_oc while the wrong one had none; and
  // with --robust-loss tls at m = 0 one whose true pose had 8 on a 775-point
  // segment, one more than 1 % -- hence the floor in points). Both 0 =
  // exactly oc_m.
  double rival_extra_fraction = 0.01;
  int rival_extra_min = 10;
  // The slack in points for a cloud of n points.
  int RivalSlack(Eigen::Index n) const;
  void Check() const;   // steps, reestimate_steps even and in [2, 36], tolerance and rival_distance >= 0 finite, fraction in [0, 1), min >= 0
};

// The default tolerance's fraction of the diameter (see `tolerance`).
inline constexpr double kDefaultToleranceFraction = 0.1;

// The evidence (part of NonDegeneracy, certificate.hpp).
struct GlobalUniqueness {
  bool passed = true;
  double rival_distance = 0.0;  // the threshold used (object units)
  int rivals_tried = 0;
  int rivals_found = 0;         // distinct rivals passing the rivals' oc (and free space)
  // The rival reported: the farthest one that counts; if none counts, the
  // distinct one (farther than rival_distance) with the fewest outliers;
  // axis -1 when every rival fell back within rival_distance of T̂.
  int rival_axis = -1;          // ReestimateAxes column: 0-2 principal axes (0 = largest extent), 3-12 diagonals
  double rival_angle_deg = 0.0; // start rotation about it
  double rival_hausdorff = 0.0; // Hausdorff(T̂·B̂, T'·B̂)
  int rival_outliers = -1;      // its oc_m outlier count (points >= eps_oc)
  double rival_budget_distance = 0.0;   // its (m+1)-th largest point distance
  bool rival_passes_oc = false;
  int rival_free_space_violations = -1; // depth-image inputs: its free-space evidence (-1: not checked)
  bool rival_counts = false;    // the reported rival is one of rivals_found (always, when rivals_found > 0)
  Pose rival_scene_from_model;
  std::vector<Pose> rival_poses;   // every rival that counts (the search's, then the restarts'), for centring
};

// Principal axes of the model sample (columns, decreasing extent, right-handed) and its centroid.
struct PrincipalFrame {
  Eigen::Matrix3d axes;
  Eigen::Vector3d centroid;
};
PrincipalFrame ModelPrincipalFrame(const ObjectModel& object);

// The rotation by `angle` (radians) about axis `axis` through the centroid,
// as a model_from_model pose: a principal axis (0-2) or a diagonal of the
// principal frame (3-12, the ReestimateAxes column).
Pose AxisRotation(const PrincipalFrame& frame, int axis, double angle);
// AxisRotation(frame, axis, pi).
Pose HalfTurn(const PrincipalFrame& frame, int axis);

// One refined rival hypothesis.
struct RivalFit {
  int axis = -1;
  double angle = 0.0;             // radians
  Pose start;                     // the pose the fit started from
  bool ok = false;                // the corrector returned a pose
  Pose scene_from_model;
  PointSet keypoints;             // corrected keypoints of the rival
  bool passes_oc = false;         // oc with the estimate's eps_oc and budget m (+ the rival slack, see above)
  int outliers = 0;
  double budget_distance = 0.0;
  double keypoint_distance = 0.0; // max_i ||y*_i - y'_i||
  double hausdorff = 0.0;         // Hausdorff(T̂·B̂, T'·B̂)
};

// Restarts the corrector (the pipeline's, with its robust kernel; certificates
// without the global test) from T̂·R_a(θ) for every (axis, angle) given, on
// `cloud`; the rivals' oc is decided with pipeline.certificate.
std::vector<RivalFit> RefineRivals(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                   const PipelineOptions& pipeline, const PrincipalFrame& frame,
                                   const std::vector<std::pair<int, double>>& hypotheses);

// The (axis, angle) hypotheses of the options: 3 × (steps - 1) turns about
// the principal axes, then the half-turns about the diagonals 3-12, then
// (0, 0): the estimate itself, refitted -- where the corrector settles from
// T̂. A pose the data put elsewhere (a given pose, `--poses --no-correct`,
// whose nearby best fit lies beyond rival_distance) has its rival there.
std::vector<std::pair<int, double>> RivalHypotheses(const GlobalUniquenessOptions& options);

// The 13 axes of the re-estimation (columns, unit): the principal axes (0-2),
// the face diagonals a_i ± a_j (3-8) and the body diagonals a_0 ± a_1 ± a_2
// (9-12) -- the rotation axes of a cube's symmetries in the principal frame.
Eigen::Matrix<double, 3, 13> ReestimateAxes(const PrincipalFrame& frame);

// The pose at the centre of `poses` (scene_from_model, at least one): the
// chordal mean of the rotations (the sum projected onto SO(3)) turning the
// model about its sample centroid c, which goes to the mean of the posed
// centroids R_i c + t_i. For poses that differ by small motions it is their
// midpoint to first order; Hausdorff distances from it are what centring
// checks, not assumed.
Pose CentreOfFits(const ObjectModel& object, const std::vector<Pose>& poses);

// An extra test a rival must pass to count (the free-space test of depth-image
// inputs, free_space.hpp): whether the pose passes and its violation count.
struct RivalFilter {
  virtual ~RivalFilter() = default;
  virtual bool Passes(const Pose& scene_from_model, int* violations) const = 0;
};

// One rival start: the pose the fit starts from and how it was made.
struct RivalStart {
  int axis = -1;          // principal axis of a turn; -1 for a displacement along the weak motion
  double angle = 0.0;     // turn (radians) or displacement step (object units)
  Pose scene_from_model;
};
// Fits every start on `cloud` (the rivals' budget and options as in
// RefineRivals); with refine = false the start itself is judged (no corrector).
// Each fit's oc is judged on `evidence` when given (the re-estimation fits
// its restarts to the estimate's cloud but, like the estimate, judges them on
// the certificate's evidence: docs/method.md "Evidence: the whole mask"),
// else on `cloud`; the budget m + slack is that of the judged points.
std::vector<RivalFit> FitRivals(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                const PipelineOptions& pipeline, const std::vector<RivalStart>& starts, bool refine,
                                const PointSet* evidence = nullptr);

// The finite check of a single weak motion (local_nondegeneracy.hpp): the
// first-order test refuses a box seen on two faces because sliding along
// their common edge moves no observed point off its face *to first order*;
// finitely it pushes the points past the faces' ends. From T̂ the pose is
// displaced along the weak motion ξ (model frame, about the centroid:
// rotation s·ω, translation s·v, ξ = (r ω, v) unit) by
// s = ±1.5·rival_distance·2^k (k = 0, 1, ... while s <= the diameter); each
// displaced pose is judged as it is and after refitting, as a rival of the
// global search (passes the rivals' oc -- budget m + slack -- and free space,
// and lies farther than rival_distance from T̂). No rival: the weak motion is
// constrained finitely and nd's local part passes. Like the global search
// this refuses on evidence and cannot prove absence between the steps
// (docs/method.md "Weak motion").
struct WeakMotionCheck {
  bool passed = false;
  int starts = 0;                 // displaced poses judged (raw and refitted)
  int rivals_found = 0;
  double rival_step = 0.0;        // the displacement s of the reported rival (object units)
  double rival_hausdorff = 0.0;   // its Hausdorff distance to T̂·B̂ (0: none)
  int rival_outliers = -1;        // its outlier count (-1: none)
  double fewest_outliers_step = 0.0;  // without a rival: the distinct displacement that came closest
  int fewest_outliers = -1;
  std::vector<Pose> rival_poses;   // every rival found, for centring
};

// The displacement by s along the unit twist ξ (LocalNonDegeneracy::motion)
// as a model_from_model pose.
Pose WeakMotionDisplacement(const ObjectModel& object, const Eigen::Matrix<double, 6, 1>& motion, double step);

WeakMotionCheck CheckWeakMotion(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                const PipelineOptions& pipeline, const RivalFilter* filter = nullptr);

// The global test of `estimate` (which must be ok()) on `cloud` with the
// pipeline's corrector and certificate options.
GlobalUniqueness CheckGlobalUniqueness(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                       const PipelineOptions& pipeline, const RivalFilter* filter = nullptr);

// The re-estimation's own evidence (GlobalUniquenessOptions::reestimate):
// the restart fits that count as rivals of the chosen pose T̂ (fitted, the
// rivals' oc, `filter`, Hausdorff(T̂·B̂, T'·B̂) > global->rival_distance) are
// added to `global` (rivals_tried, rivals_found, the farthest reported when
// it is farther than the one already there); passed = no rival found.
void AddRestartRivals(const ObjectModel& object, const std::vector<RivalFit>& fits, const Pose& scene_from_model,
                      const RivalFilter* filter, GlobalUniqueness* global);

}  // namespace c3po
