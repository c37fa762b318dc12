#include "c3po/plugins/fpfh_detector.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "c3po/base/error.hpp"

namespace c3po {

void FpfhDetectorOptions::Check() const {
  for (double v : {voxel_fraction, normal_radius_voxels, feature_radius_voxels, noise_bound_voxels}) {
    if (!(v > 0) || !std::isfinite(v)) {
      throw std::invalid_argument("FpfhDetectorOptions: fractions and radii must be positive and finite");
    }
  }
  if (max_neighbors < 3) throw std::invalid_argument("FpfhDetectorOptions: max_neighbors must be >= 3");
  if (max_input_points < 3) throw std::invalid_argument("FpfhDetectorOptions: max_input_points must be >= 3");
  if (max_correspondences < 3) {
    throw std::invalid_argument("FpfhDetectorOptions: max_correspondences must be >= 3");
  }
  if (min_mutual_matches < 0) throw std::invalid_argument("FpfhDetectorOptions: min_mutual_matches must be >= 0");
  if (max_clique_branches < 1) throw std::invalid_argument("FpfhDetectorOptions: max_clique_branches must be >= 1");
}

namespace {

FpfhOptions DescriptorOptions(const FpfhDetectorOptions& options, double voxel) {
  FpfhOptions fpfh;
  fpfh.normal_radius = options.normal_radius_voxels * voxel;
  fpfh.feature_radius = options.feature_radius_voxels * voxel;
  fpfh.max_neighbors = options.max_neighbors;
  fpfh.orientation = NormalOrientation::kTowardViewpoint;
  fpfh.viewpoint.setZero();
  return fpfh;
}

// Nearest column of `to` (squared Euclidean distance in descriptor space) for
// every column of `from`, by brute force (33-D: k-d trees do not pay here).
std::vector<std::pair<int, double>> NearestDescriptors(const FpfhFeatures& from, const FpfhFeatures& to) {
  std::vector<std::pair<int, double>> nearest(from.cols(), {-1, std::numeric_limits<double>::infinity()});
  const Eigen::VectorXd to_norms = to.colwise().squaredNorm().transpose();
  for (Eigen::Index i = 0; i < from.cols(); ++i) {
    const Eigen::VectorXd d2 = to_norms - 2 * (to.transpose() * from.col(i));
    Eigen::Index best = -1;
    if (d2.size() > 0) d2.minCoeff(&best);
    if (best >= 0) nearest[i] = {static_cast<int>(best), d2(best) + from.col(i).squaredNorm()};
  }
  return nearest;
}

}  // namespace

FpfhDetector::FpfhDetector(const ObjectModel& object, const FpfhDetectorOptions& options)
    : object_(object), options_(options) {
  options_.Check();
  voxel_ = options_.voxel_fraction * object_.diameter();
  if (!(voxel_ > 0)) throw std::invalid_argument("FpfhDetector: the object has zero diameter");
  model_points_ = VoxelDownsample(object_.sample(), voxel_);
  const PointTree tree(model_points_);
  FpfhOptions fpfh = DescriptorOptions(options_, voxel_);
  PointSet normals = EstimateNormals(tree, fpfh);
  // Orient the model's normals like the mesh's outward normal nearby.
  for (Eigen::Index i = 0; i < model_points_.cols(); ++i) {
    const auto nearest = object_.tree().Nearest(model_points_.col(i));
    if (nearest.index >= 0 && normals.col(i).dot(object_.sample_normals().col(nearest.index)) < 0) {
      normals.col(i) = -normals.col(i);
    }
  }
  model_features_ = ComputeFpfh(tree, normals, fpfh);
}

FpfhEstimate FpfhDetector::Estimate(const PointSet& cloud) const {
  FpfhEstimate estimate;
  // Huge clouds are strided first (bounded cost), then voxelised.
  const PointSet points = StridedColumns(
      VoxelDownsample(StridedColumns(cloud, 50 * options_.max_input_points), voxel_), options_.max_input_points);
  estimate.scene_points = static_cast<int>(points.cols());
  estimate.model_points = static_cast<int>(model_points_.cols());
  RobustRegistrationOptions robust;
  robust.noise_bound = options_.noise_bound_voxels * voxel_;
  robust.max_correspondences = options_.max_correspondences;
  robust.max_clique_branches = options_.max_clique_branches;
  if (points.cols() < 3) {
    estimate.registration.failure = "fewer than 3 occupied voxels in the cloud";
    return estimate;
  }
  const PointTree tree(points);
  const FpfhOptions fpfh = DescriptorOptions(options_, voxel_);
  const FpfhFeatures features = ComputeFpfh(tree, EstimateNormals(tree, fpfh), fpfh);
  // Mutual nearest neighbours in descriptor space, best matches first.
  const auto scene_to_model = NearestDescriptors(features, model_features_);
  const auto model_to_scene = NearestDescriptors(model_features_, features);
  struct Match {
    int scene, model;
    double distance;
  };
  std::vector<Match> mutual, one_way;
  for (int i = 0; i < static_cast<int>(scene_to_model.size()); ++i) {
    if (features.col(i).isZero()) continue;   // no neighbours: no descriptor
    const auto [j, d] = scene_to_model[i];
    if (j < 0) continue;
    one_way.push_back({i, j, d});
    if (model_to_scene[j].first == i) mutual.push_back({i, j, d});
  }
  estimate.mutual = static_cast<int>(mutual.size()) >= options_.min_mutual_matches;
  std::vector<Match>& matches = estimate.mutual ? mutual : one_way;
  std::stable_sort(matches.begin(), matches.end(),
                   [](const Match& a, const Match& b) { return a.distance < b.distance; });
  if (static_cast<int>(matches.size()) > options_.max_correspondences) matches.resize(options_.max_correspondences);
  PointSet model(3, static_cast<Eigen::Index>(matches.size())), scene(3, model.cols());
  for (std::size_t k = 0; k < matches.size(); ++k) {
    model.col(k) = model_points_.col(matches[k].model);
    scene.col(k) = points.col(matches[k].scene);
  }
  estimate.registration = RegisterRobust(model, scene, robust);
  estimate.scene_from_model = estimate.registration.scene_from_model;
  return estimate;
}

PointSet FpfhDetector::Detect(const PointSet& cloud) const {
  bool any_finite = false;
  for (Eigen::Index i = 0; i < cloud.cols() && !any_finite; ++i) any_finite = cloud.col(i).allFinite();
  if (!any_finite) throw InputError("cloud", "no finite point");
  const FpfhEstimate estimate = Estimate(cloud);
  if (!estimate.registration.ok()) throw InputError("cloud", "fpfh: " + estimate.registration.failure);
  return estimate.scene_from_model * object_.keypoints();
}

}  // namespace c3po
