// Corrector: analytic gradients vs finite differences; recovery of the ground
// truth from perturbed keypoints; the fast solver vs the reference gd.
#include <doctest/doctest.h>

#include "c3po/base/random.hpp"
#include "c3po/eval/metrics.hpp"
#include "c3po/geometry/registration.hpp"
#include "c3po/method/corrector.hpp"
#include "test_objects.hpp"

using namespace c3po;

namespace {

// L(R, t) = <A, R> + g·t for fixed random A, g: a linear test functional.
double LinearFunctional(const Pose& T, const Eigen::Matrix3d& A, const Eigen::Vector3d& g) {
  return (A.array() * T.R.array()).sum() + g.dot(T.t);
}

Pose RandomPose(Rng& rng, double translation) {
  Pose T;
  T.R = rng.Rotation();
  T.t = Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1)) * translation;
  return T;
}

// Keypoints perturbed as in the paper's corrector experiment: with probability
// `fraction`, uniform noise in [-sigma d / 2, sigma d / 2] per coordinate.
PointSet Perturb(const PointSet& keypoints, double sigma, double fraction, double d, Rng& rng) {
  PointSet out = keypoints;
  for (Eigen::Index i = 0; i < out.cols(); ++i) {
    if (rng.Uniform() >= fraction) continue;
    for (int k = 0; k < 3; ++k) out(k, i) += rng.Uniform(-0.5, 0.5) * sigma * d;
  }
  return out;
}

}  // namespace

TEST_CASE("RegistrationBackward matches finite differences of the registration") {
  Rng rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const int n = 6 + trial;
    const PointSet b = PointSet::Random(3, n);
    const Pose truth = RandomPose(rng, 1.0);
    const PointSet y = truth * b + 0.05 * PointSet::Random(3, n);
    const Eigen::Matrix3d A = Eigen::Matrix3d::Random();
    const Eigen::Vector3d g = Eigen::Vector3d::Random();
    const RegistrationResult reg = RegisterPoints(b, y);
    REQUIRE(reg.ok());
    const PointSet analytic = RegistrationBackward(b, y, reg.scene_from_model, A, g);
    const double h = 1e-6;
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) {
        PointSet plus = y, minus = y;
        plus(k, i) += h;
        minus(k, i) -= h;
        const double numeric = (LinearFunctional(RegisterPoints(b, plus).scene_from_model, A, g) -
                                LinearFunctional(RegisterPoints(b, minus).scene_from_model, A, g)) /
                               (2 * h);
        CHECK(analytic(k, i) == doctest::Approx(numeric).epsilon(1e-5).scale(1.0));
      }
    }
  }
}

TEST_CASE("corrector objective gradient matches finite differences (mean and max)") {
  const ObjectModel object = test::AsymmetricObject(100);  // sparse sample: stable nearest neighbours
  Rng rng(3);
  const Pose truth = RandomPose(rng, 0.3);
  // Cloud: a few model sample points (posed) plus small offsets, so that each
  // point's nearest neighbour is unambiguous.
  PointSet cloud(3, 30);
  for (int j = 0; j < 30; ++j) {
    cloud.col(j) = truth * Eigen::Vector3d(object.sample().col(3 * j)) +
                   0.001 * Eigen::Vector3d::Random();
  }
  const PointSet y = Perturb(truth * object.keypoints(), 0.02, 1.0, object.diameter(), rng);
  for (PointCloudLoss loss : {PointCloudLoss::kMeanSquared, PointCloudLoss::kMaxSquared}) {
    CAPTURE(ToString(loss));
    CorrectorOptions options;
    options.loss = loss;
    PointSet gradient;
    EvaluateCorrectorObjective(object, cloud, y, options, &gradient);
    const double h = 1e-7;
    for (Eigen::Index i = 0; i < y.cols(); ++i) {
      for (int k = 0; k < 3; ++k) {
        PointSet plus = y, minus = y;
        plus(k, i) += h;
        minus(k, i) -= h;
        const double numeric = (EvaluateCorrectorObjective(object, cloud, plus, options).value -
                                EvaluateCorrectorObjective(object, cloud, minus, options).value) /
                               (2 * h);
        CHECK(gradient(k, i) == doctest::Approx(numeric).epsilon(1e-4).scale(1e-3));
      }
    }
  }
}

TEST_CASE("corrector recovers the pose from perturbed keypoints (fast and gd)") {
  const ObjectModel object = test::AsymmetricObject();
  const double d = object.diameter();
  Rng rng(11);
  for (int trial = 0; trial < 4; ++trial) {
    const Pose truth = RandomPose(rng, 0.5);
    const PointSet cloud = truth * SampleSurface(object.mesh(), 600, 100 + trial);
    const PointSet detected = Perturb(truth * object.keypoints(), 0.3, 0.8, d, rng);
    const double error_before =
        RotationError(RegisterPoints(object.keypoints(), detected).scene_from_model.R, truth.R);
    for (CorrectorSolver solver : {CorrectorSolver::kFast, CorrectorSolver::kGradientDescent}) {
      CAPTURE(trial);
      CAPTURE(ToString(solver));
      CorrectorOptions options;
      options.solver = solver;
      const CorrectorResult result = CorrectKeypoints(object, cloud, detected, options);
      REQUIRE(result.ok());
      CHECK(result.cost_after <= result.cost_before);
      const double rotation_error = RotationError(result.scene_from_model.R, truth.R);
      CHECK(rotation_error < 0.05);                 // < 3 degrees
      CHECK(rotation_error <= error_before + 1e-9);
      CHECK(TranslationError(result.scene_from_model.t, truth.t) < 0.02 * d);
    }
  }
}

TEST_CASE("the fast solver reaches an optimum at least as good as gd") {
  const ObjectModel object = test::AsymmetricObject();
  Rng rng(5);
  int fast_not_worse = 0;
  const int trials = 6;
  for (int trial = 0; trial < trials; ++trial) {
    const Pose truth = RandomPose(rng, 0.5);
    const PointSet cloud = truth * SampleSurface(object.mesh(), 500, 200 + trial);
    const PointSet detected = Perturb(truth * object.keypoints(), 0.2, 0.8, object.diameter(), rng);
    CorrectorOptions fast, gd;
    gd.solver = CorrectorSolver::kGradientDescent;
    const double fast_cost = CorrectKeypoints(object, cloud, detected, fast).cost_after;
    const double gd_cost = CorrectKeypoints(object, cloud, detected, gd).cost_after;
    if (fast_cost <= gd_cost * 1.01 + 1e-12) ++fast_not_worse;
  }
  CHECK(fast_not_worse == trials);
}

TEST_CASE("corrector: degenerate inputs are outcomes, not crashes") {
  const ObjectModel object = test::AsymmetricObject();
  const PointSet keypoints = object.keypoints();
  SUBCASE("empty cloud") {
    const CorrectorResult r = CorrectKeypoints(object, PointSet(3, 0), keypoints);
    CHECK_FALSE(r.ok());
    CHECK(r.keypoints.isApprox(keypoints));
  }
  SUBCASE("collinear detected keypoints") {
    PointSet line = PointSet::Zero(3, keypoints.cols());
    for (Eigen::Index i = 0; i < line.cols(); ++i) line(0, i) = 0.01 * i;
    const CorrectorResult r = CorrectKeypoints(object, object.sample(), line);
    CHECK_FALSE(r.ok());
    CHECK(r.registration == RegistrationStatus::kCollinear);
  }
  SUBCASE("NaN in the cloud") {
    PointSet cloud = object.sample();
    cloud(0, 5) = std::nan("");
    const CorrectorResult r = CorrectKeypoints(object, cloud, keypoints);
    CHECK_FALSE(r.ok());
  }
  SUBCASE("wrong keypoint count is a broken contract") {
    CHECK_THROWS_AS(CorrectKeypoints(object, object.sample(), PointSet::Zero(3, 2)),
                    std::invalid_argument);
  }
}
