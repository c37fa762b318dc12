#pragma once
// The C-3PO forward pass for one cloud (docs/method.md "Pipeline"): detected
// keypoints -> registration (eq. 8) -> corrector (eq. 17) -> certificates.
#include <chrono>

#include "c3po/method/certificate.hpp"
#include "c3po/method/corrector.hpp"
#include "c3po/method/free_space.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct PipelineOptions {
  CorrectorOptions corrector;
  CertificateOptions certificate;
  bool correct = true;    // false: certify the plain registration T(ỹ)
  // The corrector sees at most this many input points, evenly strided (0 =
  // all), so huge clouds (10^7 points) cost a bounded amount; the
  // certificates always check every input point (their definition).
  int max_corrector_points = 20000;
  void Check() const;
};

// Wall-clock milliseconds of each stage of one instance (the `ms_stages` of
// `--json`). EstimateAndCertify fills the stages from `corrector` on, each
// timed once at the top level (the rival search includes its refits, the
// re-estimation its candidates and their certificates); a batch
// (certify_batch.hpp) adds `load` (reading, segmenting), `detect` and
// `identity`.
struct StageTimes {
  double load = 0.0;
  double detect = 0.0;
  double corrector = 0.0;
  double certificate = 0.0;     // Certify: oc_m, the indicator sets, the local test
  double free_space = 0.0;
  double weak_motion = 0.0;
  double rival_search = 0.0;
  double reestimation = 0.0;
  double centring = 0.0;
  double identity = 0.0;
  double Total() const;
};

// Milliseconds of wall clock since `start` (the unit of every stage time).
double MillisecondsSince(std::chrono::steady_clock::time_point start);

struct PoseEstimate {
  PointSet detected_keypoints;    // ỹ
  PointSet keypoints;             // corrected y* (= ỹ without correction)
  Pose scene_from_model;          // T̂
  CorrectorResult correction;     // iterations, costs (trivial without correction)
  Certificate certificate;
  double milliseconds = 0.0;      // correction + certification time (with the identity check, certify_batch.hpp)
  StageTimes ms_stages;
  // Re-estimation (GlobalUniquenessOptions::reestimate): the estimate failed
  // oc or free space and the corrector restarted at the turn (axis, angle)
  // found the pose reported here (axis: a column of ReestimateAxes, 0-2 the
  // principal axes); axis -1: not re-estimated. The detected keypoints stay
  // the detector's.
  int restart_axis = -1;
  double restart_angle_deg = 0.0;
  int restarts_tried = 0;
  // Centring (GlobalUniquenessOptions::centre): the estimate was refused only
  // by rivals within 2·rival_distance, and the pose reported is the centre of
  // the `centred_fits` fits (the refused estimate and its rivals), certified
  // in full. false: the estimate (or the re-estimation's pose) as fitted.
  bool centred = false;
  int centred_fits = 0;
  bool ok() const { return correction.ok(); }
  bool certified() const { return ok() && certificate.certified(); }
};

// `free_space`: the depth frame's free-space test (image inputs), else nullptr.
// `evidence`: the cloud the certificate judges (oc_m, nd, the rival and
// weak-motion refits, re-estimation's candidates), when it is not `cloud`:
// image inputs fit the pose to the eroded mask and certify it against the
// whole one (segment.hpp); nullptr = `cloud`.
PoseEstimate EstimateAndCertify(const ObjectModel& object, const PointSet& cloud,
                                const PointSet& detected_keypoints, const PipelineOptions& options,
                                const FreeSpaceTest* free_space = nullptr, const PointSet* evidence = nullptr);

// The parts of the certificate that need more than the pose and the cloud's
// distances (EstimateAndCertify calls it after Certify; callers that decide a
// certificate again, e.g. --eps-oc auto, call it after their Certify):
//  - free space (depth-image inputs: `free_space` not null);
//  - the global rival search (options.certificate.global.enabled), run only
//    when everything else passed (it can only turn nd off): nd.global.
void CompleteCertificate(const ObjectModel& object, const PointSet& cloud, const PipelineOptions& options,
                         const FreeSpaceTest* free_space, PoseEstimate* estimate);

}  // namespace c3po
