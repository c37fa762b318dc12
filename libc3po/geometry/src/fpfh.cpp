#include "c3po/geometry/fpfh.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cstdint>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <vector>


namespace c3po {

void FpfhOptions::Check() const {
  if (!(normal_radius > 0) || !std::isfinite(normal_radius)) {
    throw std::invalid_argument("FpfhOptions: normal_radius must be positive and finite");
  }
  if (!(feature_radius > 0) || !std::isfinite(feature_radius)) {
    throw std::invalid_argument("FpfhOptions: feature_radius must be positive and finite");
  }
  if (max_neighbors < 3) throw std::invalid_argument("FpfhOptions: max_neighbors must be >= 3");
  if (!viewpoint.allFinite()) throw std::invalid_argument("FpfhOptions: viewpoint must be finite");
}

namespace {

// The neighbours of point i within radius (excluding i itself unless asked).
std::vector<PointTree::Neighbor> Within(const PointTree& tree, Eigen::Index i, double radius,
                                        int max_neighbors, bool include_self) {
  auto neighbors = tree.KNearest(tree.points().col(i), max_neighbors + 1);
  std::vector<PointTree::Neighbor> kept;
  kept.reserve(neighbors.size());
  const double r2 = radius * radius;
  for (const auto& n : neighbors) {
    if (n.squared_distance > r2) break;
    if (n.index == i && !include_self) continue;
    kept.push_back(n);
    if (static_cast<int>(kept.size()) == max_neighbors + (include_self ? 1 : 0)) break;
  }
  return kept;
}

int Bin(double value, double low, double high) {
  const int bin = static_cast<int>(std::floor(kFpfhBinsPerFeature * (value - low) / (high - low)));
  return std::clamp(bin, 0, kFpfhBinsPerFeature - 1);
}

void NormaliseBlocks(Eigen::Ref<Eigen::Matrix<double, kFpfhBins, 1>> histogram) {
  for (int block = 0; block < 3; ++block) {
    auto part = histogram.segment<kFpfhBinsPerFeature>(block * kFpfhBinsPerFeature);
    const double sum = part.sum();
    if (sum > 0) part *= 100.0 / sum;
  }
}

}  // namespace

PointSet VoxelDownsample(const PointSet& points, double voxel) {
  if (!(voxel > 0) || !std::isfinite(voxel)) {
    throw std::invalid_argument("VoxelDownsample: voxel must be positive and finite");
  }
  std::map<std::array<std::int64_t, 3>, std::pair<Eigen::Vector3d, int>> cells;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d p = points.col(i);
    if (!p.allFinite()) continue;
    const Eigen::Vector3d scaled = (p / voxel).array().floor();
    // Clouds 10^15 voxels across are not representable; clamp the key.
    std::array<std::int64_t, 3> key;
    for (int k = 0; k < 3; ++k) key[k] = static_cast<std::int64_t>(std::clamp(scaled(k), -1e15, 1e15));
    auto& cell = cells[key];
    if (cell.second == 0) cell.first.setZero();
    cell.first += p;
    ++cell.second;
  }
  PointSet out(3, static_cast<Eigen::Index>(cells.size()));
  Eigen::Index column = 0;
  for (const auto& [key, cell] : cells) out.col(column++) = cell.first / cell.second;
  return out;
}

Eigen::Vector3d PairFeature(const Eigen::Vector3d& p1, const Eigen::Vector3d& n1,
                            const Eigen::Vector3d& p2, const Eigen::Vector3d& n2) {
  Eigen::Vector3d d = p2 - p1;
  const double length = d.norm();
  if (!(length > 0)) return Eigen::Vector3d::Zero();
  d /= length;
  // Source: the point whose normal makes the smaller angle with the line.
  const bool swap = std::acos(std::clamp(n1.dot(d), -1.0, 1.0)) >
                    std::acos(std::clamp(-n2.dot(d), -1.0, 1.0));
  const Eigen::Vector3d u = swap ? n2 : n1;
  const Eigen::Vector3d nt = swap ? n1 : n2;
  const Eigen::Vector3d line = swap ? Eigen::Vector3d(-d) : d;
  Eigen::Vector3d v = u.cross(line);
  const double v_norm = v.norm();
  if (v_norm > 0) v /= v_norm;
  const Eigen::Vector3d w = u.cross(v);
  return {v.dot(nt), u.dot(line), std::atan2(w.dot(nt), u.dot(nt))};
}

PointSet EstimateNormals(const PointTree& tree, const FpfhOptions& options) {
  options.Check();
  const PointSet& points = tree.points();
  const int n = static_cast<int>(points.cols());
  PointSet normals = PointSet::Zero(3, n);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  if (n > 0) centroid = points.rowwise().mean();
  for (int i = 0; i < n; ++i) {
    const auto neighbors = Within(tree, i, options.normal_radius, options.max_neighbors, true);
    if (neighbors.size() < 3) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& nb : neighbors) mean += points.col(nb.index);
    mean /= static_cast<double>(neighbors.size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const auto& nb : neighbors) {
      const Eigen::Vector3d c = points.col(nb.index) - mean;
      covariance += c * c.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
    Eigen::Vector3d normal = solver.eigenvectors().col(0);
    const Eigen::Vector3d reference = options.orientation == NormalOrientation::kTowardViewpoint
                                          ? Eigen::Vector3d(options.viewpoint - points.col(i))
                                          : Eigen::Vector3d(points.col(i) - centroid);
    if (normal.dot(reference) < 0) normal = -normal;
    if (normal.allFinite()) normals.col(i) = normal.normalized();
  }
  return normals;
}

FpfhFeatures ComputeFpfh(const PointTree& tree, const PointSet& normals, const FpfhOptions& options) {
  options.Check();
  const PointSet& points = tree.points();
  if (normals.cols() != points.cols()) throw std::invalid_argument("ComputeFpfh: normals size differs");
  const int n = static_cast<int>(points.cols());
  std::vector<std::vector<PointTree::Neighbor>> neighborhoods(n);
  FpfhFeatures spfh = FpfhFeatures::Zero(kFpfhBins, n);
  // Simplified point feature histograms.
  for (int i = 0; i < n; ++i) {
    neighborhoods[i] = Within(tree, i, options.feature_radius, options.max_neighbors, false);
    if (normals.col(i).isZero()) continue;
    Eigen::Matrix<double, kFpfhBins, 1> histogram = Eigen::Matrix<double, kFpfhBins, 1>::Zero();
    for (const auto& nb : neighborhoods[i]) {
      if (normals.col(nb.index).isZero()) continue;
      const Eigen::Vector3d f = PairFeature(points.col(i), normals.col(i), points.col(nb.index),
                                            normals.col(nb.index));
      histogram(Bin(f(2), -M_PI, M_PI)) += 1;
      histogram(kFpfhBinsPerFeature + Bin(f(0), -1, 1)) += 1;
      histogram(2 * kFpfhBinsPerFeature + Bin(f(1), -1, 1)) += 1;
    }
    NormaliseBlocks(histogram);
    spfh.col(i) = histogram;
  }
  // Eq. (4): FPFH(p) = SPFH(p) + 1/k sum SPFH(p_i) / w_i.
  FpfhFeatures fpfh = FpfhFeatures::Zero(kFpfhBins, n);
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<double, kFpfhBins, 1> sum = Eigen::Matrix<double, kFpfhBins, 1>::Zero();
    int k = 0;
    for (const auto& nb : neighborhoods[i]) {
      const double w = std::sqrt(nb.squared_distance);
      if (!(w > 0)) continue;
      sum += spfh.col(nb.index) / w;
      ++k;
    }
    Eigen::Matrix<double, kFpfhBins, 1> histogram = spfh.col(i);
    if (k > 0) histogram += sum / k;
    NormaliseBlocks(histogram);
    fpfh.col(i) = histogram;
  }
  return fpfh;
}

}  // namespace c3po
