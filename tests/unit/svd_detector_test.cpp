// The training-free svd detector: principal-axes hypotheses + ICP.
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "asymmetric_object.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/eval/metrics.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/plugins/svd_detector.hpp"
#include "test_helpers.hpp"
// Internal to the svd plugin (linked through c3po::plugins).
#include "../../plugins/svd/src/distance_grid.hpp"

using namespace c3po;

namespace {

Pose RandomPose(Rng& rng) {
  return {rng.Rotation(), Eigen::Vector3d(rng.Uniform(), rng.Uniform(), rng.Uniform())};
}

double MaxKeypointError(const PointSet& a, const PointSet& b) {
  return (a - b).colwise().norm().maxCoeff();
}

// Brute-force one-sided Chamfer (mean squared NN distance) from `cloud` to
// the model sample posed by `pose`.
double BruteForceChamfer(const ObjectModel& object, const PointSet& cloud, const Pose& pose) {
  const PointSet posed = pose * object.sample();
  double total = 0.0;
  for (Eigen::Index i = 0; i < cloud.cols(); ++i) {
    total += (posed.colwise() - cloud.col(i)).colwise().squaredNorm().minCoeff();
  }
  return total / static_cast<double>(cloud.cols());
}

// The part of `cloud` on one side of a plane through its centroid.
PointSet HalfCloud(const PointSet& cloud, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d centroid = cloud.rowwise().mean();
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < cloud.cols(); ++i) {
    if ((cloud.col(i) - centroid).dot(direction) > 0) kept.push_back(i);
  }
  PointSet half(3, static_cast<Eigen::Index>(kept.size()));
  for (std::size_t k = 0; k < kept.size(); ++k) half.col(k) = cloud.col(kept[k]);
  return half;
}

// Points of a surface sample whose triangle faces the camera position (a
// partial view without occlusion between parts).
PointSet FacingCloud(const Mesh& mesh, const Pose& pose, const Eigen::Vector3d& camera,
                     std::uint64_t seed) {
  const SurfaceSample sample = SampleSurfaceWithTriangles(mesh, 2000, seed);
  std::vector<Eigen::Vector3d> kept;
  for (Eigen::Index i = 0; i < sample.points.cols(); ++i) {
    const Eigen::Vector3i t = mesh.triangles.col(sample.triangle(i));
    const Eigen::Vector3d a = mesh.vertices.col(t(0));
    const Eigen::Vector3d normal = (mesh.vertices.col(t(1)) - a).cross(mesh.vertices.col(t(2)) - a);
    const Eigen::Vector3d point = pose * Eigen::Vector3d(sample.points.col(i));
    if ((pose.R * normal).dot(camera - point) > 0) kept.push_back(point);
  }
  PointSet cloud(3, static_cast<Eigen::Index>(kept.size()));
  for (std::size_t k = 0; k < kept.size(); ++k) cloud.col(k) = kept[k];
  return cloud;
}

}  // namespace

TEST_CASE("svd detector recovers the pose of a full noise-free sample") {
  const ObjectModel object = test::AsymmetricObject();
  const SvdDetector detector(object);
  CHECK(detector.name() == "svd");
  CHECK(detector.num_keypoints() == 5);
  const double d = object.diameter();
  double total_ms = 0.0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    CAPTURE(seed);
    Rng rng(seed);
    const Pose truth = RandomPose(rng);
    const PointSet cloud = truth * SampleSurface(object.mesh(), 1000, seed + 500);
    const auto start = std::chrono::steady_clock::now();
    const PointSet keypoints = detector.Detect(cloud);
    total_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    REQUIRE(keypoints.cols() == 5);
    CHECK(MaxKeypointError(keypoints, truth * object.keypoints()) < 0.02 * d);
    const SvdEstimate estimate = detector.Estimate(cloud);
    CHECK(RotationError(estimate.scene_from_model.R, truth.R) < 2.0 * M_PI / 180.0);
    CHECK(estimate.screened == (24 + 120) * 27);
    CHECK(estimate.hypotheses.size() == 24);
    CHECK(estimate.chamfer == doctest::Approx(BruteForceChamfer(object, cloud, estimate.scene_from_model)).epsilon(1e-9));
  }
  MESSAGE("svd Detect: " << total_ms / 8.0 << " ms per 1000-point cloud");
}

TEST_CASE("svd detector recovers the pose from camera-facing partial clouds") {
  const ObjectModel object = test::AsymmetricObject();
  const SvdDetector detector(object);
  const double d = object.diameter();
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    Rng rng(seed + 60);
    const Pose truth = RandomPose(rng);
    const PointSet cloud = FacingCloud(object.mesh(), truth, truth.t + rng.UnitVector(), seed + 200);
    REQUIRE(cloud.cols() > 300);
    const PointSet keypoints = detector.Detect(cloud);
    CHECK(MaxKeypointError(keypoints, truth * object.keypoints()) < 0.02 * d);
  }
}

TEST_CASE("svd detector on rendered depth clouds of the bundled drill (1 mm noise)") {
  const ObjectModel object = LoadObject(test::SourceDir() + "/annotations/drill.json");
  const SvdDetector detector(object);
  const double d = object.diameter();
  DepthRenderer renderer{CameraIntrinsics()};
  DepthSampleOptions sampling;
  sampling.points = 1000;
  sampling.noise_sigma = 0.001;
  int within = 0;
  const int count = 10;
  for (int i = 0; i < count; ++i) {
    Rng rng = Rng::ForItem(5, i);
    const Pose truth{rng.Rotation(), Eigen::Vector3d(rng.Uniform(-0.05, 0.05), rng.Uniform(-0.05, 0.05),
                                                     rng.Uniform(0.5, 0.8))};
    renderer.Render(object.mesh(), truth);
    const PointSet cloud = renderer.SampleCloud(sampling, rng);
    REQUIRE(cloud.cols() > 100);
    const SvdEstimate estimate = detector.Estimate(cloud);
    if (AddS(object.tree(), truth, estimate.scene_from_model) < 0.05 * d) ++within;
  }
  MESSAGE(within << " of " << count << " drill depth clouds with ADD-S below 5 % d");
  CHECK(within >= count - 1);
}

TEST_CASE("svd detector on half clouds gives finite keypoints and honest evidence") {
  const ObjectModel object = test::AsymmetricObject();
  const SvdDetector detector(object);
  const double d = object.diameter();
  int recovered = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    Rng rng(seed + 40);
    const Pose truth = RandomPose(rng);
    const PointSet cloud = HalfCloud(truth * SampleSurface(object.mesh(), 1000, seed + 100), rng.UnitVector());
    REQUIRE(cloud.cols() > 50);
    const SvdEstimate estimate = detector.Estimate(cloud);
    const PointSet keypoints = detector.Detect(cloud);
    CHECK(keypoints.allFinite());
    CHECK(keypoints.cols() == 5);
    CHECK(estimate.chamfer == doctest::Approx(BruteForceChamfer(object, cloud, estimate.scene_from_model)).epsilon(1e-9));
    if (MaxKeypointError(keypoints, truth * object.keypoints()) < 0.05 * d) ++recovered;
  }
  // A cut through the centroid removes much of the shape: the one-sided fit
  // is then often ambiguous. Reported, not asserted.
  MESSAGE(recovered << " of 6 half clouds gave keypoints within 5 % d of the truth");
}

TEST_CASE("the screening distance field agrees with brute-force nearest distances") {
  const ObjectModel object = test::AsymmetricObject(2000);
  const DistanceGrid grid(object.tree(), 30, 0.1);
  const PointSet& sample = object.sample();
  Rng rng(17);
  const Eigen::AlignedBox3d box = grid.box();
  // Trilinear interpolation of a 1-Lipschitz function: error <= step * sqrt(3).
  const double tolerance = grid.step() * std::sqrt(3.0);
  int outside = 0;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d p = box.center() + 0.75 * (box.sizes().array() *
                              Eigen::Array3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1))).matrix();
    const double truth = std::sqrt((sample.colwise() - p).colwise().squaredNorm().minCoeff());
    const double estimate = grid.Distance(p);
    if (box.contains(p)) {
      CHECK(std::abs(estimate - truth) <= tolerance);
    } else {
      ++outside;   // clamped: never below the truth by more than the tolerance
      CHECK(estimate >= truth - tolerance);
    }
  }
  CHECK(outside > 50);
  PointSet queries = sample.leftCols(10);
  CHECK(grid.MeanSquaredDistance(queries) <= tolerance * tolerance);
}

TEST_CASE("hypotheses are the 24 (or 4) proper rotations mapping model axes onto signed cloud axes") {
  Rng rng(3);
  const Eigen::Matrix3d model_axes = rng.Rotation();
  const Eigen::Matrix3d cloud_axes = rng.Rotation();
  for (bool permutations : {true, false}) {
    const std::vector<Eigen::Matrix3d> rotations =
        PrincipalAxisRotations(model_axes, cloud_axes, permutations);
    CHECK(rotations.size() == (permutations ? 24u : 4u));
    for (std::size_t i = 0; i < rotations.size(); ++i) {
      const Eigen::Matrix3d& R = rotations[i];
      CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-12);
      CHECK(R.determinant() == doctest::Approx(1.0));
      // R maps each model axis to plus or minus one cloud axis.
      const Eigen::Matrix3d in_cloud_axes = cloud_axes.transpose() * R * model_axes;
      CHECK((in_cloud_axes.cwiseAbs() * Eigen::Vector3d::Ones() - Eigen::Vector3d::Ones()).norm() < 1e-12);
      if (!permutations) CHECK(in_cloud_axes.isDiagonal(1e-12));
      for (std::size_t j = 0; j < i; ++j) CHECK((R - rotations[j]).norm() > 0.5);
    }
  }
}

TEST_CASE("PrincipalAxes finds the axes of an anisotropic cloud") {
  Rng rng(9);
  const Eigen::Matrix3d truth = rng.Rotation();
  PointSet cloud(3, 4000);
  for (Eigen::Index i = 0; i < cloud.cols(); ++i) {
    cloud.col(i) = truth * Eigen::Vector3d(3.0 * rng.Normal(), 2.0 * rng.Normal(), rng.Normal());
  }
  const Eigen::Matrix3d axes = PrincipalAxes(cloud, cloud.rowwise().mean());
  CHECK(axes.determinant() == doctest::Approx(1.0));
  for (int k = 0; k < 3; ++k) CHECK(std::abs(axes.col(k).dot(truth.col(k))) > 0.99);
}

TEST_CASE("svd detector on degenerate clouds") {
  const ObjectModel object = test::AsymmetricObject(1000);
  const SvdDetector detector(object);
  const Eigen::Vector3d model_centroid = object.sample().rowwise().mean();
  const double nan = std::numeric_limits<double>::quiet_NaN();

  CHECK_THROWS_AS(detector.Detect(PointSet(3, 0)), InputError);
  CHECK_THROWS_AS(detector.Detect(PointSet::Constant(3, 10, nan)), InputError);

  // One or two points: the model is translated onto their centroid.
  const Eigen::Vector3d point(0.3, -0.2, 1.0);
  const PointSet one = point;
  const PointSet expected = object.keypoints().colwise() + (point - model_centroid);
  CHECK(MaxKeypointError(detector.Detect(one), expected) < 1e-12);
  PointSet two(3, 2);
  two << point, point;
  two(0, 1) = nan;   // a non-finite point is ignored
  CHECK(MaxKeypointError(detector.Detect(two), expected) < 1e-12);

  // Huge coordinates: no crash (the output may overflow).
  CHECK_NOTHROW(detector.Detect(1e300 * SampleSurface(object.mesh(), 100, 8)));

  // Three identical or collinear points: finite output, no crash.
  const PointSet same = point.replicate(1, 3);
  CHECK(detector.Detect(same).allFinite());
  PointSet line(3, 20);
  for (int i = 0; i < 20; ++i) line.col(i) = point + 0.01 * i * Eigen::Vector3d(1, 2, 3);
  CHECK(detector.Detect(line).allFinite());
}

TEST_CASE("svd detector is deterministic and safe to run concurrently") {
  const ObjectModel object = test::AsymmetricObject(2000);
  SvdDetectorOptions options;
  options.try_permutations = false;   // only the 4 sign flips, centroid-aligned
  options.uniform_rotations = 0;
  options.box_translations = false;
  options.final_icp_iterations = 10;
  const SvdDetector detector(object, options);
  CHECK(PrincipalAxisRotations(Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(), false).size() == 4);
  std::vector<PointSet> clouds;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    Rng rng(seed);
    clouds.push_back(RandomPose(rng) * SampleSurface(object.mesh(), 400, seed + 100));
  }
  const std::vector<PointSet> batch = detector.DetectBatch(clouds);
  REQUIRE(batch.size() == clouds.size());
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    CHECK(detector.Detect(clouds[i]) == batch[i]);   // bitwise identical
    const SvdEstimate estimate = detector.Estimate(clouds[i]);
    CHECK(estimate.screened == 4);
    CHECK(estimate.hypotheses.size() == 4);
  }
}

TEST_CASE("SvdDetectorOptions::Check rejects out-of-range values") {
  SvdDetectorOptions options;
  CHECK_NOTHROW(options.Check());
  options.max_hypothesis_points = 2;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
  options = SvdDetectorOptions();
  options.hypothesis_icp_iterations = -1;
  CHECK_THROWS_AS(SvdDetector(test::AsymmetricObject(1000), options), std::invalid_argument);
  options = SvdDetectorOptions();
  options.trim_fraction = 1.0;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
}
