// Synthetic datasets on all cores (WriteSynthDataset) and their benchmark.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "c3po/base/interrupt.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/io/dataset_writer.hpp"
#include "c3po/synth/synth.hpp"
#include "run_batch.hpp"

namespace c3po {
namespace {

// What a sample contributes to the report.
struct SampleStats {
  int points = 0;
  int attempts = 1;
  double visible_fraction = 1.0;
};

SampleStats StatsOf(const SynthSample& sample) {
  SampleStats stats;
  stats.points = static_cast<int>(sample.cloud.cols());
  stats.attempts = sample.attempts;
  if (sample.visible && !sample.visible->empty()) {
    const auto seen = std::count(sample.visible->begin(), sample.visible->end(), true);
    stats.visible_fraction = static_cast<double>(seen) / static_cast<double>(sample.visible->size());
  }
  return stats;
}

std::string CloudName(std::size_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "%06zu.ply", index);
  return name;
}

// The manifest's "object" label: the object's name, when it is a valid label.
std::optional<std::string> LabelOf(const std::string& name) {
  if (name.empty() || name.size() > 256) return std::nullopt;
  for (unsigned char c : name) {
    if (c < 0x20 || c == 0x7f) return std::nullopt;
  }
  return name;
}

DatasetEntry EntryOf(const SynthSample& sample, std::size_t index, const std::optional<std::string>& label) {
  DatasetEntry entry;
  entry.object = label;
  entry.cloud = CloudName(index);
  entry.pose = sample.scene_from_model;
  entry.keypoints = sample.keypoints;
  entry.detected_keypoints = sample.detected_keypoints;
  entry.visible = sample.visible;
  return entry;
}

std::vector<std::unique_ptr<DepthRenderer>> MakeRenderers(const SynthGenerator& generator,
                                                          int workers) {
  std::vector<std::unique_ptr<DepthRenderer>> renderers;
  for (int w = 0; w < workers; ++w) {
    renderers.push_back(generator.options().kind == CloudKind::kDepth ? generator.MakeRenderer()
                                                                      : nullptr);
  }
  return renderers;
}

// Running sums of the per-sample figures (memory independent of the count).
class StatsAccumulator {
 public:
  void Add(const SampleStats& s) {
    min_points_ = count_ == 0 ? s.points : std::min(min_points_, s.points);
    max_points_ = count_ == 0 ? s.points : std::max(max_points_, s.points);
    ++count_;
    points_ += s.points;
    attempts_ += s.attempts;
    visible_ += s.visible_fraction;
  }
  SynthReport Report(const SynthGenerator& generator) const {
    SynthReport report;
    report.count = count_;
    report.distance_range = generator.distance_range();
    report.diameter = generator.diameter();
    if (count_ == 0) return report;
    const double n = static_cast<double>(count_);
    report.min_cloud_points = min_points_;
    report.max_cloud_points = max_points_;
    report.mean_points = points_ / n;
    report.mean_attempts = attempts_ / n;
    report.visible_keypoint_fraction = visible_ / n;
    return report;
  }

 private:
  std::size_t count_ = 0;
  int min_points_ = 0, max_points_ = 0;
  double points_ = 0.0, attempts_ = 0.0, visible_ = 0.0;
};

}  // namespace

SynthReport WriteSynthDataset(const Mesh& mesh, const ObjectSpec& spec,
                              const SynthOptions& options, const std::string& dir,
                              const SynthProgress& progress, const std::string& where) {
  const auto start = std::chrono::steady_clock::now();
  const SynthGenerator generator(
      mesh, spec.keypoints, options,
      !where.empty() ? where : spec.name.empty() ? std::string("object") : spec.name);
  DatasetWriter writer(dir);
  const std::optional<std::string> label = LabelOf(spec.name);
  const int workers = std::max(1, DefaultThreadCount());
  auto renderers = MakeRenderers(generator, workers);
  const std::size_t count = static_cast<std::size_t>(options.count);
  const std::size_t shards = static_cast<std::size_t>(options.shard.count);
  const std::size_t first = static_cast<std::size_t>(options.shard.index - 1) * count / shards;
  const std::size_t last = static_cast<std::size_t>(options.shard.index) * count / shards;
  const std::size_t batch = static_cast<std::size_t>(workers) * 32;
  StatsAccumulator accumulator;
  std::vector<SampleStats> stats(batch);
  for (std::size_t begin = first; begin < last; begin += batch) {
    const std::size_t end = std::min(last, begin + batch);
    RunBatch(generator, begin, end, renderers, [&](std::size_t i, const SynthSample& sample) {
      stats[i - begin] = StatsOf(sample);
      writer.Add(i, EntryOf(sample, i, label), sample.cloud);   // thread-safe
    });
    ThrowIfInterrupted();
    for (std::size_t i = begin; i < end; ++i) accumulator.Add(stats[i - begin]);
    if (progress) progress(end - first, last - first);
  }
  writer.Commit();
  SynthReport report = accumulator.Report(generator);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

SynthBenchmark BenchmarkSynth(const Mesh& mesh, const PointSet& keypoints,
                              const SynthOptions& options, double min_seconds) {
  const SynthGenerator generator(mesh, keypoints, options, "benchmark");
  const int workers = std::max(1, DefaultThreadCount());
  auto renderers = MakeRenderers(generator, workers);
  const std::size_t batch = static_cast<std::size_t>(options.count);
  StatsAccumulator accumulator;
  std::vector<SampleStats> stats(batch);
  const auto start = std::chrono::steady_clock::now();
  double seconds = 0.0;
  std::size_t begin = 0;
  do {
    RunBatch(generator, begin, begin + batch, renderers,
             [&](std::size_t i, const SynthSample& sample) { stats[i - begin] = StatsOf(sample); });
    ThrowIfInterrupted();
    for (const SampleStats& s : stats) accumulator.Add(s);
    begin += batch;
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  } while (seconds < min_seconds);
  const SynthReport summary = accumulator.Report(generator);
  SynthBenchmark result;
  result.kind = options.kind;
  result.clouds = summary.count;
  result.threads = workers;
  result.triangles = static_cast<long>(mesh.triangles.cols());
  result.seconds = seconds;
  result.clouds_per_second = static_cast<double>(summary.count) / seconds;
  result.mean_points = summary.mean_points;
  result.mean_attempts = summary.mean_attempts;
  return result;
}

}  // namespace c3po
