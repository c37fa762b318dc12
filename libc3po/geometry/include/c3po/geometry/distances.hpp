#pragma once
// Point-set distances (batch, both cores).
#include "c3po/base/types.hpp"
#include "c3po/geometry/kdtree.hpp"

namespace c3po {

// min_{q in to} ||p - q||^2 for every p in `from`.
Eigen::VectorXd NearestSquaredDistances(const PointSet& from, const PointTree& to);
Eigen::VectorXd NearestSquaredDistances(const PointSet& from, const PointSet& to);

// One-sided Chamfer from `from` to `to` (paper eq. 9 uses the mean of squared
// distances; the reference code uses the max of squared distances).
double ChamferMeanSquared(const PointSet& from, const PointSet& to);
double ChamferMaxSquared(const PointSet& from, const PointSet& to);

// Symmetric Hausdorff distance max(h(A,B), h(B,A)).
double HausdorffDistance(const PointSet& a, const PointSet& b);
// One-sided h(A,B) = max_a min_b ||a - b||.
double DirectedHausdorff(const PointSet& from, const PointSet& to);

}  // namespace c3po
