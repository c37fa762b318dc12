#include "c3po/pipeline.hpp"

#include <chrono>

#include "c3po/registration.hpp"

namespace c3po {

void PipelineOptions::Check() const {
  corrector.Check();
  certificate.Check();
}

PoseEstimate EstimateAndCertify(const ObjectModel& object, const PointSet& cloud,
                                const PointSet& detected_keypoints, const PipelineOptions& options) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  PoseEstimate estimate;
  estimate.detected_keypoints = detected_keypoints;
  if (options.correct) {
    estimate.correction = CorrectKeypoints(object, cloud, detected_keypoints, options.corrector);
  } else {
    // Registration only: y* = ỹ, T̂ = T(ỹ).
    CorrectorOptions no_iterations = options.corrector;
    no_iterations.solver = CorrectorSolver::kGradientDescent;
    no_iterations.gd_max_iterations = 0;
    estimate.correction = CorrectKeypoints(object, cloud, detected_keypoints, no_iterations);
  }
  estimate.keypoints = estimate.correction.keypoints;
  estimate.scene_from_model = estimate.correction.scene_from_model;
  if (estimate.ok()) {
    estimate.certificate = Certify(object, cloud, estimate.scene_from_model, estimate.keypoints,
                                   options.certificate);
  } else {
    estimate.certificate.oc.eps_oc = options.certificate.eps_oc;
    estimate.certificate.nd.delta_nd = options.certificate.delta_nd;
  }
  estimate.milliseconds =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return estimate;
}

}  // namespace c3po
