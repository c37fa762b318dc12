#include "c3po/method/pipeline.hpp"

#include <chrono>
#include <stdexcept>

#include "c3po/geometry/registration.hpp"

namespace c3po {

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
  return options.local.weak_motion_check && certificate.oc.passed && nd.sets_passed && nd.local_checked &&
         !nd.local.passed && nd.local.weak_motions == 1 && nd.local.observed_points >= options.local.min_points &&
         (!certificate.free_space.checked || certificate.free_space.passed);
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
  if (free_space) certificate.free_space = free_space->Check(estimate->scene_from_model);
  if (WeakMotionCheckApplies(certificate, options.certificate)) {
    certificate.nd.weak_motion = CheckWeakMotion(object, cloud, *estimate, options, free_space);
    certificate.nd.weak_motion_checked = true;
    certificate.nd.passed = certificate.nd.sets_passed && certificate.nd.weak_motion.passed;
  }
  if (options.certificate.global.enabled && certificate.certified()) {
    certificate.nd.global = CheckGlobalUniqueness(object, cloud, *estimate, options, free_space);
    certificate.nd.global_checked = true;
    certificate.nd.passed = certificate.nd.passed && certificate.nd.global.passed;
  }
}

PoseEstimate EstimateAndCertify(const ObjectModel& object, const PointSet& cloud,
                                const PointSet& detected_keypoints, const PipelineOptions& options,
                                const FreeSpaceTest* free_space) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  PoseEstimate estimate;
  estimate.detected_keypoints = detected_keypoints;
  const PointSet corrector_cloud = StridedColumns(cloud, options.max_corrector_points);
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
  estimate.keypoints = estimate.correction.keypoints;
  estimate.scene_from_model = estimate.correction.scene_from_model;
  if (estimate.ok()) {
    estimate.certificate = Certify(object, cloud, estimate.scene_from_model, estimate.keypoints,
                                   options.certificate);
    CompleteCertificate(object, cloud, options, free_space, &estimate);
  } else {
    estimate.certificate.oc.eps_oc = options.certificate.eps_oc;
    estimate.certificate.nd.delta_nd = options.certificate.delta_nd;
  }
  estimate.milliseconds =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return estimate;
}

}  // namespace c3po
