#pragma once
// Brute-force distance oracles shared by the tests: double loops, no tree,
// to check the fast paths and the poses they certify against.
#include <Eigen/Core>
#include <algorithm>

#include "c3po/base/types.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po::test {

// min_j ||q - p_j||.
inline double DistanceToSet(const Eigen::Vector3d& q, const PointSet& points) {
  return (points.colwise() - q).colwise().norm().minCoeff();
}

// max_i min_j ||a_i - b_j||.
inline double MaxNearest(const PointSet& a, const PointSet& b) {
  double worst = 0.0;
  for (Eigen::Index i = 0; i < a.cols(); ++i) worst = std::max(worst, DistanceToSet(a.col(i), b));
  return worst;
}

// The symmetric Hausdorff distance between the model posed at `first` and at
// `second`: `queries` strided points of B̂ against all of B̂, both ways.
inline double BrutePosedHausdorff(const ObjectModel& object, const Pose& first, const Pose& second,
                                  Eigen::Index queries = 2000) {
  const PointSet strided = StridedColumns(object.sample(), queries);
  return std::max(MaxNearest(first * strided, second * object.sample()),
                  MaxNearest(second * strided, first * object.sample()));
}

}  // namespace c3po::test
