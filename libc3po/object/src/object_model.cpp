#include "c3po/object/object_model.hpp"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <mutex>
#include <limits>
#include <set>
#include <stdexcept>

#include "c3po/base/error.hpp"

namespace c3po {

std::string ObjectSpec::KeypointName(int i) const {
  if (i >= 0 && i < static_cast<int>(keypoint_names.size()) && !keypoint_names[i].empty()) {
    return keypoint_names[i];
  }
  return "kp" + std::to_string(i);
}

void ObjectSpec::Validate(const std::string& where) const {
  auto fail = [&](const std::string& field, const std::string& problem) {
    throw InputError(where, field + ": " + problem);
  };
  if (schema_version != 1) fail("schema_version", "unsupported version " + std::to_string(schema_version));
  if (name.empty()) fail("name", "must not be empty");
  if (units != "m" && units != "mm" && units != "cm") fail("units", "must be m, cm or mm, not '" + units + "'");
  if (keypoints.cols() == 0) fail("keypoints", "at least one keypoint is required");
  if (!keypoints.allFinite()) fail("keypoints", "non-finite coordinate");
  if (!keypoint_names.empty() && keypoint_names.size() != static_cast<std::size_t>(keypoints.cols())) {
    fail("keypoint_names", std::to_string(keypoint_names.size()) + " names for " +
                               std::to_string(keypoints.cols()) + " keypoints");
  }
  for (std::size_t s = 0; s < indicator_sets.size(); ++s) {
    const auto& set = indicator_sets[s];
    const std::string field = "indicator_sets[" + std::to_string(s) + "]";
    if (set.empty()) fail(field, "empty set");
    std::set<int> seen;
    for (int index : set) {
      if (index < 0 || index >= keypoints.cols()) {
        fail(field, "keypoint index " + std::to_string(index) + " out of range [0, " +
                        std::to_string(keypoints.cols()) + ")");
      }
      if (!seen.insert(index).second) fail(field, "duplicate keypoint index " + std::to_string(index));
    }
  }
  if (!(std::isfinite(eps_oc) && eps_oc > 0)) fail("eps_oc", "must be a positive distance");
  if (!(std::isfinite(delta_nd) && delta_nd > 0)) fail("delta_nd", "must be a positive distance");
}

void ObjectModelOptions::Check() const {
  if (sample_size < 100) throw std::invalid_argument("ObjectModelOptions: sample_size must be >= 100");
}

struct ObjectModel::LazyGrid {
  std::once_flag built;
  std::unique_ptr<const NearestGrid> grid;
};

const NearestGrid& ObjectModel::grid() const {
  std::call_once(grid_->built, [this] { grid_->grid = std::make_unique<const NearestGrid>(tree_); });
  return *grid_->grid;
}

ObjectModel::ObjectModel(ObjectSpec spec, Mesh mesh, const ObjectModelOptions& options)
    : spec_(std::move(spec)), mesh_(std::move(mesh)) {
  options.Check();
  mesh_.Validate();
  if (mesh_.empty()) throw std::invalid_argument("ObjectModel: mesh has no triangles");
  SurfaceSample sample = SampleSurfaceWithTriangles(mesh_, options.sample_size, options.seed);
  auto normals = std::make_shared<PointSet>(3, sample.points.cols());
  for (Eigen::Index i = 0; i < sample.points.cols(); ++i) {
    const Eigen::Vector3i tri = mesh_.triangles.col(sample.triangle(i));
    const Eigen::Vector3d a = mesh_.vertices.col(tri(0)), b = mesh_.vertices.col(tri(1)),
                          c = mesh_.vertices.col(tri(2));
    normals->col(i) = (b - a).cross(c - a).normalized();
  }
  normals_ = std::move(normals);
  auto triangles = std::make_shared<std::vector<int>>(static_cast<std::size_t>(sample.points.cols()));
  for (Eigen::Index i = 0; i < sample.points.cols(); ++i) (*triangles)[static_cast<std::size_t>(i)] = sample.triangle(i);
  triangles_ = std::move(triangles);
  tree_ = std::make_shared<const PointTree>(std::move(sample.points));
  grid_ = std::make_shared<LazyGrid>();
  diameter_ = mesh_.Diameter();
  // Crease flags: a sample point whose 8 nearest sample neighbours include a
  // normal more than 30 degrees off its own line lies at an edge or crease,
  // where the nearest sample of a nearby point may carry the other side's
  // normal. A normal opposite to its own (within 30 degrees) is the other face
  // of a thin wall (a bowl, a mug): a point-to-plane row is the same for n and
  // -n (local_nondegeneracy.hpp), so that is no crease -- else every sample of
  // a wall thinner than the sample spacing would be flagged.
  auto crease = std::make_shared<std::vector<char>>(tree_->points().cols(), 0);
  const double cos_limit = std::cos(30.0 * M_PI / 180.0);
  for (Eigen::Index i = 0; i < tree_->points().cols(); ++i) {
    for (const auto& nb : tree_->KNearest(tree_->points().col(i), 9)) {
      if (std::abs(normals_->col(nb.index).dot(normals_->col(i))) < cos_limit) {
        (*crease)[i] = 1;
        break;
      }
    }
  }
  crease_ = std::move(crease);
}

double ObjectModel::SampleSpacing() const {
  if (spacing_ >= 0) return spacing_;
  // Mean distance of each sample point to its nearest other sample point.
  const PointSet& points = sample();
  double total = 0.0;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const auto neighbors = tree_->KNearest(points.col(i), 2);
    if (neighbors.size() == 2) total += std::sqrt(neighbors[1].squared_distance);
  }
  spacing_ = points.cols() ? total / static_cast<double>(points.cols()) : 0.0;
  return spacing_;
}

std::string ObjectModel::KeypointHash() const {
  // FNV-1a over the name and the keypoints rounded to 1e-9 object units.
  std::uint64_t hash = 1469598103934665603ULL;
  auto mix = [&hash](std::uint64_t value) {
    for (int b = 0; b < 8; ++b) {
      hash ^= (value >> (8 * b)) & 0xFF;
      hash *= 1099511628211ULL;
    }
  };
  for (char c : spec_.name) mix(static_cast<unsigned char>(c));
  for (Eigen::Index i = 0; i < spec_.keypoints.size(); ++i) {
    mix(static_cast<std::uint64_t>(std::llround(spec_.keypoints.data()[i] * 1e9)));
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

void ObjectModel::NearestInPosedModel(const PointSet& scene, const Pose& scene_from_model, Eigen::VectorXi* indices,
                                      Eigen::VectorXd* squared_distances, const Eigen::VectorXi* hints) const {
  // ||x - (R p + t)|| = ||R^T (x - t) - p||: query the model-frame grid.
  grid().NearestBatch(scene_from_model.InverseApply(scene), indices, squared_distances, hints);
}

Eigen::VectorXd ObjectModel::DistancesToPosedModel(const PointSet& scene,
                                                   const Pose& scene_from_model) const {
  Eigen::VectorXd squared;
  NearestInPosedModel(scene, scene_from_model, nullptr, &squared);
  return squared.cwiseSqrt();
}

double PosedModelHausdorff(const ObjectModel& object, const PointSet& queries, const Pose& first,
                           const Pose& second) {
  const Pose relative = first.Inverse() * second;
  const double forward = object.DistancesToPosedModel(relative * queries, Pose::Identity()).maxCoeff();
  const double backward = object.DistancesToPosedModel(queries, relative).maxCoeff();
  return std::max(forward, backward);
}

namespace {

// Largest distance of `points` (model frame) to the triangles of their 8
// nearest sample points.
double LargestSurfaceDistance(const ObjectModel& object, const PointSet& points) {
  const Mesh& mesh = object.mesh();
  double largest = 0.0;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d p = points.col(i);
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& neighbour : object.tree().KNearest(p, 16)) {
      const Eigen::Vector3i tri = mesh.triangles.col(object.sample_triangles()[neighbour.index]);
      const Eigen::Vector3d closest =
          ClosestPointOnTriangle(p, mesh.vertices.col(tri(0)), mesh.vertices.col(tri(1)), mesh.vertices.col(tri(2)));
      nearest = std::min(nearest, (p - closest).norm());
    }
    largest = std::max(largest, nearest);
  }
  return largest;
}

}  // namespace

double PosedSurfaceHausdorff(const ObjectModel& object, const PointSet& queries, const Pose& first,
                             const Pose& second) {
  const Pose relative = first.Inverse() * second;
  return std::max(LargestSurfaceDistance(object, relative * queries),
                  LargestSurfaceDistance(object, relative.Inverse() * queries));
}

}  // namespace c3po
