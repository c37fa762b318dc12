#pragma once
// The paper's corrector analysis (Section VIII-A, Fig. "corrector analysis"):
// perturb the ground-truth keypoints of each cloud — every keypoint, with
// probability `fraction`, gets uniform noise in [-sigma d/2, sigma d/2] per
// coordinate — then compare registration alone with registration + corrector.
#include <string>
#include <vector>

#include "c3po/io/dataset.hpp"
#include "c3po/method/certificate.hpp"
#include "c3po/method/corrector.hpp"
#include "c3po/method/detector.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct CorrectorBenchmarkOptions {
  std::vector<double> sigmas = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0};
  double fraction = 0.8;
  std::vector<CorrectorSolver> solvers = {CorrectorSolver::kFast};
  CorrectorOptions corrector;          // solver field is overridden per row
  CertificateOptions certificate;
  std::uint64_t seed = 0;
  int threads = 1;                     // 1 = honest per-cloud timings
  int max_clouds = 0;                  // 0 = all
  // Issue 16: stray points added to every cloud (AddStrayPoints; this
  // fraction of its points, seeded by `seed`), and the Hausdorff distance
  // (posed model vs posed model, object units) under which a pose is correct.
  double stray_fraction = 0.0;
  double correct_hausdorff = 0.02;
  void Check() const;
};

// One (sigma, method) cell: method is "registration" or "corrector (fast|gd)".
struct CorrectorBenchmarkRow {
  double sigma = 0.0;
  std::string method;
  int clouds = 0;
  double median_rotation_deg = 0.0, mean_rotation_deg = 0.0;
  double median_translation_over_d = 0.0, mean_translation_over_d = 0.0;
  double median_adds_over_d = 0.0;
  double percent_oc = 0.0;
  // Wall-clock per cloud: correction (registration alone: T(ỹ)) + certificates.
  double median_ms = 0.0, mean_ms = 0.0;
  double median_corrector_ms = 0.0, mean_corrector_ms = 0.0;   // correction only
  double median_corrector_cpu_ms = 0.0;  // correction only, the thread's CPU time
  double median_certify_ms = 0.0;        // certificates only
  StageTimes mean_stages;                // mean ms per cloud of each stage (pipeline.hpp; no load, detect)
  double mean_iterations = 0.0;
  // Certificates (oc_m and nd_m) against the Hausdorff distance to the truth.
  double percent_certified = 0.0;
  double percent_correct = 0.0;           // Hausdorff <= correct_hausdorff
  double percent_correct_certified = 0.0; // of the correct poses, certified
  int false_certificates = 0;             // certified and not correct
  double max_certified_hausdorff = 0.0;
  double median_hausdorff = 0.0;
  double q05_nd_eigenvalue_correct = 0.0; // 5 % quantile of λ_min over correct poses
  double percent_nd_local = 0.0;          // local non-degeneracy passed
};

// One cloud of one cell, with its input: lets another implementation rerun
// the very same cases (libc3po/eval/bench/pytorch_corrector_gd.py).
struct CorrectorBenchmarkCase {
  double sigma = 0.0;
  std::string method;
  int cloud = 0;                      // dataset entry index
  PointSet detected_keypoints;        // the perturbed ground truth ỹ
  double rotation_deg = 0.0, translation_over_d = 0.0, adds_over_d = 0.0;
  double corrector_ms = 0.0, corrector_cpu_ms = 0.0, certify_ms = 0.0;
  StageTimes stages;                  // corrector, certificate (Certify), free space, weak motion, rival search
  int iterations = 0;
  double cost_before = 0.0, cost_after = 0.0;   // f(ỹ), f(y*); 0 for registration alone
  bool oc = false;
  bool certified = false;
  bool nd_local = false;
  double hausdorff = 0.0;          // Hausdorff(T*·B̂, T̂·B̂)
  double nd_eigenvalue = 0.0;
};

// Requires ground truth (pose + keypoints) in every entry. With `cases`, also
// appends every cloud's case (rows' order, then cloud order).
std::vector<CorrectorBenchmarkRow> RunCorrectorBenchmark(const ObjectModel& object,
                                                         const Dataset& dataset,
                                                         const CorrectorBenchmarkOptions& options,
                                                         const ProgressCallback& progress = {},
                                                         std::vector<CorrectorBenchmarkCase>* cases = nullptr);

}  // namespace c3po
