#include "c3po/eval/corrector_benchmark.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/base/random.hpp"
#include "c3po/eval/metrics.hpp"
#include "c3po/geometry/registration.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/synth/stray_points.hpp"
#include "c3po/synth/synth.hpp"

namespace c3po {

void CorrectorBenchmarkOptions::Check() const {
  if (sigmas.empty()) throw std::invalid_argument("at least one sigma is needed");
  for (double s : sigmas) {
    if (!(s >= 0 && std::isfinite(s))) throw std::invalid_argument("sigma must be >= 0");
  }
  if (!(fraction >= 0 && fraction <= 1)) throw std::invalid_argument("fraction must be in [0, 1]");
  if (!(stray_fraction >= 0 && stray_fraction < 10)) throw std::invalid_argument("stray_fraction must be in [0, 10)");
  if (!(correct_hausdorff > 0 && std::isfinite(correct_hausdorff))) throw std::invalid_argument("correct_hausdorff must be > 0");
  corrector.Check();
  certificate.Check();
}

namespace {

using Sample = CorrectorBenchmarkCase;

double ThreadCpuMilliseconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return 1e3 * static_cast<double>(now.tv_sec) + 1e-6 * static_cast<double>(now.tv_nsec);
}

// Registration alone (y* = ỹ, T̂ = T(ỹ)) or the corrector, then the
// certificates, each timed: wall clock, and the thread's CPU time of the
// correction (robust to other processes sharing the cores).
Sample RunOne(const ObjectModel& object, const PointSet& cloud, const PointSet& detected,
              const DatasetEntry& entry, const std::optional<CorrectorSolver>& solver,
              const CorrectorBenchmarkOptions& options, const PointSet& hausdorff_queries) {
  Sample out{};
  const double cpu_start = ThreadCpuMilliseconds();
  const auto start = std::chrono::steady_clock::now();
  Pose pose;
  PointSet keypoints = detected;
  bool ok = false;
  if (solver) {
    CorrectorOptions corrector = options.corrector;
    corrector.solver = *solver;
    // Restarts follow the threshold certified here (as in the pipeline).
    if (corrector.fast_restart_distance < 0) corrector.fast_restart_distance = options.certificate.eps_oc;
    if (corrector.robust_scale < 0) corrector.robust_scale = options.certificate.eps_oc;
    const CorrectorResult result = CorrectKeypoints(object, cloud, detected, corrector);
    ok = result.ok();
    pose = result.scene_from_model;
    keypoints = result.keypoints;
    out.iterations = result.iterations;
    out.cost_before = result.cost_before;
    out.cost_after = result.cost_after;
  } else {
    const RegistrationResult registration = RegisterPoints(object.keypoints(), detected);
    ok = registration.ok() && cloud.cols() > 0;
    pose = registration.scene_from_model;
  }
  out.corrector_ms = MillisecondsSince(start);
  out.stages.corrector = out.corrector_ms;
  out.corrector_cpu_ms = ThreadCpuMilliseconds() - cpu_start;
  const auto certify_start = std::chrono::steady_clock::now();
  PoseEstimate estimate;   // the whole certificate, with the global rival search (pipeline.hpp)
  if (ok) {
    estimate.scene_from_model = pose;
    estimate.keypoints = keypoints;
    estimate.certificate = Certify(object, cloud, pose, keypoints, options.certificate);
    out.stages.certificate = MillisecondsSince(certify_start);
    PipelineOptions pipeline;
    pipeline.corrector = options.corrector;
    if (solver) pipeline.corrector.solver = *solver;
    pipeline.certificate = options.certificate;
    CompleteCertificate(object, cloud, pipeline, nullptr, &estimate);
    out.stages.free_space = estimate.ms_stages.free_space;
    out.stages.weak_motion = estimate.ms_stages.weak_motion;
    out.stages.rival_search = estimate.ms_stages.rival_search;
  }
  const Certificate& certificate = estimate.certificate;
  out.oc = ok && certificate.oc.passed;
  out.certified = ok && certificate.certified();
  out.nd_local = ok && certificate.nd.local.passed;
  out.nd_eigenvalue = certificate.nd.local.min_eigenvalue;
  out.certify_ms = MillisecondsSince(certify_start);
  out.hausdorff = ok ? PosedModelHausdorff(object, hausdorff_queries, *entry.pose, pose)
                     : std::numeric_limits<double>::infinity();
  const double d = object.diameter();
  out.rotation_deg = RotationError(pose.R, entry.pose->R) * 180.0 / M_PI;
  out.translation_over_d = TranslationError(pose.t, entry.pose->t) / d;
  out.adds_over_d = AddS(object.tree(), *entry.pose, pose) / d;
  return out;
}

double Mean(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}

// Pose errors, % oc, iterations and times of the samples.
void SummariseAccuracyAndSpeed(const std::vector<Sample>& samples, CorrectorBenchmarkRow* row) {
  std::vector<double> rot, trans, adds, ms, corrector_ms, corrector_cpu_ms, certify_ms;
  double oc = 0, iterations = 0;
  for (const auto& s : samples) {
    rot.push_back(s.rotation_deg);
    trans.push_back(s.translation_over_d);
    adds.push_back(s.adds_over_d);
    ms.push_back(s.corrector_ms + s.certify_ms);
    corrector_ms.push_back(s.corrector_ms);
    corrector_cpu_ms.push_back(s.corrector_cpu_ms);
    certify_ms.push_back(s.certify_ms);
    row->mean_stages.corrector += s.stages.corrector;
    row->mean_stages.certificate += s.stages.certificate;
    row->mean_stages.free_space += s.stages.free_space;
    row->mean_stages.weak_motion += s.stages.weak_motion;
    row->mean_stages.rival_search += s.stages.rival_search;
    oc += s.oc;
    iterations += s.iterations;
  }
  row->median_rotation_deg = Median(rot);
  row->mean_rotation_deg = Mean(rot);
  row->median_translation_over_d = Median(trans);
  row->mean_translation_over_d = Mean(trans);
  row->median_adds_over_d = Median(adds);
  row->percent_oc = samples.empty() ? 0.0 : 100.0 * oc / static_cast<double>(samples.size());
  if (!samples.empty()) {
    const double n = static_cast<double>(samples.size());
    for (double* stage : {&row->mean_stages.corrector, &row->mean_stages.certificate, &row->mean_stages.free_space,
                          &row->mean_stages.weak_motion, &row->mean_stages.rival_search}) {
      *stage /= n;
    }
  }
  row->median_ms = Median(ms);
  row->mean_ms = Mean(ms);
  row->median_corrector_ms = Median(corrector_ms);
  row->mean_corrector_ms = Mean(corrector_ms);
  row->median_corrector_cpu_ms = Median(corrector_cpu_ms);
  row->median_certify_ms = Median(certify_ms);
  row->mean_iterations = samples.empty() ? 0.0 : iterations / static_cast<double>(samples.size());
}

// Certified, correct (Hausdorff <= correct_hausdorff) and false certificates; the local test's evidence.
void SummariseCertificates(const std::vector<Sample>& samples, double correct_hausdorff, CorrectorBenchmarkRow* row) {
  int certified = 0, correct = 0, correct_certified = 0, nd_local = 0;
  std::vector<double> hausdorff, correct_eigenvalues;
  for (const auto& s : samples) {
    const bool is_correct = s.hausdorff <= correct_hausdorff;
    certified += s.certified;
    correct += is_correct;
    correct_certified += is_correct && s.certified;
    nd_local += s.nd_local;
    if (s.certified && !is_correct) ++row->false_certificates;
    if (s.certified) row->max_certified_hausdorff = std::max(row->max_certified_hausdorff, s.hausdorff);
    hausdorff.push_back(s.hausdorff);
    if (is_correct) correct_eigenvalues.push_back(s.nd_eigenvalue);
  }
  const double count = std::max<double>(1.0, static_cast<double>(samples.size()));
  row->percent_certified = 100.0 * certified / count;
  row->percent_correct = 100.0 * correct / count;
  row->percent_correct_certified = correct > 0 ? 100.0 * correct_certified / correct : 0.0;
  row->percent_nd_local = 100.0 * nd_local / count;
  row->median_hausdorff = Median(hausdorff);
  if (!correct_eigenvalues.empty()) {
    std::sort(correct_eigenvalues.begin(), correct_eigenvalues.end());
    row->q05_nd_eigenvalue_correct = correct_eigenvalues[correct_eigenvalues.size() / 20];
  }
}

CorrectorBenchmarkRow Summarise(double sigma, const std::string& method, const std::vector<Sample>& samples,
                                double correct_hausdorff) {
  CorrectorBenchmarkRow row;
  row.sigma = sigma;
  row.method = method;
  row.clouds = static_cast<int>(samples.size());
  SummariseAccuracyAndSpeed(samples, &row);
  SummariseCertificates(samples, correct_hausdorff, &row);
  return row;
}

// The first `count` clouds show the object (their label, if any, is its name) with its number of keypoints.
void CheckBenchmarkClouds(const ObjectModel& object, const Dataset& dataset, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    const DatasetEntry& entry = dataset.entries[i];
    const std::string line = dataset.dir + "/manifest.jsonl: line " + std::to_string(i + 1) + " (" + entry.cloud + ")";
    if (!dataset.Shows(i, object.name())) {
      throw InputError(line, "a cloud of object '" + *entry.object + "', not '" + object.name() + "'");
    }
    if (entry.keypoints->cols() != object.num_keypoints()) {
      throw InputError(line, std::to_string(entry.keypoints->cols()) + " keypoints, the object '" + object.name() +
                                 "' has " + std::to_string(object.num_keypoints()));
    }
  }
}

}  // namespace

std::vector<CorrectorBenchmarkRow> RunCorrectorBenchmark(const ObjectModel& object,
                                                         const Dataset& dataset,
                                                         const CorrectorBenchmarkOptions& options,
                                                         const ProgressCallback& progress,
                                                         std::vector<CorrectorBenchmarkCase>* cases) {
  options.Check();
  if (!dataset.HasGroundTruth()) throw InputError(dataset.dir, "the corrector benchmark needs ground-truth poses and keypoints");
  std::size_t count = dataset.entries.size();
  if (options.max_clouds > 0) count = std::min<std::size_t>(count, options.max_clouds);
  CheckBenchmarkClouds(object, dataset, count);
  std::vector<PointSet> clouds(count);
  ParallelFor(0, static_cast<int>(count), [&](int i) {
    clouds[i] = dataset.LoadCloud(i);
    if (options.stray_fraction > 0) {
      Rng rng = Rng::ForItem(options.seed ^ 0x5157a9ULL, static_cast<std::uint64_t>(i));
      const int stray = static_cast<int>(std::floor(options.stray_fraction * static_cast<double>(clouds[i].cols())));
      clouds[i] = AddStrayPoints(clouds[i], stray, object.diameter(), rng);
    }
  });
  const PointSet hausdorff_queries = StridedColumns(object.sample(), 2000);

  // Methods: registration alone, then the corrector with each solver.
  std::vector<std::pair<std::string, std::optional<CorrectorSolver>>> methods = {{"registration", std::nullopt}};
  for (CorrectorSolver solver : options.solvers) {
    methods.push_back({std::string("corrector (") + ToString(solver) + ")", solver});
  }
  const double d = object.diameter();
  const std::size_t total = options.sigmas.size() * methods.size() * count;
  std::atomic<std::size_t> done{0};
  std::vector<CorrectorBenchmarkRow> rows;
  for (std::size_t s = 0; s < options.sigmas.size(); ++s) {
    const double sigma = options.sigmas[s];
    for (const auto& method_and_solver : methods) {
      // Named copies: lambdas may not capture structured bindings in C++17.
      const std::string& method = method_and_solver.first;
      const std::optional<CorrectorSolver>& solver = method_and_solver.second;
      std::vector<Sample> samples(count);
      ParallelFor(0, static_cast<int>(count), [&](int i) {
        ThrowIfInterrupted();
        const DatasetEntry& entry = dataset.entries[i];
        // The same perturbation for every method at this sigma.
        Rng rng = Rng::ForItem(options.seed + 7919 * s, static_cast<std::uint64_t>(i));
        const PointSet detected = PerturbKeypoints(*entry.keypoints, sigma, options.fraction, d, rng);
        samples[i] = RunOne(object, clouds[i], detected, entry, solver, options, hausdorff_queries);
        samples[i].sigma = sigma;
        samples[i].method = method;
        samples[i].cloud = i;
        samples[i].detected_keypoints = detected;
        if (progress) progress(++done, total);
      }, options.threads);
      rows.push_back(Summarise(sigma, method, samples, options.correct_hausdorff));
      if (cases) cases->insert(cases->end(), samples.begin(), samples.end());
    }
  }
  return rows;
}

}  // namespace c3po
