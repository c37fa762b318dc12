#include "c3po/method/keypoint_ransac.hpp"

#include <array>
#include <cmath>
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

}  // namespace

KeypointRansacResult RegisterKeypointsRansac(const PointSet& model_keypoints,
                                             const PointSet& detected_keypoints,
                                             const KeypointRansacOptions& options) {
  options.Check();
  if (model_keypoints.cols() != detected_keypoints.cols()) {
    throw std::invalid_argument("RegisterKeypointsRansac: keypoint counts differ");
  }
  KeypointRansacResult result;
  std::vector<int> finite;
  for (Eigen::Index i = 0; i < detected_keypoints.cols(); ++i) {
    if (detected_keypoints.col(i).allFinite() && model_keypoints.col(i).allFinite()) {
      finite.push_back(static_cast<int>(i));
    }
  }
  const std::int64_t n = static_cast<std::int64_t>(finite.size());
  if (n < 3) {
    result.failure = "fewer than 3 finite keypoints";
    return result;
  }
  const double threshold2 = options.inlier_threshold * options.inlier_threshold;
  std::vector<int> best_inliers;
  double best_residual = std::numeric_limits<double>::infinity();
  auto score = [&](const std::array<int, 3>& triple) {
    const std::vector<int> picked = {finite[triple[0]], finite[triple[1]], finite[triple[2]]};
    const RegistrationResult fit =
        RegisterPoints(Columns(model_keypoints, picked), Columns(detected_keypoints, picked));
    if (!fit.ok()) return;
    ++result.hypotheses;
    std::vector<int> inliers;
    double residual = 0;
    for (int i : finite) {
      const double r2 = (detected_keypoints.col(i) -
                         fit.scene_from_model * Eigen::Vector3d(model_keypoints.col(i))).squaredNorm();
      if (r2 <= threshold2) {
        inliers.push_back(i);
        residual += std::sqrt(r2);
      }
    }
    if (inliers.size() > best_inliers.size() ||
        (inliers.size() == best_inliers.size() && residual < best_residual)) {
      best_inliers = std::move(inliers);
      best_residual = residual;
    }
  };
  const std::int64_t triples = n * (n - 1) * (n - 2) / 6;
  if (triples <= options.max_iterations) {
    for (int a = 0; a < n; ++a) {
      for (int b = a + 1; b < n; ++b) {
        for (int c = b + 1; c < n; ++c) score({a, b, c});
      }
    }
  } else {
    Rng rng(options.seed);
    const int count = static_cast<int>(n);
    for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
      const int a = rng.UniformInt(count);
      int b = rng.UniformInt(count - 1);
      if (b >= a) ++b;
      int c = rng.UniformInt(count - 2);
      for (int low : {std::min(a, b), std::max(a, b)}) {
        if (c >= low) ++c;
      }
      score({a, b, c});
    }
  }
  if (best_inliers.size() < 3) {
    result.failure = "no triple of keypoints with 3 inliers";
    return result;
  }
  const RegistrationResult refit =
      RegisterPoints(Columns(model_keypoints, best_inliers), Columns(detected_keypoints, best_inliers));
  if (!refit.ok()) {
    result.failure = std::string("inlier registration: ") + ToString(refit.status);
    return result;
  }
  result.scene_from_model = refit.scene_from_model;
  result.inliers = best_inliers;
  return result;
}

}  // namespace c3po
