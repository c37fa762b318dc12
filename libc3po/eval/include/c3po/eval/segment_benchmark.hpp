#pragma once
// How much of a real segment is stray (issue 15): every instance of a BOP
// folder with ground truth, back-projected under several preprocessing
// settings, each point's distance to the model posed at the ground truth.
// Measures what the defaults of SegmentOptions were chosen by
// (`c3po bench segments`, docs/camera_inputs.md). Distances are to a dense
// surface sample (spacing reported), so they overestimate by at most about
// half the spacing.
#include <map>
#include <string>
#include <vector>

#include "c3po/io/segment.hpp"

namespace c3po {

struct SegmentBenchmarkOptions {
  std::string bop_dir;                        // scene or split folder with scene_gt.json
  std::string models_dir;                     // obj_XXXXXX.ply in mm (BOP models/)
  std::vector<int> obj_ids;                   // empty = every object in scene_gt.json
  std::vector<SegmentOptions> variants;       // max_points is ignored (0)
  int model_sample = 100000;                  // surface sample per model
  std::uint64_t seed = 0;
  void Check() const;                         // throws InputError
};

struct SegmentBenchmarkRow {
  SegmentOptions options;
  int instances = 0;                          // with at least one point
  double mean_points = 0.0;
  double median_fraction_over_5mm = 0.0;
  double worst_fraction_over_1cm = 0.0;
  double instances_at_most_5pc_over_1cm = 0.0;   // fraction of instances
  double instances_at_most_2pc_over_5mm = 0.0;
  double mean_removed_by_erosion = 0.0;
  double mean_removed_by_discontinuity = 0.0;
  double mean_removed_by_plane = 0.0;
};

struct SegmentBenchmarkResult {
  std::vector<SegmentBenchmarkRow> rows;      // one per variant
  int instances = 0;                          // listed (with GT)
  double max_sample_spacing = 0.0;            // metres, over the models
};

SegmentBenchmarkResult BenchmarkSegments(const SegmentBenchmarkOptions& options);

}  // namespace c3po
