#include "c3po/geometry/distances.hpp"

#include <limits>

namespace c3po {

Eigen::VectorXd NearestSquaredDistances(const PointSet& from, const PointTree& to) {
  Eigen::VectorXd squared;
  to.NearestBatch(from, nullptr, &squared);
  return squared;
}

Eigen::VectorXd NearestSquaredDistances(const PointSet& from, const PointSet& to) {
  return NearestSquaredDistances(from, PointTree(to));
}

// Eq. (9), mean variant: (1/|X|) sum_{x in X} min_{p} ||x - p||^2.
double ChamferMeanSquared(const PointSet& from, const PointSet& to) {
  if (from.cols() == 0) return 0.0;
  if (to.cols() == 0) return std::numeric_limits<double>::infinity();
  return NearestSquaredDistances(from, to).mean();
}

// The reference code's variant: max_{x in X} min_{p} ||x - p||^2.
double ChamferMaxSquared(const PointSet& from, const PointSet& to) {
  if (from.cols() == 0) return 0.0;
  if (to.cols() == 0) return std::numeric_limits<double>::infinity();
  return NearestSquaredDistances(from, to).maxCoeff();
}

double DirectedHausdorff(const PointSet& from, const PointSet& to) {
  return std::sqrt(ChamferMaxSquared(from, to));
}

double HausdorffDistance(const PointSet& a, const PointSet& b) {
  return std::max(DirectedHausdorff(a, b), DirectedHausdorff(b, a));
}

}  // namespace c3po
