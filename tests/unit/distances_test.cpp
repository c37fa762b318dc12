// Chamfer and Hausdorff distances against brute-force double loops.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "c3po/base/random.hpp"
#include "c3po/geometry/distances.hpp"

namespace {

using c3po::PointSet;

PointSet RandomPoints(c3po::Rng& rng, int n) {
  PointSet points(3, n);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) points(k, i) = rng.Uniform(-1, 1);
  }
  return points;
}

// min_q ||p - q||^2 for every p, by a double loop.
Eigen::VectorXd BruteNearestSquared(const PointSet& from, const PointSet& to) {
  Eigen::VectorXd d(from.cols());
  for (Eigen::Index i = 0; i < from.cols(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (Eigen::Index j = 0; j < to.cols(); ++j) best = std::min(best, (from.col(i) - to.col(j)).squaredNorm());
    d(i) = best;
  }
  return d;
}

constexpr double kTol = 1e-12;

}  // namespace

TEST_CASE("Chamfer and Hausdorff match brute force on small random sets") {
  c3po::Rng rng(21);
  for (int trial = 0; trial < 60; ++trial) {
    const int na = 1 + rng.UniformInt(80), nb = 1 + rng.UniformInt(80);
    PointSet a = RandomPoints(rng, na);
    PointSet b = RandomPoints(rng, nb);
    if (trial % 4 == 0) b.col(0) = a.col(0);          // a shared point
    if (trial % 5 == 0) b.col(nb - 1) *= 10.0;        // an outlier
    const Eigen::VectorXd ab = BruteNearestSquared(a, b), ba = BruteNearestSquared(b, a);

    CHECK((c3po::NearestSquaredDistances(a, b) - ab).cwiseAbs().maxCoeff() < kTol);
    CHECK((c3po::NearestSquaredDistances(a, c3po::PointTree(b)) - ab).cwiseAbs().maxCoeff() < kTol);
    CHECK(c3po::ChamferMeanSquared(a, b) == doctest::Approx(ab.mean()).epsilon(kTol));
    CHECK(c3po::ChamferMaxSquared(a, b) == doctest::Approx(ab.maxCoeff()).epsilon(kTol));
    CHECK(c3po::DirectedHausdorff(a, b) == doctest::Approx(std::sqrt(ab.maxCoeff())).epsilon(kTol));
    CHECK(c3po::DirectedHausdorff(b, a) == doctest::Approx(std::sqrt(ba.maxCoeff())).epsilon(kTol));
    const double hausdorff = std::sqrt(std::max(ab.maxCoeff(), ba.maxCoeff()));
    CHECK(c3po::HausdorffDistance(a, b) == doctest::Approx(hausdorff).epsilon(kTol));
    CHECK(c3po::HausdorffDistance(b, a) == doctest::Approx(hausdorff).epsilon(kTol));
  }
}

TEST_CASE("a set has zero distance to itself and to a superset") {
  c3po::Rng rng(22);
  const PointSet a = RandomPoints(rng, 300);
  PointSet superset(3, 500);
  superset << a, RandomPoints(rng, 200);
  CHECK(c3po::ChamferMeanSquared(a, a) == 0.0);
  CHECK(c3po::HausdorffDistance(a, a) == 0.0);
  CHECK(c3po::ChamferMaxSquared(a, superset) == 0.0);
  CHECK(c3po::DirectedHausdorff(superset, a) > 0.0);
}

TEST_CASE("larger sets (parallel batch path) match brute force") {
  c3po::Rng rng(23);
  const PointSet a = RandomPoints(rng, 6000), b = RandomPoints(rng, 400);
  const Eigen::VectorXd ab = BruteNearestSquared(a, b);
  CHECK(c3po::ChamferMeanSquared(a, b) == doctest::Approx(ab.mean()).epsilon(kTol));
  CHECK(c3po::ChamferMaxSquared(a, b) == doctest::Approx(ab.maxCoeff()).epsilon(kTol));
}

TEST_CASE("empty sets") {
  c3po::Rng rng(24);
  const PointSet a = RandomPoints(rng, 10), empty(3, 0);
  // Nothing to measure from: zero. Something to measure to nothing: infinite.
  CHECK(c3po::ChamferMeanSquared(empty, a) == 0.0);
  CHECK(c3po::ChamferMaxSquared(empty, a) == 0.0);
  CHECK(std::isinf(c3po::ChamferMeanSquared(a, empty)));
  CHECK(std::isinf(c3po::ChamferMaxSquared(a, empty)));
  CHECK(c3po::DirectedHausdorff(empty, a) == 0.0);
  CHECK(std::isinf(c3po::DirectedHausdorff(a, empty)));
  CHECK(std::isinf(c3po::HausdorffDistance(a, empty)));
  CHECK(std::isinf(c3po::HausdorffDistance(empty, a)));
  CHECK(c3po::HausdorffDistance(empty, empty) == 0.0);
  CHECK(c3po::NearestSquaredDistances(empty, a).size() == 0);
  const Eigen::VectorXd to_nothing = c3po::NearestSquaredDistances(a, empty);
  REQUIRE(to_nothing.size() == 10);
  CHECK(to_nothing.array().isInf().all());
}
