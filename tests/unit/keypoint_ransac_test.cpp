// KeyPo + RANSAC: recovers the pose with up to 50 % planted outlier keypoints
// (planted ground truth), degenerate keypoints, determinism under the seed.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "c3po/base/random.hpp"
#include "c3po/geometry/registration.hpp"
#include "c3po/method/keypoint_ransac.hpp"

using namespace c3po;

namespace {

double RotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return std::acos(std::clamp(((a.transpose() * b).trace() - 1) / 2, -1.0, 1.0));
}

}  // namespace

TEST_CASE("RANSAC recovers the pose with up to 50 % outlier keypoints") {
  for (int n : {8, 12, 40}) {
    for (int outliers : {0, n / 4, n / 2}) {
      Rng rng(100 + n + outliers);
      PointSet model(3, n);
      for (int i = 0; i < n; ++i) model.col(i) = 0.1 * Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1));
      Pose truth;
      truth.R = rng.Rotation();
      truth.t = Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), 1);
      PointSet detected = truth * model;
      for (int i = 0; i < n; ++i) detected.col(i) += 0.001 * Eigen::Vector3d(rng.Normal(), rng.Normal(), rng.Normal());
      for (int i = 0; i < outliers; ++i) detected.col(i * 2 % n + (i * 2 >= n ? 1 : 0)) += 0.05 * rng.UnitVector() * rng.Uniform(1, 3);
      KeypointRansacOptions options;
      options.inlier_threshold = 0.01;
      options.max_iterations = 500;   // exhaustive for n = 8, 12; random for n = 40
      options.seed = 7;
      const KeypointRansacResult result = RegisterKeypointsRansac(model, detected, options);
      CAPTURE(n);
      CAPTURE(outliers);
      REQUIRE(result.ok());
      CHECK(static_cast<int>(result.inliers.size()) == n - outliers);
      CHECK(RotationAngle(result.scene_from_model.R, truth.R) < 2.0 * M_PI / 180);
      CHECK((result.scene_from_model.t - truth.t).norm() < 0.005);
      // Plain registration (eq. 8 on all keypoints) is worse with outliers present.
      if (outliers > 0) {
        const Pose all = RegisterPoints(model, detected).scene_from_model;
        CHECK((all.t - truth.t).norm() > (result.scene_from_model.t - truth.t).norm());
      }
      // Same seed, same answer.
      const KeypointRansacResult again = RegisterKeypointsRansac(model, detected, options);
      CHECK(again.inliers == result.inliers);
      CHECK((again.scene_from_model.R - result.scene_from_model.R).norm() == 0);
    }
  }
}

TEST_CASE("RANSAC on degenerate keypoints") {
  KeypointRansacOptions options;
  options.inlier_threshold = 0.01;
  PointSet model(3, 4), detected(3, 4);
  model << 0, 1, 2, 3, 0, 0, 0, 0, 0, 0, 0, 0;   // collinear
  detected = model;
  CHECK_FALSE(RegisterKeypointsRansac(model, detected, options).ok());
  detected.fill(std::numeric_limits<double>::quiet_NaN());
  CHECK_FALSE(RegisterKeypointsRansac(model, detected, options).ok());
  CHECK_FALSE(RegisterKeypointsRansac(model.leftCols(2), detected.leftCols(2), options).ok());
  CHECK_THROWS_AS(RegisterKeypointsRansac(model, detected.leftCols(3), options), std::invalid_argument);
  options.inlier_threshold = -1;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
}
