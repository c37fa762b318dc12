#include "distance_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace c3po {

DistanceGrid::DistanceGrid(const PointTree& points, int cells, double margin) {
  if (points.size() == 0 || cells < 1) throw std::invalid_argument("DistanceGrid: empty set or no cells");
  const Eigen::Vector3d low = points.points().rowwise().minCoeff();
  const Eigen::Vector3d high = points.points().rowwise().maxCoeff();
  const double pad = margin * (high - low).norm();
  origin_ = low.array() - pad;
  const Eigen::Vector3d extent = (high - low).array() + 2.0 * pad;
  step_ = std::max(extent.maxCoeff(), 1e-12) / cells;
  for (int axis = 0; axis < 3; ++axis) {
    size_(axis) = std::max(2, static_cast<int>(std::ceil(extent(axis) / step_)) + 1);
  }
  values_.resize(static_cast<std::size_t>(size_.prod()));
  for (int k = 0; k < size_.z(); ++k) {
    for (int j = 0; j < size_.y(); ++j) {
      for (int i = 0; i < size_.x(); ++i) {
        const Eigen::Vector3d node = origin_ + step_ * Eigen::Vector3d(i, j, k);
        values_[(k * size_.y() + j) * size_.x() + i] = std::sqrt(points.Nearest(node).squared_distance);
      }
    }
  }
}

double DistanceGrid::Distance(const Eigen::Vector3d& p) const {
  // Grid coordinates, clamped into the grid; the clamped-off part is added.
  const Eigen::Vector3d g = (p - origin_) / step_;
  const Eigen::Vector3d upper = (size_ - Eigen::Vector3i::Ones()).cast<double>();
  const Eigen::Vector3d clamped = g.cwiseMax(0.0).cwiseMin(upper);
  const double outside = (g - clamped).norm() * step_;
  const Eigen::Vector3i cell =
      clamped.cast<int>().cwiseMin(size_ - Eigen::Vector3i::Constant(2)).cwiseMax(0);
  const Eigen::Vector3d f = clamped - cell.cast<double>();
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = (corner >> 2) & 1;
    const double weight = (dx ? f.x() : 1 - f.x()) * (dy ? f.y() : 1 - f.y()) * (dz ? f.z() : 1 - f.z());
    value += weight * Node(cell.x() + dx, cell.y() + dy, cell.z() + dz);
  }
  return value + outside;
}

double DistanceGrid::MeanSquaredDistance(const PointSet& queries) const {
  double total = 0.0;
  for (Eigen::Index i = 0; i < queries.cols(); ++i) {
    const double distance = Distance(queries.col(i));
    total += distance * distance;
  }
  return queries.cols() ? total / static_cast<double>(queries.cols()) : 0.0;
}

}  // namespace c3po
