#pragma once
// Basic geometric types. A point set is 3xN, one point per column; a pose maps
// model coordinates to scene coordinates: x_scene = R * x_model + t.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace c3po {

using PointSet = Eigen::Matrix3Xd;

struct Pose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();

  static Pose Identity() { return {}; }

  // x_scene = R x_model + t
  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return R * x + t; }
  PointSet operator*(const PointSet& points) const {
    return (R * points).colwise() + t;
  }
  // (this * other)(x) = this(other(x))
  Pose operator*(const Pose& other) const { return {R * other.R, R * other.t + t}; }
  Pose Inverse() const { return {R.transpose(), -(R.transpose() * t)}; }
  // Applies the inverse without forming it: R^T (x - t).
  PointSet InverseApply(const PointSet& points) const {
    return R.transpose() * (points.colwise() - t);
  }
  bool IsFinite() const { return R.allFinite() && t.allFinite(); }
};

// At most `limit` columns, evenly strided: columns floor(j n / k),
// j = 0..k-1, k = min(n, limit); every column when limit <= 0 or n <= limit.
// Deterministic and spread over the whole set (clouds are stored in scan
// or sampling order).
inline PointSet StridedColumns(const PointSet& points, Eigen::Index limit) {
  const Eigen::Index n = points.cols();
  if (limit <= 0 || n <= limit) return points;
  PointSet subset(3, limit);
  for (Eigen::Index j = 0; j < limit; ++j) subset.col(j) = points.col(j * n / limit);
  return subset;
}

// The finite columns (no NaN or infinite coordinate), in order.
inline PointSet FiniteColumns(const PointSet& points) {
  Eigen::Index finite = 0;
  for (Eigen::Index i = 0; i < points.cols(); ++i) finite += points.col(i).allFinite() ? 1 : 0;
  if (finite == points.cols()) return points;
  PointSet kept(3, finite);
  for (Eigen::Index i = 0, k = 0; i < points.cols(); ++i) {
    if (points.col(i).allFinite()) kept.col(k++) = points.col(i);
  }
  return kept;
}

// StridedColumns of the finite columns: the finite points of rank
// floor(j m / k), j = 0..k-1, of the m finite ones (k = min(m, limit)).
inline PointSet FiniteStridedColumns(const PointSet& points, Eigen::Index limit) {
  return StridedColumns(FiniteColumns(points), limit);
}

}  // namespace c3po
