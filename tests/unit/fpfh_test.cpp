// FPFH (Rusu et al. 2009): the pair feature on an analytic case, the
// descriptors against a brute-force computation (all-pairs neighbour search,
// direct formulas), invariance to rigid motion, degenerate clouds.
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "c3po/base/random.hpp"
#include "c3po/geometry/fpfh.hpp"
#include "test_objects.hpp"

using namespace c3po;

namespace {

FpfhOptions Options(double normal_radius, double feature_radius) {
  FpfhOptions options;
  options.normal_radius = normal_radius;
  options.feature_radius = feature_radius;
  options.max_neighbors = 1000;   // larger than any neighbourhood below: radius search
  options.orientation = NormalOrientation::kAwayFromCentroid;
  return options;
}

// Oracle: O(n^2) neighbourhoods, normals by PCA, histograms by the paper's formulas.
FpfhFeatures BruteForceFpfh(const PointSet& points, const FpfhOptions& options, PointSet* normals_out) {
  const Eigen::Index n = points.cols();
  const Eigen::Vector3d centroid = points.rowwise().mean();
  PointSet normals = PointSet::Zero(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    std::vector<Eigen::Index> nb;
    for (Eigen::Index j = 0; j < n; ++j) {
      if ((points.col(j) - points.col(i)).norm() <= options.normal_radius) nb.push_back(j);
    }
    if (nb.size() < 3) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (auto j : nb) mean += points.col(j);
    mean /= static_cast<double>(nb.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (auto j : nb) cov += (points.col(j) - mean) * (points.col(j) - mean).transpose();
    Eigen::Vector3d normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
    if (normal.dot(points.col(i) - centroid) < 0) normal = -normal;
    normals.col(i) = normal.normalized();
  }
  auto bin = [](double v, double lo, double hi) {
    int b = static_cast<int>(std::floor(11 * (v - lo) / (hi - lo)));
    return b < 0 ? 0 : (b > 10 ? 10 : b);
  };
  auto normalise = [](Eigen::VectorXd h) {
    for (int k = 0; k < 3; ++k) {
      const double s = h.segment(11 * k, 11).sum();
      if (s > 0) h.segment(11 * k, 11) *= 100 / s;
    }
    return h;
  };
  std::vector<std::vector<Eigen::Index>> neighbours(n);
  FpfhFeatures spfh = FpfhFeatures::Zero(33, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j) {
      if (j != i && (points.col(j) - points.col(i)).norm() <= options.feature_radius) neighbours[i].push_back(j);
    }
    Eigen::VectorXd h = Eigen::VectorXd::Zero(33);
    // Points without a normal (< 3 neighbours) contribute no pair (the documented rule).
    for (auto j : neighbours[i]) {
      if (normals.col(i).isZero() || normals.col(j).isZero()) continue;
      // Direct transcription of Rusu 2009 eqs. (1)-(3).
      Eigen::Vector3d ps = points.col(i), pt = points.col(j), ns = normals.col(i), nt = normals.col(j);
      Eigen::Vector3d d = (pt - ps).normalized();
      if (std::acos(ns.dot(d)) > std::acos(nt.dot(-d))) {
        std::swap(ps, pt);
        std::swap(ns, nt);
        d = -d;
      }
      const Eigen::Vector3d u = ns, v = u.cross(d).normalized(), w = u.cross(v);
      h(bin(std::atan2(w.dot(nt), u.dot(nt)), -M_PI, M_PI)) += 1;
      h(11 + bin(v.dot(nt), -1, 1)) += 1;
      h(22 + bin(u.dot(d), -1, 1)) += 1;
    }
    spfh.col(i) = normalise(h);
  }
  FpfhFeatures fpfh(33, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::VectorXd h = spfh.col(i);
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(33);
    for (auto j : neighbours[i]) sum += spfh.col(j) / (points.col(j) - points.col(i)).norm();
    if (!neighbours[i].empty()) h += sum / static_cast<double>(neighbours[i].size());
    fpfh.col(i) = normalise(h);
  }
  *normals_out = normals;
  return fpfh;
}

// A small curved surface patch (part of an ellipsoid) with jitter.
PointSet EllipsoidPatch(int count, std::uint64_t seed) {
  Rng rng(seed);
  PointSet points(3, count);
  for (int i = 0; i < count; ++i) {
    Eigen::Vector3d u = rng.UnitVector();
    if (u.z() < -0.3) u.z() = -u.z();
    points.col(i) = Eigen::Vector3d(0.10 * u.x(), 0.06 * u.y(), 0.04 * u.z());
  }
  return points;
}

}  // namespace

TEST_CASE("PairFeature on an analytic case") {
  // p1 at origin with normal +z, p2 on the x axis with normal tilted by 30 deg in the x-z plane.
  const double a = M_PI / 6;
  const Eigen::Vector3d n2(std::sin(a), 0, std::cos(a));
  const Eigen::Vector3d f = PairFeature({0, 0, 0}, {0, 0, 1}, {1, 0, 0}, n2);
  // Source is p1 (its normal is at 90 deg to the line, n2 at 90-30 to -d: n2 . -d = -sin a -> 120 deg).
  // u = z, v = z x x = y, w = z x y = -x.
  CHECK(f(0) == doctest::Approx(0.0).epsilon(1e-12));                                   // alpha = y . n2
  CHECK(f(1) == doctest::Approx(0.0).epsilon(1e-12));                                   // phi = z . x
  CHECK(f(2) == doctest::Approx(std::atan2(-std::sin(a), std::cos(a))).epsilon(1e-12)); // theta
  // Swapping the points gives the same feature (the source choice is symmetric).
  const Eigen::Vector3d g = PairFeature({1, 0, 0}, n2, {0, 0, 0}, {0, 0, 1});
  CHECK((f - g).norm() < 1e-12);
}

TEST_CASE("FPFH equals a brute-force computation on a small cloud") {
  const PointSet points = EllipsoidPatch(300, 3);
  const FpfhOptions options = Options(0.02, 0.035);
  PointSet oracle_normals;
  const FpfhFeatures oracle = BruteForceFpfh(points, options, &oracle_normals);
  const PointTree tree(points);
  const PointSet normals = EstimateNormals(tree, options);
  // Normals agree up to the orientation rule (same rule in both).
  CHECK((normals - oracle_normals).cwiseAbs().maxCoeff() < 1e-9);
  const FpfhFeatures features = ComputeFpfh(tree, normals, options);
  REQUIRE(features.cols() == 300);
  int without_normal = 0;
  for (int i = 0; i < 300; ++i) without_normal += normals.col(i).isZero() ? 1 : 0;
  MESSAGE(without_normal << " of 300 points without a normal");
  CHECK((features - oracle).cwiseAbs().maxCoeff() < 1e-6);
  // Each 11-bin block sums to 100 where the point has neighbours.
  for (int i = 0; i < 300; ++i) {
    if (features.col(i).isZero()) continue;
    for (int k = 0; k < 3; ++k) CHECK(features.col(i).segment(11 * k, 11).sum() == doctest::Approx(100));
  }
}

TEST_CASE("FPFH is invariant to rigid motion") {
  const ObjectModel object = test::AsymmetricObject(3000);
  const PointSet& points = object.sample();
  Rng rng(11);
  Pose motion;
  motion.R = rng.Rotation();
  motion.t = Eigen::Vector3d(0.3, -0.2, 0.8);
  const PointSet moved = motion * points;
  const FpfhOptions options = Options(0.015, 0.03);
  const PointTree tree(points), moved_tree(moved);
  const FpfhFeatures f = ComputeFpfh(tree, EstimateNormals(tree, options), options);
  const FpfhFeatures g = ComputeFpfh(moved_tree, EstimateNormals(moved_tree, options), options);
  // Bin boundaries can flip a count under rounding; compare per point with a
  // tolerance of a few counts and require near-equality in aggregate.
  const Eigen::VectorXd difference = (f - g).cwiseAbs().colwise().sum().transpose();
  int close = 0;
  for (Eigen::Index i = 0; i < difference.size(); ++i) close += difference(i) < 1e-6 ? 1 : 0;
  CHECK(close >= 0.99 * difference.size());
  // A different object region gives a different descriptor (the test can fail).
  CHECK((f.col(0) - f.col(1500)).norm() > 1.0);
}

TEST_CASE("FPFH on degenerate clouds") {
  const FpfhOptions options = Options(0.01, 0.02);
  SUBCASE("empty") {
    const PointTree tree{PointSet(3, 0)};
    CHECK(EstimateNormals(tree, options).cols() == 0);
    CHECK(ComputeFpfh(tree, PointSet(3, 0), options).cols() == 0);
  }
  SUBCASE("isolated points get zero normals and zero descriptors") {
    PointSet points(3, 2);
    points << 0, 1, 0, 0, 0, 0;
    const PointTree tree(points);
    const PointSet normals = EstimateNormals(tree, options);
    CHECK(normals.isZero());
    CHECK(ComputeFpfh(tree, normals, options).isZero());
  }
  SUBCASE("bad options and sizes") {
    FpfhOptions bad = options;
    bad.feature_radius = 0;
    CHECK_THROWS_AS(bad.Check(), std::invalid_argument);
    const PointTree tree{PointSet::Zero(3, 4)};
    CHECK_THROWS_AS(ComputeFpfh(tree, PointSet(3, 3), options), std::invalid_argument);
  }
}
