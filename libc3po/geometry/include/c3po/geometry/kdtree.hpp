#pragma once
// A nanoflann k-d tree over a 3xN point set it owns.
#include <memory>

#include "c3po/base/types.hpp"

namespace c3po {

class PointTree {
 public:
  struct Neighbor {
    Eigen::Index index = -1;
    double squared_distance = 0.0;
  };

  explicit PointTree(PointSet points);
  ~PointTree();
  PointTree(PointTree&&) noexcept;
  PointTree& operator=(PointTree&&) noexcept;
  PointTree(const PointTree&) = delete;
  PointTree& operator=(const PointTree&) = delete;

  const PointSet& points() const { return points_; }
  Eigen::Index size() const { return points_.cols(); }

  Neighbor Nearest(const Eigen::Vector3d& query) const;
  // The same neighbour, found faster when `hint` (a point index, e.g. the
  // query's nearest point at the previous ICP iteration) is close: the search
  // starts bounded by the hint's distance, which the nearest point cannot
  // exceed, so the result is exactly Nearest(query), ties included. An index
  // outside [0, size()) is no hint.
  Neighbor Nearest(const Eigen::Vector3d& query, Eigen::Index hint) const;
  // k nearest, sorted by distance (k clipped to size()).
  std::vector<Neighbor> KNearest(const Eigen::Vector3d& query, int k) const;
  // Nearest neighbour of every column of `queries`, on both cores; with
  // `hints` (one index per query, as for Nearest above) the same result, faster.
  void NearestBatch(const PointSet& queries, Eigen::VectorXi* indices, Eigen::VectorXd* squared_distances,
                    const Eigen::VectorXi* hints = nullptr) const;

 private:
  struct Index;
  PointSet points_;
  std::unique_ptr<Index> index_;
};

}  // namespace c3po
