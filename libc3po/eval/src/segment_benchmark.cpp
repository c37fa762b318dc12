// Stray points of real segments under preprocessing variants (segment_benchmark.hpp).
#include "c3po/eval/segment_benchmark.hpp"

#include <algorithm>
#include <cmath>
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

}  // namespace

void SegmentBenchmarkOptions::Check() const {
  if (bop_dir.empty()) throw InputError("c3po bench segments", "--bop DIR is required");
  if (variants.empty()) throw InputError("c3po bench segments", "no preprocessing variants");
  if (model_sample < 1000) throw InputError("c3po bench segments", "--model-sample must be >= 1000");
  for (const auto& v : variants) v.Check();
}

SegmentBenchmarkResult BenchmarkSegments(const SegmentBenchmarkOptions& options) {
  options.Check();
  // Object ids present in the ground truth (listing with a dummy id reads every scene_gt.json).
  std::vector<int> obj_ids = options.obj_ids;
  if (obj_ids.empty()) {
    std::set<int> ids;
    BopOptions probe;
    probe.obj_id = 0;
    for (const std::string& scene : ListBopInstances(options.bop_dir, probe).scene_dirs) {
      const std::string path = scene + "/scene_gt.json";
      for (const auto& [im_id, list] : ParseSceneGt(ReadFileToString(path), path)) {
        for (const auto& gt : list) ids.insert(gt.obj_id);
      }
    }
    obj_ids.assign(ids.begin(), ids.end());
  }
  SegmentBenchmarkResult result;
  const std::size_t variants = options.variants.size();
  // Per variant, per instance: fractions and counts.
  std::vector<std::vector<double>> over5(variants), over10(variants), points(variants), eroded(variants), edges(variants),
      planes(variants);
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
      ++result.instances;
      SegmentOptions all;
      all.erode_mask = 0;
      all.max_relative_depth_step = 0.0;
      all.support_plane_distance = 0.0;
      all.max_points = 0;
      const SegmentCloud every = LoadBopInstance(instance, all);
      if (every.cloud.cols() == 0) continue;
      // Distance of every valid mask pixel to the GT-posed model.
      Eigen::VectorXi indices;
      Eigen::VectorXd squared;
      tree.NearestBatch(instance.ground_truth->InverseApply(every.cloud), &indices, &squared);
      std::unordered_map<std::int32_t, double> distance;
      for (std::size_t i = 0; i < every.pixels.size(); ++i) distance[every.pixels[i]] = std::sqrt(squared(static_cast<Eigen::Index>(i)));
      for (std::size_t k = 0; k < variants; ++k) {
        SegmentOptions variant = options.variants[k];
        variant.max_points = 0;
        const SegmentCloud kept = LoadBopInstance(instance, variant);
        if (kept.pixels.empty()) continue;
        std::size_t n5 = 0, n10 = 0;
        for (std::int32_t pixel : kept.pixels) {
          const double d = distance.at(pixel);
          n5 += d > 0.005;
          n10 += d > 0.010;
        }
        const double n = static_cast<double>(kept.pixels.size());
        over5[k].push_back(n5 / n);
        over10[k].push_back(n10 / n);
        points[k].push_back(n);
        eroded[k].push_back(static_cast<double>(kept.removed_by_erosion));
        edges[k].push_back(static_cast<double>(kept.removed_by_discontinuity));
        planes[k].push_back(static_cast<double>(kept.removed_by_plane));
      }
    }
  }
  for (std::size_t k = 0; k < variants; ++k) {
    SegmentBenchmarkRow row;
    row.options = options.variants[k];
    row.instances = static_cast<int>(over5[k].size());
    if (row.instances > 0) {
      const double count = row.instances;
      auto mean = [&](const std::vector<double>& v) { double s = 0; for (double x : v) s += x; return s / count; };
      row.mean_points = mean(points[k]);
      row.median_fraction_over_5mm = Median(over5[k]);
      row.worst_fraction_over_1cm = *std::max_element(over10[k].begin(), over10[k].end());
      row.instances_at_most_5pc_over_1cm = std::count_if(over10[k].begin(), over10[k].end(), [](double f) { return f <= 0.05; }) / count;
      row.instances_at_most_2pc_over_5mm = std::count_if(over5[k].begin(), over5[k].end(), [](double f) { return f <= 0.02; }) / count;
      row.mean_removed_by_erosion = mean(eroded[k]);
      row.mean_removed_by_discontinuity = mean(edges[k]);
      row.mean_removed_by_plane = mean(planes[k]);
    }
    result.rows.push_back(row);
  }
  return result;
}

}  // namespace c3po
