// Metrics against brute force, numerical integration and closed forms.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/eval/metrics.hpp"

namespace {

using c3po::PointSet;
using c3po::Pose;

PointSet RandomPoints(c3po::Rng& rng, int n) {
  PointSet points(3, n);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) points(k, i) = rng.Uniform(-1, 1);
  }
  return points;
}

Pose RandomPose(c3po::Rng& rng) {
  Pose pose;
  pose.R = rng.Rotation();
  pose.t = Eigen::Vector3d(rng.Uniform(0, 1), rng.Uniform(0, 1), rng.Uniform(0, 1));
  return pose;
}

// mean_i min_j ||A b_i - B b_j|| by a double loop over explicitly posed samples.
double BruteMeanPosedDistance(const PointSet& sample, const Pose& a, const Pose& b) {
  const PointSet pa = a * sample, pb = b * sample;
  double total = 0.0;
  for (Eigen::Index i = 0; i < pa.cols(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (Eigen::Index j = 0; j < pb.cols(); ++j) best = std::min(best, (pa.col(i) - pb.col(j)).norm());
    total += best;
  }
  return total / static_cast<double>(pa.cols());
}

// Midpoint rule for (100 / m) * integral_0^m F(t) dt, F(t) = fraction of errors < t.
double NumericalAuc(const std::vector<double>& errors, double m, int steps) {
  const double h = m / steps;
  double integral = 0.0;
  for (int s = 0; s < steps; ++s) {
    const double t = (s + 0.5) * h;
    const auto below = std::count_if(errors.begin(), errors.end(), [t](double e) { return e < t; });
    integral += h * static_cast<double>(below) / static_cast<double>(errors.size());
  }
  return 100.0 * integral / m;
}

}  // namespace

TEST_CASE("ADD-S (one-sided and symmetric) matches brute force over posed samples") {
  c3po::Rng rng(31);
  const PointSet sample = RandomPoints(rng, 300);
  const c3po::PointTree tree(sample);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose truth = RandomPose(rng);
    Pose estimate = truth;
    if (trial % 2 == 0) {
      estimate = RandomPose(rng);
    } else {
      estimate.R = rng.RotationUpTo(0.2) * truth.R;
      estimate.t += 0.05 * rng.UnitVector();
    }
    const double forward = BruteMeanPosedDistance(sample, truth, estimate);
    const double backward = BruteMeanPosedDistance(sample, estimate, truth);
    CHECK(c3po::AddS(tree, truth, estimate) == doctest::Approx(forward).epsilon(1e-10));
    CHECK(c3po::AddS(tree, truth, estimate, c3po::AddSVariant::kOneSided) ==
          doctest::Approx(forward).epsilon(1e-10));
    CHECK(c3po::AddS(tree, truth, estimate, c3po::AddSVariant::kSymmetric) ==
          doctest::Approx(forward + backward).epsilon(1e-10));
  }
  const Pose pose = RandomPose(rng);
  CHECK(c3po::AddS(tree, pose, pose) == doctest::Approx(0.0).scale(1).epsilon(1e-12));
}

TEST_CASE("ADD-S is zero for a symmetric object under its symmetry") {
  // Orbit of random points under the 4-fold rotation about z.
  c3po::Rng rng(32);
  const PointSet seeds = RandomPoints(rng, 50);
  const Eigen::Matrix3d quarter = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  PointSet orbit(3, 200);
  for (int k = 0; k < 4; ++k) {
    Eigen::Matrix3d power = Eigen::Matrix3d::Identity();
    for (int j = 0; j < k; ++j) power = quarter * power;
    orbit.middleCols(50 * k, 50) = power * seeds;
  }
  const c3po::PointTree tree(orbit);
  const Pose truth = RandomPose(rng);
  Pose symmetric = truth;
  symmetric.R = truth.R * quarter;
  CHECK(c3po::AddS(tree, truth, symmetric, c3po::AddSVariant::kSymmetric) < 1e-9);
  Pose rotated = truth;
  rotated.R = truth.R * Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  CHECK(c3po::AddS(tree, truth, rotated) > 1e-3);
}

TEST_CASE("ThresholdScore counts errors strictly below the threshold") {
  c3po::Rng rng(33);
  std::vector<double> errors;
  for (int i = 0; i < 101; ++i) errors.push_back(rng.Uniform(0, 0.1));
  errors.push_back(0.05);  // exactly at the threshold: not counted
  errors.push_back(std::numeric_limits<double>::quiet_NaN());  // a failure
  errors.push_back(std::numeric_limits<double>::infinity());
  for (double threshold : {0.0, 0.02, 0.05, 0.2}) {
    int below = 0;
    for (double e : errors) below += (e < threshold) ? 1 : 0;
    CHECK(c3po::ThresholdScore(errors, threshold) ==
          doctest::Approx(100.0 * below / static_cast<double>(errors.size())));
  }
  CHECK(c3po::ThresholdScore({0.05}, 0.05) == 0.0);
  CHECK(std::isnan(c3po::ThresholdScore({}, 0.05)));
}

TEST_CASE("ADD-S AUC matches numerical integration of the accuracy curve") {
  c3po::Rng rng(34);
  constexpr int kSteps = 200000;
  for (int trial = 0; trial < 10; ++trial) {
    const double m = rng.Uniform(0.01, 1.0);
    std::vector<double> errors;
    const int n = 1 + rng.UniformInt(60);
    for (int i = 0; i < n; ++i) errors.push_back(rng.Uniform(0, 1.5 * m));
    if (trial % 2 == 0) {
      errors.push_back(0.0);
      errors.push_back(m);
      errors.push_back(std::numeric_limits<double>::quiet_NaN());
      errors.push_back(std::numeric_limits<double>::infinity());
    }
    // Each error moves the midpoint-rule integral by at most one step h, so the
    // normalised AUC differs by at most 100 h / m.
    const double tolerance = 100.0 / kSteps + 1e-9;
    CHECK(std::abs(c3po::AddSAuc(errors, m) - NumericalAuc(errors, m, kSteps)) <= tolerance);
  }
  CHECK(c3po::AddSAuc({0.0, 0.0}, 0.1) == doctest::Approx(100.0));
  CHECK(c3po::AddSAuc({0.2, 5.0}, 0.1) == 0.0);
  CHECK(std::isnan(c3po::AddSAuc({}, 0.1)));
  CHECK_THROWS_AS(c3po::AddSAuc({0.1}, 0.0), std::invalid_argument);
  CHECK_THROWS_AS(c3po::AddSAuc({0.1}, -1.0), std::invalid_argument);
}

TEST_CASE("RotationError equals the arccos formula and known angle-axis angles") {
  c3po::Rng rng(35);
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Matrix3d a = rng.Rotation(), b = rng.Rotation();
    const double cosine = ((a.transpose() * b).trace() - 1.0) / 2.0;
    const double angle = c3po::RotationError(a, b);
    CHECK(angle >= 0.0);
    CHECK(angle <= M_PI);
    // arccos loses precision near 0 and pi; elsewhere it is an accurate oracle.
    if (std::abs(cosine) < 0.999) CHECK(angle == doctest::Approx(std::acos(cosine)).epsilon(1e-9));
    CHECK(c3po::RotationError(b, a) == doctest::Approx(angle).epsilon(1e-12));
  }
  for (double angle : {0.0, 1e-12, 1e-8, 1e-4, 0.3, 1.0, M_PI / 2, 2.5, M_PI - 1e-4, M_PI - 1e-7, M_PI}) {
    for (int k = 0; k < 5; ++k) {
      CAPTURE(angle);
      const Eigen::Matrix3d base = rng.Rotation();
      const Eigen::Matrix3d delta = Eigen::AngleAxisd(angle, rng.UnitVector()).toRotationMatrix();
      CHECK(c3po::RotationError(Eigen::Matrix3d::Identity(), delta) ==
            doctest::Approx(angle).epsilon(1e-9).scale(1e-6));
      // Composition rounding is ~1e-16 per entry: absolute accuracy ~1e-7 near pi
      // (the angle's sensitivity to trace noise there), ~1e-15 elsewhere.
      const double tolerance = angle > 3.0 ? 1e-6 : 1e-12;
      CHECK(std::abs(c3po::RotationError(base, base * delta) - angle) < tolerance);
    }
  }
}

TEST_CASE("TranslationError is the Euclidean distance") {
  CHECK(c3po::TranslationError(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 6, 3)) == doctest::Approx(5.0));
  CHECK(c3po::TranslationError(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 2, 3)) == 0.0);
}

TEST_CASE("Median of odd, even and empty lists") {
  c3po::Rng rng(36);
  for (int n = 1; n <= 25; ++n) {
    std::vector<double> values;
    for (int i = 0; i < n; ++i) values.push_back(rng.UniformInt(5) == 0 ? 0.5 : rng.Uniform(-3, 3));
    std::vector<double> sorted = values;
    std::sort(sorted.begin(), sorted.end());
    const double expected = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
    CHECK(c3po::Median(values) == expected);
  }
  CHECK(c3po::Median({2.0, 1.0}) == 1.5);
  CHECK(std::isnan(c3po::Median({})));
}

TEST_CASE("ADD-S variant names round trip") {
  for (auto v : {c3po::AddSVariant::kOneSided, c3po::AddSVariant::kSymmetric}) {
    CHECK(c3po::ParseAddSVariant(c3po::ToString(v)) == v);
  }
  CHECK_THROWS_AS(c3po::ParseAddSVariant("both"), c3po::InputError);
}
