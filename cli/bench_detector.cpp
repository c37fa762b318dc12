// c3po bench detector: detection time per cloud of a detector on a dataset,
// one cloud at a time on one thread (the figure eval's per-row times leave
// out: they count correction + certification only). No output file.
// Registered by bench_entries.cpp as {SetupDetectorBench}.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "c3po/base/error.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/object/object_io.hpp"
#include "command.hpp"
#include "options.hpp"

namespace c3po::cli {
namespace {

struct DetectorBenchCommand {
  std::string object_path;
  std::string data_dir;
  DetectorFlags detector;
  int count = 0;
};

int RunDetectorBench(const DetectorBenchCommand& cmd) {
  if (cmd.detector.models.size() + cmd.detector.detectors.size() != 1) {
    throw InputError("detector", "give exactly one of --model FILE or --detector NAME");
  }
  if (cmd.count < 0) throw InputError("detector", "--count must be >= 0");
  const ObjectModel object = LoadObject(cmd.object_path);
  const Dataset dataset = ReadDataset(cmd.data_dir);
  LoadPlugins(cmd.detector);
  const std::unique_ptr<Detector> detector =
      MakeDetector(cmd.detector.models.empty() ? "" : cmd.detector.models.front(),
                   cmd.detector.detectors.empty() ? "" : cmd.detector.detectors.front(), object);
  const std::size_t n = cmd.count > 0 ? std::min<std::size_t>(cmd.count, dataset.entries.size()) : dataset.entries.size();
  std::vector<double> ms;
  int failures = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const PointSet cloud = dataset.LoadCloud(i);
    const auto start = std::chrono::steady_clock::now();
    try {
      detector->Detect(cloud);
    } catch (const InputError&) {
      ++failures;
    }
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  if (ms.empty()) throw InputError(cmd.data_dir, "no clouds");
  double total = 0;
  for (double m : ms) total += m;
  std::sort(ms.begin(), ms.end());
  std::printf("detector %s on %s: %zu clouds, one thread: mean %.1f ms, median %.1f ms, max %.1f ms per cloud; "
              "%d detection failures\n",
              detector->name().c_str(), cmd.data_dir.c_str(), ms.size(), total / ms.size(), ms[ms.size() / 2],
              ms.back(), failures);
  return 0;
}

}  // namespace

void SetupDetectorBench(CLI::App& parent, std::function<int()>* run) {
  auto cmd = std::make_shared<DetectorBenchCommand>();
  CLI::App* sub = parent.add_subcommand("detector", "Detection time per cloud of a detector on a dataset (one thread)");
  sub->add_option("object", cmd->object_path, "Object JSON")->required();
  sub->add_option("--data", cmd->data_dir, "Dataset folder (manifest.jsonl + clouds)")->required();
  AddDetectorOptions(*sub, &cmd->detector, DetectorCount::kOne);
  sub->add_option("--count", cmd->count, "Only the first N clouds (0 = all)");
  sub->footer("Example:\n  c3po bench detector drill.json --data data/drill_depth --detector fpfh");
  sub->callback([cmd, run]() { *run = [cmd]() { return RunDetectorBench(*cmd); }; });
}

}  // namespace c3po::cli
