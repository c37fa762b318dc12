#pragma once
// The C-3PO forward pass for one cloud (docs/method.md "Pipeline"): detected
// keypoints -> registration (eq. 8) -> corrector (eq. 17) -> certificates.
#include "c3po/method/certificate.hpp"
#include "c3po/method/corrector.hpp"
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

struct PoseEstimate {
  PointSet detected_keypoints;    // ỹ
  PointSet keypoints;             // corrected y* (= ỹ without correction)
  Pose scene_from_model;          // T̂
  CorrectorResult correction;     // iterations, costs (trivial without correction)
  Certificate certificate;
  double milliseconds = 0.0;      // correction + certification time
  bool ok() const { return correction.ok(); }
  bool certified() const { return ok() && certificate.certified(); }
};

PoseEstimate EstimateAndCertify(const ObjectModel& object, const PointSet& cloud,
                                const PointSet& detected_keypoints, const PipelineOptions& options);

}  // namespace c3po
