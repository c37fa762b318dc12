#include "c3po/method/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "c3po/geometry/registration.hpp"

namespace c3po {

double StageTimes::Total() const {
  return load + detect + corrector + certificate + free_space + weak_motion + rival_search + reestimation + centring +
         identity;
}

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void PipelineOptions::Check() const {
  if (max_corrector_points < 0) throw std::invalid_argument("max_corrector_points must be >= 0");
  corrector.Check();
  certificate.Check();
}

namespace {

// Only the local test failed, on a single weak motion, and it had the points
// to decide (LocalNonDegeneracyOptions::weak_motion_check).
bool WeakMotionCheckApplies(const Certificate& certificate, const CertificateOptions& options) {
  const NonDegeneracy& nd = certificate.nd;
  return options.local.weak_motion_check && certificate.fits_observation() && nd.sets_passed && nd.local_checked &&
         !nd.local.passed && nd.local.weak_motions == 1 && nd.local.observed_points >= options.local.min_points;
}

}  // namespace

void CompleteCertificate(const ObjectModel& object, const PointSet& cloud, const PipelineOptions& options,
                         const FreeSpaceTest* free_space, PoseEstimate* estimate) {
  Certificate& certificate = estimate->certificate;
  certificate.nd.global_checked = false;
  certificate.nd.global = GlobalUniqueness{};
  certificate.nd.weak_motion_checked = false;
  certificate.nd.weak_motion = WeakMotionCheck{};
  if (!estimate->ok()) return;
  StageTimes& times = estimate->ms_stages;
  if (free_space) {
    const auto start = std::chrono::steady_clock::now();
    certificate.free_space = free_space->Check(estimate->scene_from_model);
    times.free_space += MillisecondsSince(start);
  }
  if (WeakMotionCheckApplies(certificate, options.certificate)) {
    const auto start = std::chrono::steady_clock::now();
    certificate.nd.weak_motion = CheckWeakMotion(object, cloud, *estimate, options, free_space);
    certificate.nd.weak_motion_checked = true;
    certificate.nd.passed = certificate.nd.sets_passed && certificate.nd.weak_motion.passed;
    times.weak_motion += MillisecondsSince(start);
  }
  if (options.certificate.global.enabled && certificate.certified()) {
    const auto start = std::chrono::steady_clock::now();
    certificate.nd.global = CheckGlobalUniqueness(object, cloud, *estimate, options, free_space);
    certificate.nd.global_checked = true;
    certificate.nd.passed = certificate.nd.passed && certificate.nd.global.passed;
    times.rival_search += MillisecondsSince(start);
  }
}

namespace {

bool Refuted(const Certificate& certificate) {
  return !certificate.fits_observation();
}

// The restarts of the re-estimation: T̂ turned about the 13 ReestimateAxes
// through the centroid by k·360°/steps.
std::vector<RivalStart> ReestimateStarts(const ObjectModel& object, const Pose& scene_from_model, int steps) {
  const PrincipalFrame frame = ModelPrincipalFrame(object);
  std::vector<RivalStart> starts;
  for (int a = 0; a < ReestimateAxes(frame).cols(); ++a) {
    for (int k = 1; k < steps; ++k) {
      const double angle = 2.0 * M_PI * k / steps;
      starts.push_back({a, angle, scene_from_model * AxisRotation(frame, a, angle)});
    }
  }
  return starts;
}

// GlobalUniquenessOptions::reestimate: the refuted estimate is replaced by the
// best restart that passes oc_m and free space, if any; a certified
// replacement must have no other restart as a rival (AddRestartRivals).
void Reestimate(const ObjectModel& object, const PointSet& cloud, const PointSet& evidence,
                const PipelineOptions& options, const FreeSpaceTest* free_space, PoseEstimate* estimate) {
  // The candidates are estimates: fitted to `cloud` like the detector's,
  // judged (the rivals' oc) on `evidence` like every rival of the chosen pose;
  // the chosen one is certified against `evidence` in full.
  const std::vector<RivalFit> fits =
      FitRivals(object, cloud, *estimate, options,
                ReestimateStarts(object, estimate->scene_from_model, options.certificate.global.reestimate_steps), true,
                &evidence);
  // Candidates by their outlier count (the rivals' looser budget), best first.
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < fits.size(); ++i) {
    if (fits[i].ok && fits[i].passes_oc) order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return fits[a].outliers < fits[b].outliers; });
  PipelineOptions once = options;
  once.certificate.global.reestimate = false;
  once.certificate.global.centre = false;   // the chosen pose is centred once, by the caller
  for (const std::size_t i : order) {
    int violations = -1;
    if (free_space && !free_space->Passes(fits[i].scene_from_model, &violations)) continue;
    PoseEstimate restarted =
        EstimateAndCertify(object, cloud, fits[i].start * object.keypoints(), once, free_space, &evidence);
    if (!restarted.ok() || Refuted(restarted.certificate)) continue;
    restarted.detected_keypoints = estimate->detected_keypoints;
    if (restarted.certificate.certified() && options.certificate.global.enabled) {
      NonDegeneracy& nd = restarted.certificate.nd;
      AddRestartRivals(object, fits, restarted.scene_from_model, free_space, &nd.global);
      nd.global_checked = true;
      nd.passed = nd.passed && nd.global.passed;
    }
    restarted.restart_axis = fits[i].axis;
    restarted.restart_angle_deg = fits[i].angle * 180.0 / M_PI;
    *estimate = std::move(restarted);
    break;
  }
  estimate->restarts_tried = static_cast<int>(fits.size());
}

// The rivals that alone refuse a pose that fits the observation (oc_m, free
// space, the sets, the local test up to its weak motion): the weak-motion
// check's or the global search's. Empty when anything else refuses.
std::vector<Pose> RefusingRivals(const Certificate& certificate) {
  const NonDegeneracy& nd = certificate.nd;
  if (!certificate.fits_observation() || !nd.sets_passed || nd.passed) return {};
  if (nd.weak_motion_checked && !nd.weak_motion.passed) return nd.weak_motion.rival_poses;
  if (nd.local_checked && !nd.local.passed && !nd.weak_motion_checked) return {};
  if (nd.global_checked && !nd.global.passed) return nd.global.rival_poses;
  return {};
}

// GlobalUniquenessOptions::centre: a pose refused only by rivals that all lie
// within 2·rho of it is replaced by the centre of the two of these fits (it
// and its rivals) farthest apart when that centre is certified in full and
// every one of the fits lies within rho of it (docs/method.md "Centring a
// valley of fits").
void Centre(const ObjectModel& object, const PointSet& judged, const PipelineOptions& options,
            const FreeSpaceTest* free_space, PoseEstimate* estimate) {
  std::vector<Pose> fits = RefusingRivals(estimate->certificate);
  if (fits.empty()) return;
  const double eps_oc = options.certificate.eps_oc;
  const GlobalUniquenessOptions& global = options.certificate.global;
  const double rho = global.RivalDistance(eps_oc, object.diameter());
  const PointSet queries = StridedColumns(object.sample(), 1000);
  for (const Pose& rival : fits) {
    if (!(PosedModelHausdorff(object, queries, estimate->scene_from_model, rival) <= 2.0 * rho)) return;
  }
  fits.push_back(estimate->scene_from_model);
  // The centre of the two fits farthest apart: for a valley of fits along one
  // motion (a slide, a turn about an axis) the pose nearest to all of them.
  std::pair<std::size_t, std::size_t> ends{0, fits.size() - 1};
  double diameter = -1.0;
  for (std::size_t i = 0; i < fits.size(); ++i) {
    for (std::size_t j = i + 1; j < fits.size(); ++j) {
      const double d = PosedModelHausdorff(object, queries, fits[i], fits[j]);
      if (d > diameter) {
        diameter = d;
        ends = {i, j};
      }
    }
  }
  PoseEstimate centred = *estimate;
  centred.scene_from_model = CentreOfFits(object, {fits[ends.first], fits[ends.second]});
  centred.keypoints = centred.scene_from_model * object.keypoints();
  centred.certificate = Certify(object, judged, centred.scene_from_model, centred.keypoints, options.certificate);
  CompleteCertificate(object, judged, options, free_space, &centred);
  if (!centred.certified()) return;
  for (const Pose& fit : fits) {
    if (!(PosedModelHausdorff(object, queries, centred.scene_from_model, fit) <= rho)) return;
  }
  centred.centred = true;
  centred.centred_fits = static_cast<int>(fits.size());
  *estimate = std::move(centred);
}

}  // namespace

PoseEstimate EstimateAndCertify(const ObjectModel& object, const PointSet& cloud,
                                const PointSet& detected_keypoints, const PipelineOptions& options,
                                const FreeSpaceTest* free_space, const PointSet* evidence) {
  options.Check();
  const PointSet& judged = evidence ? *evidence : cloud;
  const auto start = std::chrono::steady_clock::now();
  PoseEstimate estimate;
  estimate.detected_keypoints = detected_keypoints;
  const PointSet corrector_cloud = StridedColumns(cloud, options.max_corrector_points);
  auto stage_start = std::chrono::steady_clock::now();
  if (options.correct) {
    // The fast solver's restarts are triggered by the threshold actually
    // certified (a --eps-oc override), not only the object file's.
    CorrectorOptions corrector = options.corrector;
    if (corrector.fast_restart_distance < 0 && options.certificate.eps_oc > 0) {
      corrector.fast_restart_distance = options.certificate.eps_oc;
    }
    // The robust kernel's truncation is the certified eps_oc (issue 16).
    if (corrector.robust_scale < 0 && options.certificate.eps_oc > 0) {
      corrector.robust_scale = options.certificate.eps_oc;
    }
    estimate.correction = CorrectKeypoints(object, corrector_cloud, detected_keypoints, corrector);
  } else {
    // Registration only: y* = ỹ, T̂ = T(ỹ).
    CorrectorOptions no_iterations = options.corrector;
    no_iterations.solver = CorrectorSolver::kGradientDescent;
    no_iterations.gd_max_iterations = 0;
    estimate.correction = CorrectKeypoints(object, corrector_cloud, detected_keypoints, no_iterations);
  }
  StageTimes times;   // the top level's; the replacements below carry their own
  times.corrector = MillisecondsSince(stage_start);
  estimate.keypoints = estimate.correction.keypoints;
  estimate.scene_from_model = estimate.correction.scene_from_model;
  if (estimate.ok()) {
    stage_start = std::chrono::steady_clock::now();
    estimate.certificate = Certify(object, judged, estimate.scene_from_model, estimate.keypoints,
                                   options.certificate);
    times.certificate = MillisecondsSince(stage_start);
    CompleteCertificate(object, judged, options, free_space, &estimate);
    times.free_space = estimate.ms_stages.free_space;
    times.weak_motion = estimate.ms_stages.weak_motion;
    times.rival_search = estimate.ms_stages.rival_search;
    if (options.correct && options.certificate.global.reestimate && Refuted(estimate.certificate)) {
      stage_start = std::chrono::steady_clock::now();
      Reestimate(object, cloud, judged, options, free_space, &estimate);
      times.reestimation = MillisecondsSince(stage_start);
    }
    if (options.correct && options.certificate.global.centre) {
      stage_start = std::chrono::steady_clock::now();
      Centre(object, judged, options, free_space, &estimate);
      times.centring = MillisecondsSince(stage_start);
    }
  } else {
    estimate.certificate.oc.eps_oc = options.certificate.eps_oc;
    estimate.certificate.nd.delta_nd = options.certificate.delta_nd;
  }
  estimate.ms_stages = times;
  estimate.milliseconds = MillisecondsSince(start);
  return estimate;
}

}  // namespace c3po
