// RegisterPoints (paper eq. 8) against independent oracles: synthetic ground
// truth, Horn's quaternion method (a different closed form that can never
// return a reflection), the cost at perturbed poses, duplicated points.
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "c3po/base/random.hpp"
#include "c3po/geometry/registration.hpp"

namespace {

using c3po::PointSet;
using c3po::Pose;
using c3po::RegisterPoints;
using c3po::RegistrationStatus;

PointSet RandomPoints(c3po::Rng& rng, int n, double extent = 1.0) {
  PointSet points(3, n);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) points(k, i) = rng.Uniform(-extent, extent);
  }
  return points;
}

Pose RandomPose(c3po::Rng& rng) {
  Pose pose;
  pose.R = rng.Rotation();
  pose.t = Eigen::Vector3d(rng.Uniform(-2, 2), rng.Uniform(-2, 2), rng.Uniform(-2, 2));
  return pose;
}

// sum_i w_i ||y_i - T b_i||^2, the objective of eq. (8).
double Cost(const PointSet& model, const PointSet& scene, const Eigen::VectorXd& w, const Pose& T) {
  const PointSet residual = scene - T * model;
  return (residual.colwise().squaredNorm().transpose().array() * w.array()).sum();
}

// Horn (1987): the optimal rotation is the unit quaternion maximising q^T N q,
// i.e. the eigenvector of the largest eigenvalue of the symmetric 4x4 N.
Pose HornRegistration(const PointSet& model, const PointSet& scene, const Eigen::VectorXd& w) {
  const double total = w.sum();
  const Eigen::Vector3d mb = model * w / total, my = scene * w / total;
  const Eigen::Matrix3d S = (model.colwise() - mb) * w.asDiagonal() *
                            (scene.colwise() - my).transpose();  // S_ab = sum b_a y_b
  const double xx = S(0, 0), xy = S(0, 1), xz = S(0, 2), yx = S(1, 0), yy = S(1, 1),
               yz = S(1, 2), zx = S(2, 0), zy = S(2, 1), zz = S(2, 2);
  Eigen::Matrix4d N;
  N << xx + yy + zz, yz - zy, zx - xz, xy - yx,
       yz - zy, xx - yy - zz, xy + yx, zx + xz,
       zx - xz, xy + yx, -xx + yy - zz, yz + zy,
       xy - yx, zx + xz, yz + zy, -xx - yy + zz;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(N);
  const Eigen::Vector4d q = eig.eigenvectors().col(3);  // eigenvalues ascending
  Pose pose;
  pose.R = Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized().toRotationMatrix();
  pose.t = my - pose.R * mb;
  return pose;
}

void CheckProperRotation(const Eigen::Matrix3d& R) {
  CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-12);
  CHECK(R.determinant() == doctest::Approx(1.0).epsilon(1e-12));
}

// Every degenerate outcome: not ok, identity pose, nothing non-finite.
void CheckDegenerateOutcome(const c3po::RegistrationResult& r, RegistrationStatus expected) {
  CHECK(r.status == expected);
  CHECK_FALSE(r.ok());
  CHECK(r.scene_from_model.IsFinite());
  CHECK(r.scene_from_model.R.isApprox(Eigen::Matrix3d::Identity()));
  CHECK(r.scene_from_model.t.isZero());
  CHECK(std::isfinite(r.rms_residual));
  CHECK(r.singular_values.allFinite());
  CHECK(std::string(c3po::ToString(r.status)).size() > 0);
}

}  // namespace

TEST_CASE("noise-free random poses are recovered exactly") {
  c3po::Rng rng(1);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 3 + rng.UniformInt(30);
    const PointSet model = RandomPoints(rng, n);
    const Pose truth = RandomPose(rng);
    const auto result = RegisterPoints(model, truth * model);
    REQUIRE(result.ok());
    CheckProperRotation(result.scene_from_model.R);
    CHECK((result.scene_from_model.R - truth.R).norm() < 1e-9);
    CHECK((result.scene_from_model.t - truth.t).norm() < 1e-9);
    CHECK(result.rms_residual < 1e-9);
    // Singular values are reported sorted and equal those of M = Y_c B_c^T.
    const PointSet bc = model.colwise() - model.rowwise().mean();
    const PointSet yc = (truth * model).colwise() - (truth * model).rowwise().mean();
    const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(yc * bc.transpose()).singularValues();
    CHECK((result.singular_values - sv).norm() < 1e-9 * (1 + sv(0)));
  }
}

TEST_CASE("noisy registration is the minimum of the cost and agrees with Horn's method") {
  c3po::Rng rng(2);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 5 + rng.UniformInt(40);
    const PointSet model = RandomPoints(rng, n);
    const Pose truth = RandomPose(rng);
    PointSet scene = truth * model;
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) scene(k, i) += 0.05 * rng.Normal();
    }
    const Eigen::VectorXd w = Eigen::VectorXd::Ones(n);
    const auto result = RegisterPoints(model, scene);
    REQUIRE(result.ok());
    CheckProperRotation(result.scene_from_model.R);
    const Pose& estimate = result.scene_from_model;

    const Pose horn = HornRegistration(model, scene, w);
    CHECK((estimate.R - horn.R).norm() < 1e-8);
    CHECK((estimate.t - horn.t).norm() < 1e-8);

    const double best = Cost(model, scene, w, estimate);
    CHECK(result.rms_residual == doctest::Approx(std::sqrt(best / n)).epsilon(1e-9));
    for (int k = 0; k < 100; ++k) {
      const double size = std::pow(10.0, rng.Uniform(-4, -1));
      Pose perturbed;
      perturbed.R = rng.RotationUpTo(size) * estimate.R;
      perturbed.t = estimate.t + size * rng.UnitVector() * rng.Uniform();
      CHECK(Cost(model, scene, w, perturbed) >= best - 1e-12 * (1 + best));
    }
  }
}

TEST_CASE("integer weights equal duplicated points") {
  c3po::Rng rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 4 + rng.UniformInt(10);
    const PointSet model = RandomPoints(rng, n);
    PointSet scene = RandomPose(rng) * model;
    for (int i = 0; i < n; ++i) scene.col(i) += 0.1 * rng.UnitVector();
    Eigen::VectorXd w(n);
    for (int i = 0; i < n; ++i) w(i) = rng.UniformInt(4);  // 0..3, zero drops the point
    w(0) = w(1) = w(2) = 1;  // keep at least three points
    const int total = static_cast<int>(w.sum());
    PointSet model_rep(3, total), scene_rep(3, total);
    for (int i = 0, c = 0; i < n; ++i) {
      for (int r = 0; r < static_cast<int>(w(i)); ++r, ++c) {
        model_rep.col(c) = model.col(i);
        scene_rep.col(c) = scene.col(i);
      }
    }
    const auto weighted = RegisterPoints(model, scene, w);
    const auto repeated = RegisterPoints(model_rep, scene_rep);
    REQUIRE(weighted.ok());
    REQUIRE(repeated.ok());
    CHECK((weighted.scene_from_model.R - repeated.scene_from_model.R).norm() < 1e-9);
    CHECK((weighted.scene_from_model.t - repeated.scene_from_model.t).norm() < 1e-9);
    CHECK(weighted.rms_residual == doctest::Approx(repeated.rms_residual).epsilon(1e-9));
    // Scaling all weights changes nothing; Horn agrees with the weighted solution.
    const auto scaled = RegisterPoints(model, scene, 7.5 * w);
    CHECK((scaled.scene_from_model.R - weighted.scene_from_model.R).norm() < 1e-9);
    const Pose horn = HornRegistration(model, scene, w);
    CHECK((horn.R - weighted.scene_from_model.R).norm() < 1e-8);
  }
}

TEST_CASE("mirrored scene: plain SVD gives a reflection, the result is a proper rotation") {
  c3po::Rng rng(4);
  int reflections_seen = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 6 + rng.UniformInt(10);
    const PointSet model = RandomPoints(rng, n);
    const Eigen::Matrix3d mirror = Eigen::Vector3d(1, 1, -1).asDiagonal();
    const Pose pose = RandomPose(rng);
    const PointSet scene = (pose.R * mirror * model).colwise() + pose.t;

    const PointSet bc = model.colwise() - model.rowwise().mean();
    const PointSet yc = scene.colwise() - scene.rowwise().mean();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(yc * bc.transpose(),
                                                Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Matrix3d plain = svd.matrixU() * svd.matrixV().transpose();
    if (plain.determinant() < 0) ++reflections_seen;

    const auto result = RegisterPoints(model, scene);
    REQUIRE(result.ok());
    CheckProperRotation(result.scene_from_model.R);
    const Eigen::VectorXd w = Eigen::VectorXd::Ones(n);
    const Pose horn = HornRegistration(model, scene, w);
    const double cost = Cost(model, scene, w, result.scene_from_model);
    CHECK(cost <= Cost(model, scene, w, horn) + 1e-9);
    for (int k = 0; k < 50; ++k) {
      Pose perturbed = result.scene_from_model;
      perturbed.R = rng.RotationUpTo(0.05) * perturbed.R;
      CHECK(Cost(model, scene, w, perturbed) >= cost - 1e-12);
    }
  }
  CHECK(reflections_seen == 30);  // a mirror image always yields det(U V^T) = -1
}

TEST_CASE("planar configurations are recovered exactly (reflection correction)") {
  c3po::Rng rng(5);
  for (int trial = 0; trial < 100; ++trial) {
    const int n = 3 + rng.UniformInt(8);
    PointSet model = RandomPoints(rng, n);
    model.row(2).setZero();  // all points in the plane z = 0
    const Pose truth = RandomPose(rng);
    const auto result = RegisterPoints(model, truth * model);
    REQUIRE(result.ok());
    CheckProperRotation(result.scene_from_model.R);
    CHECK((result.scene_from_model.R - truth.R).norm() < 1e-8);
    CHECK((result.scene_from_model.t - truth.t).norm() < 1e-8);
  }
}

TEST_CASE("degenerate inputs are outcomes, not NaNs") {
  c3po::Rng rng(6);
  const Pose truth = RandomPose(rng);
  SUBCASE("no points") {
    CheckDegenerateOutcome(RegisterPoints(PointSet(3, 0), PointSet(3, 0)),
                           RegistrationStatus::kTooFewPoints);
  }
  SUBCASE("one and two points") {
    for (int n : {1, 2}) {
      const PointSet model = RandomPoints(rng, n);
      CheckDegenerateOutcome(RegisterPoints(model, truth * model), RegistrationStatus::kTooFewPoints);
    }
  }
  SUBCASE("all points identical") {
    const PointSet model = Eigen::Vector3d(0.3, -0.2, 0.9).replicate(1, 12);
    CheckDegenerateOutcome(RegisterPoints(model, truth * model), RegistrationStatus::kTooFewPoints);
  }
  SUBCASE("two distinct points repeated") {
    PointSet model(3, 10);
    for (int i = 0; i < 10; ++i) model.col(i) = (i % 2) ? Eigen::Vector3d(1, 2, 3) : Eigen::Vector3d(-1, 0, 0.5);
    const auto r = RegisterPoints(model, truth * model);
    CHECK_FALSE(r.ok());
    CHECK(r.scene_from_model.IsFinite());
  }
  SUBCASE("collinear points") {
    const Eigen::Vector3d origin(0.1, 0.2, 0.3), direction = rng.UnitVector();
    PointSet model(3, 8);
    for (int i = 0; i < 8; ++i) model.col(i) = origin + rng.Uniform(-1, 1) * direction;
    CheckDegenerateOutcome(RegisterPoints(model, truth * model), RegistrationStatus::kCollinear);
  }
  SUBCASE("scene collapsed to a point") {
    const PointSet model = RandomPoints(rng, 6);
    const PointSet scene = Eigen::Vector3d(1, 1, 1).replicate(1, 6);
    const auto r = RegisterPoints(model, scene);
    CHECK_FALSE(r.ok());
    CHECK(r.scene_from_model.IsFinite());
  }
  SUBCASE("zero weights") {
    const PointSet model = RandomPoints(rng, 6);
    CheckDegenerateOutcome(RegisterPoints(model, truth * model, Eigen::VectorXd::Zero(6)),
                           RegistrationStatus::kZeroWeights);
  }
  SUBCASE("only two positive weights") {
    const PointSet model = RandomPoints(rng, 6);
    Eigen::VectorXd w = Eigen::VectorXd::Zero(6);
    w(1) = 1;
    w(4) = 2;
    CheckDegenerateOutcome(RegisterPoints(model, truth * model, w), RegistrationStatus::kTooFewPoints);
  }
  SUBCASE("non-finite input") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (double bad : {nan, inf, -inf}) {
      PointSet model = RandomPoints(rng, 6);
      PointSet scene = truth * model;
      PointSet bad_model = model;
      bad_model(1, 3) = bad;
      CheckDegenerateOutcome(RegisterPoints(bad_model, scene), RegistrationStatus::kNonFinite);
      scene(2, 0) = bad;
      CheckDegenerateOutcome(RegisterPoints(model, scene), RegistrationStatus::kNonFinite);
      Eigen::VectorXd w = Eigen::VectorXd::Ones(6);
      w(2) = bad;
      if (!(bad < 0)) {  // a negative weight is a contract violation (tested below)
        CheckDegenerateOutcome(RegisterPoints(model, truth * model, w), RegistrationStatus::kNonFinite);
      }
    }
  }
  SUBCASE("coordinates too large to square are reported, not NaN") {
    const PointSet model = 1e200 * RandomPoints(rng, 6);
    const PointSet scene = 1e200 * RandomPoints(rng, 6);
    CheckDegenerateOutcome(RegisterPoints(model, scene), RegistrationStatus::kNonFinite);
  }
}

TEST_CASE("registration is scale-free over a wide range of units") {
  c3po::Rng rng(8);
  for (double scale : {1e-6, 1e-3, 1e3, 1e100}) {
    CAPTURE(scale);
    const PointSet model = scale * RandomPoints(rng, 10);
    Pose truth = RandomPose(rng);
    truth.t *= scale;
    const auto result = RegisterPoints(model, truth * model);
    REQUIRE(result.ok());
    CHECK((result.scene_from_model.R - truth.R).norm() < 1e-9);
    CHECK((result.scene_from_model.t - truth.t).norm() < 1e-9 * scale);
    CHECK(result.rms_residual < 1e-9 * scale);
  }
}

TEST_CASE("contract violations throw") {
  c3po::Rng rng(7);
  const PointSet model = RandomPoints(rng, 5);
  CHECK_THROWS_AS(RegisterPoints(model, RandomPoints(rng, 4)), std::invalid_argument);
  CHECK_THROWS_AS(RegisterPoints(model, model, Eigen::VectorXd::Ones(4)), std::invalid_argument);
  Eigen::VectorXd negative = Eigen::VectorXd::Ones(5);
  negative(3) = -0.5;
  CHECK_THROWS_AS(RegisterPoints(model, model, negative), std::invalid_argument);
}
