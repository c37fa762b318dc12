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
  double mean_iterations = 0.0;
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
  int iterations = 0;
  double cost_before = 0.0, cost_after = 0.0;   // f(ỹ), f(y*); 0 for registration alone
  bool oc = false;
};

// Requires ground truth (pose + keypoints) in every entry. With `cases`, also
// appends every cloud's case (rows' order, then cloud order).
std::vector<CorrectorBenchmarkRow> RunCorrectorBenchmark(const ObjectModel& object,
                                                         const Dataset& dataset,
                                                         const CorrectorBenchmarkOptions& options,
                                                         const ProgressCallback& progress = {},
                                                         std::vector<CorrectorBenchmarkCase>* cases = nullptr);

}  // namespace c3po
