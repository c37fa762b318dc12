#include "c3po/synth/stray_points.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace c3po {

PointSet AddStrayPoints(const PointSet& cloud, int count, double diameter, Rng& rng, std::vector<char>* is_stray) {
  if (count < 0) throw std::invalid_argument("AddStrayPoints: count must be >= 0");
  const Eigen::Index n = cloud.cols();
  if (count == 0 || n == 0) {
    if (is_stray) is_stray->assign(n, 0);
    return cloud;
  }
  const Eigen::Vector3d low = cloud.rowwise().minCoeff().array() - 0.5 * diameter;
  const Eigen::Vector3d high = cloud.rowwise().maxCoeff().array() + 0.5 * diameter;
  PointSet stray(3, count);
  for (int k = 0; k < count; ++k) {
    if (k % 2 == 0) {
      for (int a = 0; a < 3; ++a) stray(a, k) = rng.Uniform(low(a), high(a));
    } else {
      const Eigen::Vector3d x = cloud.col(rng.UniformInt(static_cast<int>(n)));
      const double range = x.norm();
      const double push = rng.Uniform(0.02, 0.5) * diameter;
      stray.col(k) = range > 0 ? Eigen::Vector3d(x * (1.0 + push / range)) : Eigen::Vector3d(x + Eigen::Vector3d(0, 0, push));
    }
  }
  // Random interleaving (a Fisher-Yates shuffle of the output order).
  std::vector<Eigen::Index> order(n + count);
  std::iota(order.begin(), order.end(), 0);
  for (std::size_t i = order.size() - 1; i > 0; --i) std::swap(order[i], order[rng.UniformInt(static_cast<int>(i + 1))]);
  PointSet out(3, n + count);
  if (is_stray) is_stray->assign(n + count, 0);
  for (std::size_t i = 0; i < order.size(); ++i) {
    const Eigen::Index source = order[i];
    if (source < n) out.col(i) = cloud.col(source);
    else out.col(i) = stray.col(source - n);
    if (is_stray && source >= n) (*is_stray)[i] = 1;
  }
  return out;
}

}  // namespace c3po
