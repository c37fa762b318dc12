// PointTree queries against brute-force linear scans.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

#include "c3po/base/random.hpp"
#include "c3po/geometry/kdtree.hpp"

namespace {

using c3po::PointSet;
using c3po::PointTree;

PointSet RandomPoints(c3po::Rng& rng, int n) {
  PointSet points(3, n);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) points(k, i) = rng.Uniform(-1, 1);
  }
  return points;
}

// Random points where about a third are exact copies of earlier ones.
PointSet PointsWithDuplicates(c3po::Rng& rng, int n) {
  PointSet points = RandomPoints(rng, n);
  for (int i = 1; i < n; ++i) {
    if (rng.UniformInt(3) == 0) points.col(i) = points.col(rng.UniformInt(i));
  }
  return points;
}

std::vector<double> SortedSquaredDistances(const PointSet& points, const Eigen::Vector3d& q) {
  std::vector<double> d(points.cols());
  for (Eigen::Index i = 0; i < points.cols(); ++i) d[i] = (points.col(i) - q).squaredNorm();
  std::sort(d.begin(), d.end());
  return d;
}

// Queries: random points, exact data points, and points far outside.
PointSet Queries(c3po::Rng& rng, const PointSet& data, int n) {
  PointSet queries = RandomPoints(rng, n);
  for (int i = 0; i < n; ++i) {
    if (i % 3 == 1 && data.cols() > 0) queries.col(i) = data.col(rng.UniformInt(static_cast<int>(data.cols())));
    if (i % 7 == 2) queries.col(i) *= 50.0;
  }
  return queries;
}

void CheckNearest(const PointTree& tree, const PointSet& data, const PointSet& queries) {
  for (Eigen::Index q = 0; q < queries.cols(); ++q) {
    const Eigen::Vector3d query = queries.col(q);
    const double best = SortedSquaredDistances(data, query).front();
    const auto nb = tree.Nearest(query);
    REQUIRE(nb.index >= 0);
    REQUIRE(nb.index < data.cols());
    CHECK(nb.squared_distance == doctest::Approx(best).epsilon(1e-12).scale(1));
    CHECK((data.col(nb.index) - query).squaredNorm() == doctest::Approx(best).epsilon(1e-12).scale(1));
  }
}

}  // namespace

TEST_CASE("Nearest matches brute force (sizes 1..2000, with duplicates)") {
  c3po::Rng rng(11);
  for (int n : {1, 2, 3, 10, 11, 64, 500, 2000}) {
    CAPTURE(n);
    const PointSet data = PointsWithDuplicates(rng, n);
    const PointTree tree(data);
    CHECK(tree.size() == n);
    CHECK(tree.points() == data);
    CheckNearest(tree, data, Queries(rng, data, 200));
  }
}

TEST_CASE("all points identical") {
  const PointSet data = Eigen::Vector3d(0.5, 0.5, 0.5).replicate(1, 40);
  const PointTree tree(data);
  const auto nb = tree.Nearest(Eigen::Vector3d(1, 1, 1));
  CHECK(nb.index >= 0);
  CHECK(nb.index < 40);
  CHECK(nb.squared_distance == doctest::Approx(0.75));
  const auto k = tree.KNearest(Eigen::Vector3d(0, 0, 0), 5);
  REQUIRE(k.size() == 5);
  std::set<Eigen::Index> distinct;
  for (const auto& n : k) {
    CHECK(n.squared_distance == doctest::Approx(0.75));
    distinct.insert(n.index);
  }
  CHECK(distinct.size() == 5);
}

TEST_CASE("KNearest matches the k smallest brute-force distances, sorted") {
  c3po::Rng rng(12);
  for (int n : {1, 5, 50, 700}) {
    const PointSet data = PointsWithDuplicates(rng, n);
    const PointTree tree(data);
    const PointSet queries = Queries(rng, data, 40);
    for (int k : {1, 2, 5, n, n + 3}) {
      CAPTURE(n);
      CAPTURE(k);
      for (Eigen::Index q = 0; q < queries.cols(); ++q) {
        const auto brute = SortedSquaredDistances(data, queries.col(q));
        const auto found = tree.KNearest(queries.col(q), k);
        REQUIRE(found.size() == static_cast<std::size_t>(std::min(k, n)));
        std::set<Eigen::Index> indices;
        for (std::size_t i = 0; i < found.size(); ++i) {
          CHECK(found[i].squared_distance == doctest::Approx(brute[i]).epsilon(1e-12).scale(1));
          CHECK((data.col(found[i].index) - queries.col(q)).squaredNorm() ==
                doctest::Approx(found[i].squared_distance).epsilon(1e-12).scale(1));
          if (i > 0) CHECK(found[i].squared_distance >= found[i - 1].squared_distance);
          indices.insert(found[i].index);
        }
        CHECK(indices.size() == found.size());  // no index reported twice
      }
    }
  }
  const PointTree tree(RandomPoints(rng, 10));
  CHECK(tree.KNearest(Eigen::Vector3d::Zero(), 0).empty());
  CHECK(tree.KNearest(Eigen::Vector3d::Zero(), -4).empty());
}

TEST_CASE("NearestBatch equals Nearest, inline and parallel paths") {
  c3po::Rng rng(13);
  const PointSet data = PointsWithDuplicates(rng, 3000);
  const PointTree tree(data);
  for (int count : {0, 1, 300, 9000}) {  // 9000 > the inline threshold: uses both cores
    CAPTURE(count);
    const PointSet queries = Queries(rng, data, count);
    Eigen::VectorXi indices;
    Eigen::VectorXd squared;
    tree.NearestBatch(queries, &indices, &squared);
    REQUIRE(indices.size() == count);
    REQUIRE(squared.size() == count);
    for (int i = 0; i < count; ++i) {
      const auto nb = tree.Nearest(queries.col(i));
      CHECK(squared(i) == nb.squared_distance);
      CHECK((data.col(indices(i)) - queries.col(i)).squaredNorm() ==
            doctest::Approx(nb.squared_distance).epsilon(1e-12).scale(1));
    }
    // Either output may be omitted.
    Eigen::VectorXd only_distances;
    tree.NearestBatch(queries, nullptr, &only_distances);
    CHECK(only_distances == squared);
    Eigen::VectorXi only_indices;
    tree.NearestBatch(queries, &only_indices, nullptr);
    CHECK(only_indices == indices);
  }
}

TEST_CASE("empty tree: index -1 and infinite distance") {
  const PointTree tree{PointSet(3, 0)};
  CHECK(tree.size() == 0);
  const auto nb = tree.Nearest(Eigen::Vector3d(1, 2, 3));
  CHECK(nb.index == -1);
  CHECK(std::isinf(nb.squared_distance));
  CHECK(tree.KNearest(Eigen::Vector3d::Zero(), 3).empty());
  Eigen::VectorXi indices;
  Eigen::VectorXd squared;
  tree.NearestBatch(PointSet::Zero(3, 5), &indices, &squared);
  REQUIRE(indices.size() == 5);
  CHECK((indices.array() == -1).all());
  CHECK(squared.array().isInf().all());
}

TEST_CASE("a moved tree keeps answering correctly") {
  c3po::Rng rng(14);
  const PointSet data = RandomPoints(rng, 400);
  const PointSet queries = Queries(rng, data, 100);
  PointTree original(data);
  PointTree moved(std::move(original));
  CheckNearest(moved, data, queries);

  PointTree assigned(RandomPoints(rng, 3));
  assigned = std::move(moved);
  CheckNearest(assigned, data, queries);

  // Reallocation of a vector moves every tree.
  std::vector<PointTree> trees;
  std::vector<PointSet> datas;
  for (int i = 0; i < 20; ++i) {
    datas.push_back(RandomPoints(rng, 50 + i));
    trees.emplace_back(datas.back());
  }
  for (int i = 0; i < 20; ++i) CheckNearest(trees[i], datas[i], Queries(rng, datas[i], 10));
}

TEST_CASE("non-finite queries find no neighbour, like an empty tree") {
  c3po::Rng rng(15);
  const PointTree tree(RandomPoints(rng, 100));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& query : {Eigen::Vector3d(nan, 0, 0), Eigen::Vector3d(0, inf, 0),
                                       Eigen::Vector3d(0, 0, -inf)}) {
    const auto nb = tree.Nearest(query);
    CHECK(nb.index == -1);
    CHECK(std::isinf(nb.squared_distance));
    CHECK(tree.KNearest(query, 3).empty());
  }
  PointSet queries = RandomPoints(rng, 5);
  queries(1, 2) = nan;
  Eigen::VectorXi indices;
  Eigen::VectorXd squared;
  tree.NearestBatch(queries, &indices, &squared);
  CHECK(indices(2) == -1);
  CHECK(std::isinf(squared(2)));
  CHECK(indices(1) >= 0);
  CHECK(std::isfinite(squared(1)));
}

TEST_CASE("Nearest with a hint is exactly Nearest: any hint, duplicates, far queries, non-finite queries") {
  c3po::Rng rng(16);
  for (int n : {1, 2, 11, 500, 3000}) {
    CAPTURE(n);
    const PointSet data = PointsWithDuplicates(rng, n);
    const PointTree tree(data);
    const PointSet queries = Queries(rng, data, 300);
    for (Eigen::Index q = 0; q < queries.cols(); ++q) {
      const Eigen::Vector3d query = queries.col(q);
      const auto plain = tree.Nearest(query);
      // Oracle: brute force; the hinted answer is the same point (ties included) and distance.
      const double best = SortedSquaredDistances(data, query).front();
      CHECK(plain.squared_distance == doctest::Approx(best).epsilon(1e-12).scale(1));
      const Eigen::Index good = plain.index;                                  // the exact answer
      const Eigen::Index random = rng.UniformInt(n);                          // an arbitrary point
      const Eigen::Index bad_hints[] = {-1, n, std::numeric_limits<Eigen::Index>::max()};  // no hint
      for (const Eigen::Index hint : {good, random, bad_hints[0], bad_hints[1], bad_hints[2]}) {
        CAPTURE(hint);
        const auto hinted = tree.Nearest(query, hint);
        CHECK(hinted.index == plain.index);
        CHECK(hinted.squared_distance == plain.squared_distance);
      }
    }
    // The batch with hints (a permutation of the answers: mostly wrong hints) equals the plain batch.
    Eigen::VectorXi plain_indices, hinted_indices, hints(queries.cols());
    Eigen::VectorXd plain_squared, hinted_squared;
    tree.NearestBatch(queries, &plain_indices, &plain_squared);
    for (Eigen::Index q = 0; q < queries.cols(); ++q) hints(q) = plain_indices((q * 7 + 3) % queries.cols());
    tree.NearestBatch(queries, &hinted_indices, &hinted_squared, &hints);
    CHECK(hinted_indices == plain_indices);
    CHECK(hinted_squared == plain_squared);
    // Hints of the wrong length are ignored.
    const Eigen::VectorXi short_hints = hints.head(queries.cols() / 2);
    tree.NearestBatch(queries, &hinted_indices, &hinted_squared, &short_hints);
    CHECK(hinted_indices == plain_indices);
  }
  const PointTree tree(RandomPoints(rng, 100));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto none = tree.Nearest(Eigen::Vector3d(nan, 0, 0), 5);
  CHECK(none.index == -1);
  CHECK(std::isinf(none.squared_distance));
  const PointTree empty{PointSet(3, 0)};
  CHECK(empty.Nearest(Eigen::Vector3d::Zero(), 0).index == -1);
}
