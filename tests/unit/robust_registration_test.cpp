// TEASER-style robust registration: maximum clique vs enumeration, GNC-TLS
// rotation with 80 % outliers, adaptive voting vs a dense grid of the TLS
// cost, and the whole chain with planted outlier correspondences.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "c3po/base/random.hpp"
#include "c3po/method/robust_registration.hpp"

using namespace c3po;

namespace {

double RotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return std::acos(std::clamp(((a.transpose() * b).trace() - 1) / 2, -1.0, 1.0));
}

Graph RandomGraph(int n, double density, Rng& rng, std::vector<std::vector<bool>>* matrix) {
  Graph graph(n);
  matrix->assign(n, std::vector<bool>(n, false));
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if (rng.Uniform() < density) {
        graph[i].push_back(j);
        graph[j].push_back(i);
        (*matrix)[i][j] = (*matrix)[j][i] = true;
      }
    }
  }
  return graph;
}

// Oracle: the size of the largest clique over all 2^n vertex subsets.
int EnumeratedCliqueSize(const std::vector<std::vector<bool>>& adjacent) {
  const int n = static_cast<int>(adjacent.size());
  int best = 0;
  for (std::uint32_t mask = 0; mask < (1u << n); ++mask) {
    const int size = __builtin_popcount(mask);
    if (size <= best) continue;
    bool clique = true;
    for (int i = 0; i < n && clique; ++i) {
      if (!(mask >> i & 1)) continue;
      for (int j = i + 1; j < n; ++j) {
        if ((mask >> j & 1) && !adjacent[i][j]) { clique = false; break; }
      }
    }
    if (clique) best = size;
  }
  return best;
}

}  // namespace

TEST_CASE("Maximum clique equals enumeration on random graphs up to 20 vertices") {
  Rng rng(5);
  for (int trial = 0; trial < 60; ++trial) {
    const int n = 1 + trial % 20;
    const double density = 0.2 + 0.7 * rng.Uniform();
    std::vector<std::vector<bool>> adjacent;
    const Graph graph = RandomGraph(n, density, rng, &adjacent);
    const MaxCliqueResult result = MaximumClique(graph);
    CAPTURE(trial);
    CHECK(result.exact);
    CHECK(static_cast<int>(result.clique.size()) == EnumeratedCliqueSize(adjacent));
    for (std::size_t a = 0; a < result.clique.size(); ++a) {
      for (std::size_t b = a + 1; b < result.clique.size(); ++b) {
        CHECK(adjacent[result.clique[a]][result.clique[b]]);
      }
    }
  }
}

TEST_CASE("Maximum clique: degenerate graphs and the branch budget") {
  CHECK(MaximumClique(Graph()).clique.empty());
  CHECK(MaximumClique(Graph(4)).clique.size() == 1);   // no edges
  Graph complete(8);
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      if (i != j) complete[i].push_back(j);
    }
  }
  CHECK(MaximumClique(complete).clique.size() == 8);
  // A budget of one node returns a clique (possibly not maximum) flagged inexact.
  Rng rng(9);
  std::vector<std::vector<bool>> adjacent;
  const Graph dense = RandomGraph(60, 0.7, rng, &adjacent);
  const MaxCliqueResult capped = MaximumClique(dense, 1);
  CHECK_FALSE(capped.exact);
  CHECK_THROWS_AS(MaximumClique(Graph{{5}}), std::invalid_argument);
}

TEST_CASE("GNC-TLS rotation recovers a planted rotation with 80 % outliers") {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    Rng rng(seed);
    const Eigen::Matrix3d truth = rng.Rotation();
    const int m = 200;
    PointSet model(3, m), scene(3, m);
    for (int i = 0; i < m; ++i) {
      model.col(i) = rng.UnitVector() * rng.Uniform(0.5, 1.0);
      if (i < m / 5) {
        scene.col(i) = truth * model.col(i) + 0.005 * Eigen::Vector3d(rng.Normal(), rng.Normal(), rng.Normal());
      } else {
        scene.col(i) = rng.UnitVector() * rng.Uniform(0.5, 1.0);
      }
    }
    GncTlsOptions options;
    options.noise_bound = 0.03;
    const GncTlsRotationResult result = GncTlsRotation(model, scene, options);
    CAPTURE(seed);
    CHECK(result.ok);
    CHECK(RotationAngle(result.R, truth) < 2.0 * M_PI / 180);
    // Plain least squares (the oracle for "outliers matter") is far off.
    GncTlsOptions huge = options;
    huge.noise_bound = 100;
    CHECK(RotationAngle(GncTlsRotation(model, scene, huge).R, truth) > 5.0 * M_PI / 180);
    // Every planted inlier is found.
    int planted = 0;
    for (int i : result.inliers) planted += i < m / 5 ? 1 : 0;
    CHECK(planted == m / 5);
  }
}

TEST_CASE("Adaptive voting minimises the 1-D TLS cost (dense grid oracle)") {
  Rng rng(21);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 1 + trial;
    std::vector<double> values, bounds;
    for (int i = 0; i < n; ++i) {
      values.push_back(i % 3 == 0 ? rng.Uniform(-1, 1) : 0.3 + 0.05 * rng.Normal());
      bounds.push_back(trial % 2 ? 0.1 : rng.Uniform(0.02, 0.2));
    }
    auto cost = [&](double t) {
      double c = 0;
      for (int i = 0; i < n; ++i) c += std::min((values[i] - t) * (values[i] - t), bounds[i] * bounds[i]);
      return c;
    };
    double grid_best = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= 400000; ++k) grid_best = std::min(grid_best, cost(-1.5 + 3.0 * k / 400000));
    const VotingResult result = AdaptiveVoting(values, bounds);
    CAPTURE(trial);
    CHECK(result.cost == doctest::Approx(cost(result.value)).epsilon(1e-12));
    CHECK(result.cost <= grid_best + 1e-12);
    CHECK(result.cost >= grid_best - 1e-4);   // the grid is fine enough to be close
  }
  CHECK(AdaptiveVoting({}, {}).inliers.empty());
  CHECK_THROWS_AS(AdaptiveVoting({1.0}, {0.0}), std::invalid_argument);
}

TEST_CASE("Robust registration with 90 % outlier correspondences") {
  Rng rng(3);
  Pose truth;
  truth.R = rng.Rotation();
  truth.t = Eigen::Vector3d(0.1, -0.3, 0.7);
  const int m = 300, inliers = 30;
  PointSet model(3, m), scene(3, m);
  for (int i = 0; i < m; ++i) {
    model.col(i) = Eigen::Vector3d(rng.Uniform(-0.1, 0.1), rng.Uniform(-0.1, 0.1), rng.Uniform(-0.1, 0.1));
    const Eigen::Vector3d noise = 0.001 * Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1));
    scene.col(i) = i % 10 == 0 ? Eigen::Vector3d(truth * Eigen::Vector3d(model.col(i)) + noise)
                               : Eigen::Vector3d(truth * Eigen::Vector3d(rng.Uniform(-0.1, 0.1), rng.Uniform(-0.1, 0.1),
                                                                         rng.Uniform(-0.1, 0.1)));
  }
  RobustRegistrationOptions options;
  options.noise_bound = 0.002;
  const RobustRegistrationResult result = RegisterRobust(model, scene, options);
  REQUIRE(result.ok());
  CHECK(result.clique_size >= inliers);
  CHECK(RotationAngle(result.scene_from_model.R, truth.R) < 1.0 * M_PI / 180);
  CHECK((result.scene_from_model.t - truth.t).norm() < 0.004);
  CHECK(result.translation_inliers >= inliers);

  SUBCASE("degenerate input is a failure, not a crash") {
    CHECK_FALSE(RegisterRobust(model.leftCols(2), scene.leftCols(2), options).ok());
    PointSet nan_scene = scene;
    nan_scene.fill(std::numeric_limits<double>::quiet_NaN());
    CHECK_FALSE(RegisterRobust(model, nan_scene, options).ok());
    CHECK_THROWS_AS(RegisterRobust(model, scene.leftCols(5), options), std::invalid_argument);
  }
}
