// Huge clouds (issue 7): the svd detector and the pipeline's corrector work on
// an evenly strided subset, the certificate still checks every input point,
// and ordinary clouds (below the limits) give exactly the old results.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "asymmetric_object.hpp"
#include "c3po/base/random.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/plugins/svd_detector.hpp"

using namespace c3po;

namespace {

const Pose kTruth{Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix(),
                  Eigen::Vector3d(0.3, -0.2, 1.1)};

PointSet PosedSurface(const ObjectModel& object, int count, std::uint64_t seed) {
  return kTruth * SampleSurface(object.mesh(), count, seed);
}

// Thresholds above the model sample's spacing (~4 mm for 5000 points) and far
// below the outlier's distance (~0.9 m).
PipelineOptions DefaultPipeline() {
  PipelineOptions options;
  options.certificate.eps_oc = 0.02;
  options.certificate.delta_nd = 0.02;
  return options;
}

}  // namespace

TEST_CASE("svd detector: clouds below max_input_points give exactly the unlimited result") {
  const ObjectModel object = test::AsymmetricObject();
  PointSet cloud = PosedSurface(object, 1000, 3);
  cloud.col(17).setConstant(std::numeric_limits<double>::quiet_NaN());   // skipped either way
  SvdDetectorOptions unlimited;
  unlimited.max_input_points = 0;
  const SvdDetector limited_detector(object), unlimited_detector(object, unlimited);
  REQUIRE(limited_detector.options().max_input_points >= cloud.cols());
  const SvdEstimate a = limited_detector.Estimate(cloud), b = unlimited_detector.Estimate(cloud);
  CHECK(a.scene_from_model.R == b.scene_from_model.R);
  CHECK(a.scene_from_model.t == b.scene_from_model.t);
  CHECK(a.chamfer == b.chamfer);
}

TEST_CASE("svd detector: a cloud far above max_input_points is subsampled and still posed") {
  const ObjectModel object = test::AsymmetricObject();
  const PointSet cloud = PosedSurface(object, 200000, 5);
  SvdDetectorOptions small;
  small.max_input_points = 2000;
  const SvdDetector detector(object, small);
  const SvdEstimate estimate = detector.Estimate(cloud);
  // Synthetic ground truth: the detected keypoints are the truly posed ones.
  const PointSet truth = kTruth * object.keypoints();
  const double error = (detector.Detect(cloud) - truth).colwise().norm().maxCoeff();
  CHECK(error < 0.02 * object.diameter());
  // The evidence is the mean squared distance of the used (strided) points.
  PointSet used(3, small.max_input_points);
  for (int j = 0; j < small.max_input_points; ++j) {
    used.col(j) = cloud.col(static_cast<Eigen::Index>(j) * cloud.cols() / small.max_input_points);
  }
  Eigen::VectorXd squared;
  object.NearestInPosedModel(used, estimate.scene_from_model, nullptr, &squared);
  CHECK(estimate.chamfer == doctest::Approx(squared.mean()).epsilon(1e-12));
}

TEST_CASE("pipeline: clouds below max_corrector_points give exactly the unlimited result") {
  const ObjectModel object = test::AsymmetricObject();
  const PointSet cloud = PosedSurface(object, 1000, 7);
  Rng rng(11);
  PointSet detected = kTruth * object.keypoints();
  for (Eigen::Index i = 0; i < detected.cols(); ++i) detected.col(i) += 0.01 * rng.UnitVector();
  PipelineOptions limited = DefaultPipeline(), unlimited = limited;
  unlimited.max_corrector_points = 0;
  const PoseEstimate a = EstimateAndCertify(object, cloud, detected, limited);
  const PoseEstimate b = EstimateAndCertify(object, cloud, detected, unlimited);
  CHECK(a.keypoints == b.keypoints);
  CHECK(a.correction.iterations == b.correction.iterations);
  CHECK(a.certificate.oc.max_point_distance == b.certificate.oc.max_point_distance);
  CHECK(a.certified() == b.certified());
}

TEST_CASE("pipeline: the corrector sees a strided subset, the certificate every point") {
  const ObjectModel object = test::AsymmetricObject();
  PointSet cloud = PosedSurface(object, 50000, 9);
  PipelineOptions options = DefaultPipeline();
  options.max_corrector_points = 20000;
  // Stride floor(j n / k) with n = 50000, k = 20000 takes columns 0, 2, 5, 7,
  // ...; column 1 is never seen by the corrector.
  const Eigen::Index hidden = 1;
  bool seen = false;
  for (Eigen::Index j = 0; j < options.max_corrector_points; ++j) {
    seen = seen || j * cloud.cols() / options.max_corrector_points == hidden;
  }
  REQUIRE_FALSE(seen);
  const PointSet detected = kTruth * object.keypoints();
  const PoseEstimate clean = EstimateAndCertify(object, cloud, detected, options);
  CHECK(clean.certified());

  const Eigen::Vector3d outlier = kTruth * Eigen::Vector3d(0.1, 0.1, 1.0);   // far off the object
  cloud.col(hidden) = outlier;
  const PoseEstimate dirty = EstimateAndCertify(object, cloud, detected, options);
  // The corrector's input did not change, so neither did its pose ...
  CHECK(dirty.keypoints == clean.keypoints);
  // ... but the certificate saw the outlier: brute-force distance to T̂·B̂.
  const PointSet posed = dirty.scene_from_model * object.sample();
  const double brute = std::sqrt((posed.colwise() - outlier).colwise().squaredNorm().minCoeff());
  CHECK_FALSE(dirty.certificate.oc.passed);
  CHECK(dirty.certificate.oc.worst_point == hidden);
  CHECK(dirty.certificate.oc.max_point_distance == doctest::Approx(brute));
  CHECK(dirty.certificate.oc.point_distances.size() == cloud.cols());
}

TEST_CASE("StridedColumns keeps min(n, limit) columns, in order, evenly spread from the first") {
  for (const Eigen::Index n : {0, 1, 7, 1000, 1001, 99991}) {
    PointSet points(3, n);
    for (Eigen::Index i = 0; i < n; ++i) points.col(i) = Eigen::Vector3d(static_cast<double>(i), 0, 0);
    for (const Eigen::Index limit : {0, 1, 5, 128, 256, 1000, 20000}) {
      const PointSet kept = StridedColumns(points, limit);
      const Eigen::Index expected = (limit <= 0 || n <= limit) ? n : limit;
      REQUIRE(kept.cols() == expected);
      if (expected == 0) continue;
      CHECK(kept(0, 0) == 0.0);
      // Gaps between kept column indices are floor or ceil of n / k.
      const double mean_gap = static_cast<double>(n) / static_cast<double>(expected);
      for (Eigen::Index j = 1; j < expected; ++j) {
        const double gap = kept(0, j) - kept(0, j - 1);
        CHECK(gap >= std::floor(mean_gap));
        CHECK(gap <= std::ceil(mean_gap));
      }
    }
  }
}
