#pragma once
// A sampled distance field of a point set: distance from every node of a
// regular grid over the set's bounding box (plus a margin) to the nearest
// point, trilinearly interpolated. Lets the svd detector screen thousands of
// pose hypotheses at a few nanoseconds per point instead of a k-d tree query.
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/geometry/kdtree.hpp"

namespace c3po {

class DistanceGrid {
 public:
  // `cells` along the longest side of the box; the margin is a fraction of
  // the box diagonal added on every side.
  DistanceGrid(const PointTree& points, int cells, double margin);

  // Approximate distance of p to the point set: interpolated inside the grid;
  // outside, the distance to the grid box plus the value at the clamped point.
  double Distance(const Eigen::Vector3d& p) const;
  // Mean of squared approximate distances over the columns of `queries`.
  double MeanSquaredDistance(const PointSet& queries) const;

  double step() const { return step_; }   // node spacing
  Eigen::AlignedBox3d box() const {       // region covered by the nodes
    return {origin_, origin_ + step_ * (size_ - Eigen::Vector3i::Ones()).cast<double>()};
  }

 private:
  double Node(int i, int j, int k) const { return values_[(k * size_.y() + j) * size_.x() + i]; }

  Eigen::Vector3d origin_;
  double step_ = 1.0;
  Eigen::Vector3i size_;        // nodes per axis
  std::vector<double> values_;  // x fastest
};

}  // namespace c3po
