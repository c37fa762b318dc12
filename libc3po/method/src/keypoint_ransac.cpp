#include "c3po/method/keypoint_ransac.hpp"

#include <array>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "c3po/base/random.hpp"
#include "c3po/geometry/registration.hpp"

namespace c3po {

void KeypointRansacOptions::Check() const {
  if (!(inlier_threshold > 0) || !std::isfinite(inlier_threshold)) {
    throw std::invalid_argument("KeypointRansacOptions: inlier_threshold must be positive and finite");
  }
  if (max_iterations < 1) throw std::invalid_argument("KeypointRansacOptions: max_iterations must be >= 1");
}

namespace {

PointSet Columns(const PointSet& points, const std::vector<int>& indices) {
  PointSet out(3, static_cast<Eigen::Index>(indices.size()));
  for (std::size_t k = 0; k < indices.size(); ++k) out.col(k) = points.col(indices[k]);
  return out;
}

std::vector<int> FiniteKeypoints(const PointSet& model_keypoints, const PointSet& detected_keypoints) {
  std::vector<int> finite;
  for (Eigen::Index i = 0; i < detected_keypoints.cols(); ++i) {
    if (detected_keypoints.col(i).allFinite() && model_keypoints.col(i).allFinite()) {
      finite.push_back(static_cast<int>(i));
    }
  }
  return finite;
}

// Calls visit({a, b, c}) for every triple a < b < c of 0..n-1 when there are at most
// max_iterations, else for max_iterations seeded random triples of distinct indices.
template <typename Visit>
void ForEachTriple(int n, int max_iterations, std::uint64_t seed, const Visit& visit) {
  const std::int64_t count = n;
  if (count * (count - 1) * (count - 2) / 6 <= max_iterations) {
    for (int a = 0; a < n; ++a) {
      for (int b = a + 1; b < n; ++b) {
        for (int c = b + 1; c < n; ++c) visit({a, b, c});
      }
    }
    return;
  }
  Rng rng(seed);
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    const int a = rng.UniformInt(n);
    int b = rng.UniformInt(n - 1);
    if (b >= a) ++b;
    int c = rng.UniformInt(n - 2);
    for (int low : {std::min(a, b), std::max(a, b)}) {
      if (c >= low) ++c;
    }
    visit({a, b, c});
  }
}

// The consensus of the hypotheses so far: the most inliers, ties to the smaller residual sum.
struct Consensus {
  std::vector<int> inliers;
  double residual = std::numeric_limits<double>::infinity();

  void Offer(const Pose& scene_from_model, const PointSet& model_keypoints, const PointSet& detected_keypoints,
             const std::vector<int>& finite, double threshold) {
    std::vector<int> candidate;
    double residual_sum = 0;
    for (int i : finite) {
      const double r2 =
          (detected_keypoints.col(i) - scene_from_model * Eigen::Vector3d(model_keypoints.col(i))).squaredNorm();
      if (r2 <= threshold * threshold) {
        candidate.push_back(i);
        residual_sum += std::sqrt(r2);
      }
    }
    if (candidate.size() > inliers.size() || (candidate.size() == inliers.size() && residual_sum < residual)) {
      inliers = std::move(candidate);
      residual = residual_sum;
    }
  }
};

}  // namespace

KeypointRansacResult RegisterKeypointsRansac(const PointSet& model_keypoints,
                                             const PointSet& detected_keypoints,
                                             const KeypointRansacOptions& options) {
  options.Check();
  if (model_keypoints.cols() != detected_keypoints.cols()) {
    throw std::invalid_argument("RegisterKeypointsRansac: keypoint counts differ");
  }
  KeypointRansacResult result;
  const std::vector<int> finite = FiniteKeypoints(model_keypoints, detected_keypoints);
  if (finite.size() < 3) {
    result.failure = "fewer than 3 finite keypoints";
    return result;
  }
  Consensus best;
  ForEachTriple(static_cast<int>(finite.size()), options.max_iterations, options.seed,
                [&](const std::array<int, 3>& triple) {
                  const std::vector<int> picked = {finite[triple[0]], finite[triple[1]], finite[triple[2]]};
                  const RegistrationResult fit =
                      RegisterPoints(Columns(model_keypoints, picked), Columns(detected_keypoints, picked));
                  if (!fit.ok()) return;
                  ++result.hypotheses;
                  best.Offer(fit.scene_from_model, model_keypoints, detected_keypoints, finite,
                             options.inlier_threshold);
                });
  if (best.inliers.size() < 3) {
    result.failure = "no triple of keypoints with 3 inliers";
    return result;
  }
  const RegistrationResult refit =
      RegisterPoints(Columns(model_keypoints, best.inliers), Columns(detected_keypoints, best.inliers));
  if (!refit.ok()) {
    result.failure = std::string("inlier registration: ") + ToString(refit.status);
    return result;
  }
  result.scene_from_model = refit.scene_from_model;
  result.inliers = best.inliers;
  return result;
}

}  // namespace c3po
