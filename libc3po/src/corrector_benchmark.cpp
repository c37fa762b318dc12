#include "c3po/corrector_benchmark.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "c3po/error.hpp"
#include "c3po/interrupt.hpp"
#include "c3po/metrics.hpp"
#include "c3po/parallel.hpp"
#include "c3po/pipeline.hpp"
#include "c3po/random.hpp"
#include "c3po/synth.hpp"

namespace c3po {

void CorrectorBenchmarkOptions::Check() const {
  if (sigmas.empty()) throw std::invalid_argument("at least one sigma is needed");
  for (double s : sigmas) {
    if (!(s >= 0 && std::isfinite(s))) throw std::invalid_argument("sigma must be >= 0");
  }
  if (!(fraction >= 0 && fraction <= 1)) throw std::invalid_argument("fraction must be in [0, 1]");
  corrector.Check();
  certificate.Check();
}

namespace {

struct Sample {
  double rotation_deg, translation_over_d, adds_over_d, ms;
  int iterations;
  bool oc;
};

CorrectorBenchmarkRow Summarise(double sigma, const std::string& method, const std::vector<Sample>& samples) {
  CorrectorBenchmarkRow row;
  row.sigma = sigma;
  row.method = method;
  row.clouds = static_cast<int>(samples.size());
  std::vector<double> rot, trans, adds, ms;
  double oc = 0, iterations = 0;
  for (const auto& s : samples) {
    rot.push_back(s.rotation_deg);
    trans.push_back(s.translation_over_d);
    adds.push_back(s.adds_over_d);
    ms.push_back(s.ms);
    oc += s.oc;
    iterations += s.iterations;
  }
  auto mean = [](const std::vector<double>& v) {
    double sum = 0;
    for (double x : v) sum += x;
    return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
  };
  row.median_rotation_deg = Median(rot);
  row.mean_rotation_deg = mean(rot);
  row.median_translation_over_d = Median(trans);
  row.mean_translation_over_d = mean(trans);
  row.median_adds_over_d = Median(adds);
  row.percent_oc = samples.empty() ? 0.0 : 100.0 * oc / static_cast<double>(samples.size());
  row.median_ms = Median(ms);
  row.mean_ms = mean(ms);
  row.mean_iterations = samples.empty() ? 0.0 : iterations / static_cast<double>(samples.size());
  return row;
}

}  // namespace

std::vector<CorrectorBenchmarkRow> RunCorrectorBenchmark(const ObjectModel& object,
                                                         const Dataset& dataset,
                                                         const CorrectorBenchmarkOptions& options,
                                                         const ProgressCallback& progress) {
  options.Check();
  if (!dataset.HasGroundTruth()) throw InputError(dataset.dir, "the corrector benchmark needs ground-truth poses and keypoints");
  std::size_t count = dataset.entries.size();
  if (options.max_clouds > 0) count = std::min<std::size_t>(count, options.max_clouds);
  std::vector<PointSet> clouds(count);
  ParallelFor(0, static_cast<int>(count), [&](int i) { clouds[i] = dataset.LoadCloud(i); });

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
        PipelineOptions pipeline;
        pipeline.corrector = options.corrector;
        pipeline.certificate = options.certificate;
        pipeline.correct = solver.has_value();
        if (solver) pipeline.corrector.solver = *solver;
        const PoseEstimate estimate = EstimateAndCertify(object, clouds[i], detected, pipeline);
        Sample& out = samples[i];
        out.rotation_deg = RotationError(estimate.scene_from_model.R, entry.pose->R) * 180.0 / M_PI;
        out.translation_over_d = TranslationError(estimate.scene_from_model.t, entry.pose->t) / d;
        out.adds_over_d = AddS(object.tree(), *entry.pose, estimate.scene_from_model) / d;
        out.ms = estimate.milliseconds;
        out.iterations = estimate.correction.iterations;
        out.oc = estimate.ok() && estimate.certificate.oc.passed;
        if (progress) progress(++done, total);
      }, options.threads);
      rows.push_back(Summarise(sigma, method, samples));
    }
  }
  return rows;
}

}  // namespace c3po
