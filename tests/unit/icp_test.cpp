// Point-to-point ICP with the model k-d tree: convergence from small
// perturbations, graceful failure from large ones, degenerate inputs.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "asymmetric_object.hpp"
#include "c3po/base/random.hpp"
#include "c3po/eval/metrics.hpp"
#include "c3po/io/mesh_io.hpp"
#include "c3po/method/icp.hpp"
#include "test_helpers.hpp"

using namespace c3po;

namespace {

// Brute-force oracle: RMS over the scene of the distance to the posed sample.
double BruteForceRms(const ObjectModel& object, const PointSet& scene, const Pose& pose) {
  const PointSet posed = pose * object.sample();
  double total = 0.0;
  for (Eigen::Index i = 0; i < scene.cols(); ++i) {
    total += (posed.colwise() - scene.col(i)).colwise().squaredNorm().minCoeff();
  }
  return std::sqrt(total / static_cast<double>(scene.cols()));
}

Pose RandomPose(Rng& rng) {
  return {rng.Rotation(), Eigen::Vector3d(rng.Uniform(), rng.Uniform(), rng.Uniform())};
}

// The truth moved by a rotation of `angle` about a random axis through the
// model's centroid and a translation of length `shift`.
Pose Perturb(const Pose& truth, const Eigen::Vector3d& model_centroid, double angle,
             double shift, Rng& rng) {
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(angle, rng.UnitVector()).toRotationMatrix();
  const Pose about_centroid{turn, model_centroid - turn * model_centroid};
  Pose perturbed = truth * about_centroid;
  perturbed.t += shift * rng.UnitVector();
  return perturbed;
}

bool IsRotation(const Eigen::Matrix3d& R) {
  return R.allFinite() && (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-9 &&
         std::abs(R.determinant() - 1.0) < 1e-9;
}

struct Scene {
  Pose truth;
  PointSet points;
};

Scene SampleScene(const ObjectModel& object, int count, std::uint64_t seed) {
  Rng rng(seed);
  Scene scene;
  scene.truth = RandomPose(rng);
  scene.points = scene.truth * SampleSurface(object.mesh(), count, seed + 1000);
  return scene;
}

}  // namespace

TEST_CASE("ICP converges to the truth from 10 degree / 2 % d perturbations") {
  const ObjectModel object = test::AsymmetricObject(10000);
  const Eigen::Vector3d centroid = object.sample().rowwise().mean();
  const double d = object.diameter();
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    const Scene scene = SampleScene(object, 800, seed);
    Rng rng(seed + 77);
    const Pose initial = Perturb(scene.truth, centroid, 10.0 * M_PI / 180.0, 0.02 * d, rng);
    IcpOptions options;
    options.max_iterations = 60;   // point-to-point ICP converges linearly
    const IcpResult result = RefineIcp(object, scene.points, initial, options);
    CHECK(result.ok());
    CHECK(result.converged);
    CHECK(result.iterations >= 1);
    CHECK(result.inliers == 800);
    CHECK(result.scene_points == 800);
    CHECK(IsRotation(result.scene_from_model.R));
    CHECK(RotationError(result.scene_from_model.R, scene.truth.R) < 1.0 * M_PI / 180.0);
    CHECK(TranslationError(result.scene_from_model.t, scene.truth.t) < 0.005 * d);
    // The reported residuals are the true ones (oracle), and the fit is at
    // least as good as the truth itself up to sampling noise.
    CHECK(result.rms_before == doctest::Approx(BruteForceRms(object, scene.points, initial)).epsilon(1e-9));
    CHECK(result.rms_after == doctest::Approx(BruteForceRms(object, scene.points, result.scene_from_model)).epsilon(1e-9));
    CHECK(result.rms_after < result.rms_before);
    CHECK(result.rms_after <= 1.05 * BruteForceRms(object, scene.points, scene.truth));
  }
}

TEST_CASE("ICP from large perturbations fails gracefully and reports its residual honestly") {
  const ObjectModel object = test::AsymmetricObject();
  const Eigen::Vector3d centroid = object.sample().rowwise().mean();
  const double d = object.diameter();
  int wrong = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    const Scene scene = SampleScene(object, 600, seed);
    const double truth_rms = BruteForceRms(object, scene.points, scene.truth);
    Rng rng(seed + 99);
    const Pose initial = Perturb(scene.truth, centroid, M_PI * 0.95, 0.5 * d, rng);
    IcpOptions options;
    options.max_iterations = 15;
    const IcpResult result = RefineIcp(object, scene.points, initial, options);
    CHECK(result.ok());
    CHECK(IsRotation(result.scene_from_model.R));
    CHECK(result.scene_from_model.t.allFinite());
    CHECK(std::isfinite(result.rms_after));
    CHECK(result.rms_after == doctest::Approx(BruteForceRms(object, scene.points, result.scene_from_model)).epsilon(1e-9));
    // A wrong pose is visible in the residual: never reported as a fit as good as the truth.
    if (RotationError(result.scene_from_model.R, scene.truth.R) > 5.0 * M_PI / 180.0) {
      ++wrong;
      CHECK(result.rms_after > 2.0 * truth_rms);
    }
  }
  MESSAGE(wrong << " of 6 large perturbations ended in a wrong local minimum");
}

TEST_CASE("Trimmed ICP and the distance gate ignore outliers") {
  const ObjectModel object = test::AsymmetricObject();
  const Eigen::Vector3d centroid = object.sample().rowwise().mean();
  const double d = object.diameter();
  const Scene scene = SampleScene(object, 600, 42);
  Rng rng(5);
  PointSet cluttered(3, 750);
  cluttered.leftCols(600) = scene.points;
  for (int i = 600; i < 750; ++i) {   // 20 % outliers 1-2 d away from the object
    cluttered.col(i) = scene.truth.t + (1.0 + rng.Uniform()) * d * rng.UnitVector();
  }
  const Pose initial = Perturb(scene.truth, centroid, 5.0 * M_PI / 180.0, 0.01 * d, rng);

  IcpOptions trimmed;
  trimmed.trim_fraction = 0.25;
  IcpOptions gated;
  gated.max_correspondence_distance = 0.1 * d;
  for (const IcpOptions& options : {trimmed, gated}) {
    const IcpResult result = RefineIcp(object, cluttered, initial, options);
    CHECK(result.ok());
    CHECK(result.inliers <= 600);
    CHECK(RotationError(result.scene_from_model.R, scene.truth.R) < 1.0 * M_PI / 180.0);
    CHECK(TranslationError(result.scene_from_model.t, scene.truth.t) < 0.005 * d);
  }
  // Plain ICP is dragged by the outliers: the gate/trim make a difference.
  const IcpResult plain = RefineIcp(object, cluttered, initial);
  CHECK(TranslationError(plain.scene_from_model.t, scene.truth.t) > 0.005 * d);
}

TEST_CASE("ICP on degenerate input is an outcome, not a crash") {
  const ObjectModel object = test::AsymmetricObject(1000);
  Pose initial;
  initial.t = Eigen::Vector3d(0.1, 0.2, 0.3);
  const double nan = std::numeric_limits<double>::quiet_NaN();

  SUBCASE("empty scene") {
    const IcpResult result = RefineIcp(object, PointSet(3, 0), initial);
    CHECK_FALSE(result.ok());
    CHECK_FALSE(result.converged);
    CHECK(result.scene_points == 0);
    CHECK(result.scene_from_model.t == initial.t);
  }
  SUBCASE("one point") {
    const PointSet one = Eigen::Vector3d(0.1, 0.2, 0.3);
    const IcpResult result = RefineIcp(object, one, initial);
    CHECK_FALSE(result.ok());
    CHECK(result.scene_points == 1);
    CHECK(std::isfinite(result.rms_after));
    CHECK(result.rms_after == doctest::Approx(BruteForceRms(object, one, initial)));
  }
  SUBCASE("NaN-filled scene") {
    const IcpResult result = RefineIcp(object, PointSet::Constant(3, 50, nan), initial);
    CHECK_FALSE(result.ok());
    CHECK(result.scene_points == 0);
  }
  SUBCASE("a few NaN points among valid ones are ignored") {
    const Scene scene = SampleScene(object, 300, 3);
    PointSet mixed = scene.points;
    mixed.col(10).setConstant(nan);
    mixed(1, 20) = std::numeric_limits<double>::infinity();
    const IcpResult result = RefineIcp(object, mixed, scene.truth);
    CHECK(result.ok());
    CHECK(result.scene_points == 298);
    CHECK(std::isfinite(result.rms_after));
  }
  SUBCASE("huge coordinates") {
    const PointSet huge = 1e300 * SampleScene(object, 50, 6).points;
    IcpResult result;
    CHECK_NOTHROW(result = RefineIcp(object, huge, initial));
    CHECK(result.scene_from_model.IsFinite());
    CHECK_FALSE(result.converged);
  }
  SUBCASE("non-finite initial pose") {
    Pose broken = initial;
    broken.R(0, 0) = nan;
    const IcpResult result = RefineIcp(object, SampleScene(object, 100, 4).points, broken);
    CHECK_FALSE(result.ok());
  }
  SUBCASE("every point beyond the distance gate") {
    IcpOptions options;
    options.max_correspondence_distance = 1e-3;
    const PointSet far = PointSet::Constant(3, 20, 50.0) + PointSet::Random(3, 20);
    const IcpResult result = RefineIcp(object, far, initial, options);
    CHECK_FALSE(result.ok());
    CHECK(result.iterations == 0);
  }
  SUBCASE("zero iterations returns the initial pose with its residual") {
    IcpOptions options;
    options.max_iterations = 0;
    const Scene scene = SampleScene(object, 100, 5);
    const IcpResult result = RefineIcp(object, scene.points, initial, options);
    CHECK(result.iterations == 0);
    CHECK_FALSE(result.converged);
    CHECK(result.rms_after == result.rms_before);
    CHECK(result.scene_from_model.t == initial.t);
  }
}

TEST_CASE("IcpOptions::Check rejects out-of-range values") {
  IcpOptions options;
  CHECK_NOTHROW(options.Check());
  options.max_iterations = -1;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
  options = IcpOptions();
  options.trim_fraction = 0.95;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
  options = IcpOptions();
  options.max_correspondence_distance = 0.0;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
  options = IcpOptions();
  options.convergence_rotation = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(RefineIcp(test::AsymmetricObject(1000), PointSet(3, 0), Pose(), options),
                  std::invalid_argument);
}

TEST_CASE("ICP on the YCB power drill") {
  const std::string mesh_path = test::SharedData() + "/ycb/035_power_drill/textured.obj";
  if (!std::filesystem::exists(mesh_path)) {
    MESSAGE("skipped: " << mesh_path << " is absent");
    return;
  }
  ObjectSpec spec;
  spec.name = "drill";
  spec.keypoints = PointSet::Zero(3, 1);
  ObjectModelOptions model_options;
  model_options.sample_size = 5000;
  const ObjectModel object(spec, LoadMesh(mesh_path), model_options);
  const Eigen::Vector3d centroid = object.sample().rowwise().mean();
  const double d = object.diameter();
  const Scene scene = SampleScene(object, 800, 11);
  Rng rng(12);
  const Pose initial = Perturb(scene.truth, centroid, 10.0 * M_PI / 180.0, 0.02 * d, rng);
  IcpOptions options;
  options.max_iterations = 60;
  const IcpResult result = RefineIcp(object, scene.points, initial, options);
  CHECK(result.ok());
  CHECK(result.converged);
  CHECK(RotationError(result.scene_from_model.R, scene.truth.R) < 1.0 * M_PI / 180.0);
  CHECK(TranslationError(result.scene_from_model.t, scene.truth.t) < 0.005 * d);
}
