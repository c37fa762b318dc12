// c3po bench segments: stray points of real segments (BOP folder with ground
// truth) under mask erosion / depth-discontinuity variants; the measurement
// behind SegmentOptions' defaults. Registered by bench_entries.cpp.
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "c3po/base/error.hpp"
#include "c3po/eval/segment_benchmark.hpp"
#include "command.hpp"

namespace c3po::cli {
namespace {

struct SegmentsBenchCommand {
  std::string bop_dir;
  std::string models_dir;
  std::vector<int> obj_ids;
  std::string erode = "0,1,2,3,4,6";
  std::string steps = "0,0.01,0.02,0.03,0.05";
  std::string planes = "0,0.01";
  int model_sample = 100000;
};

template <typename T>
std::vector<T> ParseList(const std::string& text, const std::string& option) {
  std::vector<T> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    std::istringstream one(item);
    T value;
    if (!(one >> value) || !one.eof()) throw InputError(option, "'" + item + "' is not a number");
    values.push_back(value);
  }
  return values;
}

int RunSegmentsBench(const SegmentsBenchCommand& cmd) {
  SegmentBenchmarkOptions options;
  options.bop_dir = cmd.bop_dir;
  options.models_dir = cmd.models_dir.empty()
                           ? (std::filesystem::path(cmd.bop_dir).parent_path() / "models").string()
                           : cmd.models_dir;
  options.obj_ids = cmd.obj_ids;
  options.model_sample = cmd.model_sample;
  for (int erode : ParseList<int>(cmd.erode, "--erode")) {
    for (double step : ParseList<double>(cmd.steps, "--depth-steps")) {
      for (double plane : ParseList<double>(cmd.planes, "--support-planes")) {
        SegmentOptions variant;
        variant.erode_mask_metres = 0.0;
        variant.erode_mask = erode;
        variant.max_relative_depth_step = step;
        variant.support_plane_distance = plane;
        variant.max_points = 0;
        try {
          variant.Check();
        } catch (const std::invalid_argument& e) {
          throw InputError("segments", e.what());
        }
        options.variants.push_back(variant);
      }
    }
  }
  const SegmentBenchmarkResult result = BenchmarkSegments(options);
  std::printf("bench segments %s: %d instances with ground truth; distances to a %d-point surface sample "
              "(spacing <= %.2f mm)\n",
              cmd.bop_dir.c_str(), result.instances, cmd.model_sample, 1000.0 * result.max_sample_spacing);
  std::printf("%6s %7s %7s %9s %12s %12s %14s %14s %9s %9s\n", "erode", "step", "plane", "instances", "mean points",
              "median>5mm", "inst<=5%>1cm", "inst<=2%>5mm", "worst>1cm", "-erosion");
  for (const SegmentBenchmarkRow& row : result.rows) {
    std::printf("%6d %7.3f %7.3f %9d %12.0f %11.2f%% %13.1f%% %13.1f%% %8.1f%% %9.0f  -edges %.0f  -plane %.0f\n",
                row.options.erode_mask, row.options.max_relative_depth_step, row.options.support_plane_distance,
                row.instances, row.mean_points,
                100.0 * row.median_fraction_over_5mm, 100.0 * row.instances_at_most_5pc_over_1cm,
                100.0 * row.instances_at_most_2pc_over_5mm, 100.0 * row.worst_fraction_over_1cm,
                row.mean_removed_by_erosion, row.mean_removed_by_discontinuity, row.mean_removed_by_plane);
  }
  return 0;
}

}  // namespace

void SetupSegmentsBench(CLI::App& parent, std::function<int()>* run) {
  auto cmd = std::make_shared<SegmentsBenchCommand>();
  CLI::App* sub = parent.add_subcommand("segments", "Stray points of real segments under mask erosion and the depth-discontinuity filter");
  sub->add_option("--bop", cmd->bop_dir, "BOP scene or split folder with scene_gt.json")->required();
  sub->add_option("--models", cmd->models_dir, "Folder of obj_XXXXXX.ply in mm (default: DIR/../models)");
  sub->add_option("--obj-id", cmd->obj_ids, "Only these objects (repeatable; default every object)");
  sub->add_option("--erode", cmd->erode, "Erosion radii to try (pixels)")->capture_default_str();
  sub->add_option("--depth-steps", cmd->steps, "Relative depth-step thresholds to try (0 = off)")->capture_default_str();
  sub->add_option("--support-planes", cmd->planes, "Support-plane distances to try (metres; 0 = off)")
      ->capture_default_str();
  sub->add_option("--model-sample", cmd->model_sample, "Surface points per model")->capture_default_str();
  sub->footer("Example:\n  c3po bench segments --bop ../shared/data/real/ycbv-bop/test");
  sub->callback([cmd, run]() { *run = [cmd]() { return RunSegmentsBench(*cmd); }; });
}

}  // namespace c3po::cli
