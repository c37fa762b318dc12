// NearestGrid against brute-force linear scans: surfaces (where its lists
// answer), far and non-finite queries (where the tree does), ties and
// degenerate point sets.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "c3po/base/random.hpp"
#include "c3po/geometry/nearest_grid.hpp"

namespace {

using c3po::NearestGrid;
using c3po::PointSet;
using c3po::PointTree;

// Points on a sphere of radius 0.1 and on a 0.2 x 0.1 x 0.02 box's faces:
// sampled surfaces as object models have them.
PointSet SurfacePoints(c3po::Rng& rng, int n) {
  PointSet points(3, n);
  for (int i = 0; i < n; ++i) {
    if (i % 2 == 0) {
      Eigen::Vector3d u(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1));
      if (u.norm() < 1e-6) u = Eigen::Vector3d::UnitX();
      points.col(i) = 0.1 * u.normalized();
    } else {
      const Eigen::Vector3d half(0.1, 0.05, 0.01);
      Eigen::Vector3d p(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1));
      const int face = rng.UniformInt(3);
      p(face) = p(face) < 0 ? -1.0 : 1.0;
      points.col(i) = p.cwiseProduct(half) + Eigen::Vector3d(0.3, 0.0, 0.0);
    }
  }
  return points;
}

// Queries: near the points (the grid's part), exactly on them, on cell
// boundaries' scale of rounding, and far away (the tree's part).
PointSet Queries(c3po::Rng& rng, const PointSet& data, int n) {
  PointSet queries(3, n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d on = data.col(rng.UniformInt(static_cast<int>(data.cols())));
    const Eigen::Vector3d jitter(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1));
    switch (i % 4) {
      case 0: queries.col(i) = on + 0.003 * jitter; break;
      case 1: queries.col(i) = on; break;
      case 2: queries.col(i) = on + 0.03 * jitter; break;
      default: queries.col(i) = 2.0 * jitter; break;
    }
  }
  return queries;
}

double BruteForceSquared(const PointSet& data, const Eigen::Vector3d& query) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < data.cols(); ++i) best = std::min(best, (data.col(i) - query).squaredNorm());
  return best;
}

void CheckAgainstBruteForce(const NearestGrid& grid, const PointSet& data, const PointSet& queries) {
  for (Eigen::Index q = 0; q < queries.cols(); ++q) {
    const Eigen::Vector3d query = queries.col(q);
    const double best = BruteForceSquared(data, query);
    const PointTree::Neighbor nb = grid.Nearest(query);
    REQUIRE(nb.index >= 0);
    REQUIRE(nb.index < data.cols());
    CHECK(nb.squared_distance == doctest::Approx(best).epsilon(1e-12).scale(1e-300));
    CHECK((data.col(nb.index) - query).squaredNorm() == doctest::Approx(best).epsilon(1e-12).scale(1e-300));
  }
}

}  // namespace

TEST_CASE("the grid finds the exact nearest point of surface, far and on-point queries") {
  c3po::Rng rng(11);
  const PointSet data = SurfacePoints(rng, 4000);
  const NearestGrid grid(std::make_shared<PointTree>(data));
  // The lists answer most of the cells near the surface, and are short.
  CHECK(grid.listed_cells() > 0);
  CHECK(grid.mean_list_length() > 1.0);
  CHECK(grid.mean_list_length() < 200.0);
  CheckAgainstBruteForce(grid, data, Queries(rng, data, 4000));
}

TEST_CASE("the grid is exact for every cell size and reach") {
  c3po::Rng rng(12);
  const PointSet data = SurfacePoints(rng, 1500);
  for (const double cell : {0.3, 1.0, 3.0}) {
    for (const double reach : {1.0, 2.5, 4.0}) {
      CAPTURE(cell);
      CAPTURE(reach);
      c3po::NearestGridOptions options;
      options.cell_over_spacing = cell;
      options.reach_cells = reach;
      CheckAgainstBruteForce(NearestGrid(std::make_shared<PointTree>(data), options), data, Queries(rng, data, 800));
    }
  }
  SUBCASE("a grid capped to few cells grows its cells and stays exact") {
    c3po::NearestGridOptions options;
    options.max_cells = 1000;
    const NearestGrid grid(std::make_shared<PointTree>(data), options);
    CHECK(grid.cell_count() <= 1000);
    CheckAgainstBruteForce(grid, data, Queries(rng, data, 800));
  }
}

TEST_CASE("the grid's batch equals its single queries, with and without hints") {
  c3po::Rng rng(13);
  const PointSet data = SurfacePoints(rng, 3000);
  const NearestGrid grid(std::make_shared<PointTree>(data));
  const PointSet queries = Queries(rng, data, 6000);   // > 4096: both cores
  Eigen::VectorXi indices, hinted_indices;
  Eigen::VectorXd squared, hinted_squared;
  grid.NearestBatch(queries, &indices, &squared);
  Eigen::VectorXi hints(queries.cols());
  for (Eigen::Index i = 0; i < hints.size(); ++i) hints(i) = rng.UniformInt(static_cast<int>(data.cols()));
  grid.NearestBatch(queries, &hinted_indices, &hinted_squared, &hints);
  for (Eigen::Index i = 0; i < queries.cols(); ++i) {
    const PointTree::Neighbor nb = grid.Nearest(queries.col(i));
    CHECK(indices(i) == nb.index);
    CHECK(squared(i) == nb.squared_distance);
    CHECK(hinted_squared(i) == doctest::Approx(nb.squared_distance).epsilon(1e-12).scale(1e-300));
  }
}

TEST_CASE("ties, duplicates and degenerate point sets") {
  c3po::Rng rng(14);
  SUBCASE("duplicated points: the lowest index among the equidistant") {
    PointSet data = SurfacePoints(rng, 600);
    for (int i = 1; i < data.cols(); i += 3) data.col(i) = data.col(i - 1);
    const NearestGrid grid(std::make_shared<PointTree>(data));
    CheckAgainstBruteForce(grid, data, Queries(rng, data, 600));
    const PointTree::Neighbor nb = grid.Nearest(data.col(3));
    CHECK(nb.squared_distance == 0.0);
    CHECK(nb.index == 3);
  }
  SUBCASE("one point, identical points, a line, a plane") {
    PointSet one(3, 1);
    one << 0.1, 0.2, 0.3;
    PointSet same(3, 50);
    same.colwise() = Eigen::Vector3d(1, 2, 3);
    PointSet line(3, 200), plane(3, 400);
    for (int i = 0; i < 200; ++i) line.col(i) = Eigen::Vector3d(0.001 * i, 0, 0);
    for (int i = 0; i < 400; ++i) plane.col(i) = Eigen::Vector3d(0.01 * (i % 20), 0.01 * (i / 20), 0.5);
    for (const PointSet* data : {&one, &same, &line, &plane}) {
      const NearestGrid grid(std::make_shared<PointTree>(*data));
      PointSet queries(3, 300);
      for (int i = 0; i < 300; ++i) {
        queries.col(i) = data->col(rng.UniformInt(static_cast<int>(data->cols()))) +
                         (i % 2 ? 0.005 : 0.5) * Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1));
      }
      CheckAgainstBruteForce(grid, *data, queries);
    }
  }
  SUBCASE("no points, non-finite queries") {
    const NearestGrid empty(std::make_shared<PointTree>(PointSet(3, 0)));
    CHECK(empty.Nearest(Eigen::Vector3d::Zero()).index == -1);
    CHECK(std::isinf(empty.Nearest(Eigen::Vector3d::Zero()).squared_distance));
    const PointSet data = SurfacePoints(rng, 300);
    const NearestGrid grid(std::make_shared<PointTree>(data));
    const double nan = std::numeric_limits<double>::quiet_NaN();
    CHECK(grid.Nearest(Eigen::Vector3d(nan, 0, 0)).index == -1);
    CHECK(grid.Nearest(Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0, 0)).index == -1);
  }
}
