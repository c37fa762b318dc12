// Stray points of real segments under preprocessing variants (segment_benchmark.hpp).
#include "c3po/eval/segment_benchmark.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <unordered_map>

#include "c3po/base/atomic_file.hpp"
#include "c3po/io/bop.hpp"
#include "c3po/base/error.hpp"
#include "c3po/geometry/kdtree.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/io/mesh_io.hpp"
#include "c3po/base/parallel.hpp"

namespace c3po {
namespace {

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::string Id6(int id) {
  char text[16];
  std::snprintf(text, sizeof text, "%06d", id);
  return text;
}

// Object ids present in the ground truth (listing with a dummy id reads every scene_gt.json).
std::vector<int> ObjectIdsInGroundTruth(const std::string& bop_dir) {
  std::set<int> ids;
  BopOptions probe;
  probe.obj_id = 0;
  for (const std::string& scene : ListBopInstances(bop_dir, probe).scene_dirs) {
    const std::string path = scene + "/scene_gt.json";
    for (const auto& [im_id, list] : ParseSceneGt(ReadFileToString(path), path)) {
      for (const auto& gt : list) ids.insert(gt.obj_id);
    }
  }
  return {ids.begin(), ids.end()};
}

// Distance of every valid mask pixel's point (no preprocessing) to the ground-truth-posed model.
std::unordered_map<std::int32_t, double> DistanceByPixel(const BopInstance& instance, const PointTree& model) {
  SegmentOptions all;
  all.erode_mask_metres = 0.0;
  all.erode_mask = 0;
  all.max_relative_depth_step = 0.0;
  all.support_plane_distance = 0.0;
  all.max_points = 0;
  const SegmentCloud every = LoadBopInstance(instance, all);
  std::unordered_map<std::int32_t, double> distance;
  if (every.cloud.cols() == 0) return distance;
  Eigen::VectorXi indices;
  Eigen::VectorXd squared;
  model.NearestBatch(instance.ground_truth->InverseApply(every.cloud), &indices, &squared);
  for (std::size_t i = 0; i < every.pixels.size(); ++i) {
    distance[every.pixels[i]] = std::sqrt(squared(static_cast<Eigen::Index>(i)));
  }
  return distance;
}

// One variant's per-instance figures.
struct VariantSamples {
  std::vector<double> over5, over10, points, eroded, edges, planes;

  void Add(const SegmentCloud& kept, const std::unordered_map<std::int32_t, double>& distance) {
    std::size_t n5 = 0, n10 = 0;
    for (std::int32_t pixel : kept.pixels) {
      const double d = distance.at(pixel);
      n5 += d > 0.005;
      n10 += d > 0.010;
    }
    const double n = static_cast<double>(kept.pixels.size());
    over5.push_back(n5 / n);
    over10.push_back(n10 / n);
    points.push_back(n);
    eroded.push_back(static_cast<double>(kept.removed_by_erosion));
    edges.push_back(static_cast<double>(kept.removed_by_discontinuity));
    planes.push_back(static_cast<double>(kept.removed_by_plane));
  }

  SegmentBenchmarkRow Row(const SegmentOptions& options) const {
    SegmentBenchmarkRow row;
    row.options = options;
    row.instances = static_cast<int>(over5.size());
    if (row.instances == 0) return row;
    const double count = row.instances;
    const auto mean = [count](const std::vector<double>& v) {
      return std::accumulate(v.begin(), v.end(), 0.0) / count;
    };
    const auto share_at_most = [count](const std::vector<double>& v, double limit) {
      return std::count_if(v.begin(), v.end(), [limit](double f) { return f <= limit; }) / count;
    };
    row.mean_points = mean(points);
    row.median_fraction_over_5mm = Median(over5);
    row.worst_fraction_over_1cm = *std::max_element(over10.begin(), over10.end());
    row.instances_at_most_5pc_over_1cm = share_at_most(over10, 0.05);
    row.instances_at_most_2pc_over_5mm = share_at_most(over5, 0.02);
    row.mean_removed_by_erosion = mean(eroded);
    row.mean_removed_by_discontinuity = mean(edges);
    row.mean_removed_by_plane = mean(planes);
    return row;
  }
};

}  // namespace


void SegmentBenchmarkOptions::Check() const {
  if (bop_dir.empty()) throw InputError("c3po bench segments", "--bop DIR is required");
  if (variants.empty()) throw InputError("c3po bench segments", "no preprocessing variants");
  if (model_sample < 1000) throw InputError("c3po bench segments", "--model-sample must be >= 1000");
  for (const auto& v : variants) v.Check();
}

SegmentBenchmarkResult BenchmarkSegments(const SegmentBenchmarkOptions& options) {
  options.Check();
  const std::vector<int> obj_ids =
      options.obj_ids.empty() ? ObjectIdsInGroundTruth(options.bop_dir) : options.obj_ids;
  SegmentBenchmarkResult result;
  std::vector<VariantSamples> samples(options.variants.size());
  for (int obj_id : obj_ids) {
    BopOptions bop;
    bop.obj_id = obj_id;
    const BopInstances listed = ListBopInstances(options.bop_dir, bop);
    if (listed.instances.empty()) continue;
    const Mesh mesh = LoadMesh(options.models_dir + "/obj_" + Id6(obj_id) + ".ply", kMetresPerMillimetre);
    const PointTree tree(SampleSurface(mesh, options.model_sample, options.seed));
    result.max_sample_spacing = std::max(result.max_sample_spacing,
                                         std::sqrt(mesh.SurfaceArea() / options.model_sample));
    for (const BopInstance& instance : listed.instances) {
      if (!instance.ground_truth) continue;   // its pose is unusable: listed.warnings says why
      ++result.instances;
      const std::unordered_map<std::int32_t, double> distance = DistanceByPixel(instance, tree);
      if (distance.empty()) continue;
      for (std::size_t k = 0; k < samples.size(); ++k) {
        SegmentOptions variant = options.variants[k];
        variant.max_points = 0;
        const SegmentCloud kept = LoadBopInstance(instance, variant);
        if (!kept.pixels.empty()) samples[k].Add(kept, distance);
      }
    }
  }
  for (std::size_t k = 0; k < samples.size(); ++k) result.rows.push_back(samples[k].Row(options.variants[k]));
  return result;
}

}  // namespace c3po
