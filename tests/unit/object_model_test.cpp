// ObjectModel: sample density (a probabilistic bound derived from the sample
// size and the area), diameter, posed nearest-neighbour queries against brute
// force, keypoint hash.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

#include "c3po/base/random.hpp"
#include "c3po/object/object_model.hpp"

namespace {

using c3po::Mesh;
using c3po::ObjectModel;
using c3po::ObjectSpec;
using c3po::PointSet;

// Box [lo, lo + size]: corner i = lo + (bit0 sx, bit1 sy, bit2 sz), 12 triangles.
Mesh BoxMesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& size) {
  const int quads[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  Mesh mesh;
  mesh.vertices.resize(3, 8);
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.col(i) = lo + Eigen::Vector3d((i & 1) * size.x(), ((i >> 1) & 1) * size.y(), ((i >> 2) & 1) * size.z());
  }
  mesh.triangles.resize(3, 12);
  for (int q = 0; q < 6; ++q) {
    mesh.triangles.col(2 * q) = Eigen::Vector3i(quads[q][0], quads[q][1], quads[q][2]);
    mesh.triangles.col(2 * q + 1) = Eigen::Vector3i(quads[q][0], quads[q][2], quads[q][3]);
  }
  return mesh;
}

ObjectSpec CubeSpec() {
  ObjectSpec spec;
  spec.name = "cube";
  spec.mesh_path = "/nowhere/cube.obj";
  spec.keypoints = PointSet(3, 3);
  spec.keypoints << 0, 1, 1,  //
                    0, 0, 1,  //
                    0, 0, 1;
  spec.indicator_sets = {{0, 1}};
  spec.eps_oc = 0.05;
  spec.delta_nd = 0.02;
  return spec;
}

PointSet BrutePosed(const PointSet& sample, const c3po::Pose& pose) { return pose * sample; }

}  // namespace

TEST_CASE("every point of the unit cube surface lies near the dense sample") {
  // For a surface point whose geodesic r-neighbourhood has area >= A_r, the
  // chance that none of n uniform samples lands within r is (1 - A_r / A)^n <=
  // exp(-n A_r / A). The smallest neighbourhood on a cube is at a corner:
  // three quarter discs, A_r = 3 pi r^2 / 4. Requiring exp(-n A_r / A) <= 1e-9
  // gives r = sqrt(4 A ln(1e9) / (3 pi n)). A seeded sample that misses this
  // bound is, with probability 1 - 1e-9 per point, a sampler that is not uniform.
  constexpr int kSamples = 10000;
  const double area = 6.0;
  const double radius = std::sqrt(4.0 * area * std::log(1e9) / (3.0 * M_PI * kSamples));
  const ObjectModel model(CubeSpec(), BoxMesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()),
                          {kSamples, 5});
  REQUIRE(model.sample().cols() == kSamples);
  // Mesh vertices (the corners) ...
  for (int i = 0; i < 8; ++i) {
    CAPTURE(i);
    CHECK(std::sqrt(model.tree().Nearest(model.mesh().vertices.col(i)).squared_distance) < radius);
  }
  // ... and a grid over every face (edges and face interiors have larger
  // neighbourhoods, so the same radius applies).
  for (int axis = 0; axis < 3; ++axis) {
    for (double side : {0.0, 1.0}) {
      for (int i = 0; i <= 10; ++i) {
        for (int j = 0; j <= 10; ++j) {
          Eigen::Vector3d p;
          p(axis) = side;
          p((axis + 1) % 3) = i / 10.0;
          p((axis + 2) % 3) = j / 10.0;
          CHECK(std::sqrt(model.tree().Nearest(p).squared_distance) < radius);
        }
      }
    }
  }
  // Every sample point is on the surface: one coordinate is 0 or 1, all in [0, 1].
  const PointSet& s = model.sample();
  for (Eigen::Index i = 0; i < s.cols(); ++i) {
    const Eigen::Vector3d p = s.col(i);
    CHECK(p.minCoeff() >= -1e-12);
    CHECK(p.maxCoeff() <= 1 + 1e-12);
    CHECK(std::min(p.cwiseAbs().minCoeff(), (p.array() - 1).abs().minCoeff()) < 1e-12);
  }
}

TEST_CASE("diameter is the bounding-box diagonal") {
  c3po::Rng rng(51);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Vector3d lo(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1));
    const Eigen::Vector3d size(rng.Uniform(0.1, 2), rng.Uniform(0.1, 2), rng.Uniform(0.1, 2));
    const ObjectModel model(CubeSpec(), BoxMesh(lo, size), {200, 1});
    CHECK(model.diameter() == doctest::Approx(size.norm()).epsilon(1e-12));
    CHECK(model.diameter() == doctest::Approx(model.mesh().Diameter()).epsilon(1e-12));
  }
}

TEST_CASE("NearestInPosedModel equals brute force over the explicitly posed sample") {
  c3po::Rng rng(52);
  const ObjectModel model(CubeSpec(), BoxMesh(Eigen::Vector3d(-0.5, -0.2, 0), Eigen::Vector3d(1, 0.4, 0.7)),
                          {1500, 3});
  for (int trial = 0; trial < 5; ++trial) {
    c3po::Pose pose;
    pose.R = rng.Rotation();
    pose.t = Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(0, 2));
    const PointSet posed = BrutePosed(model.sample(), pose);
    PointSet scene(3, 300);
    for (int i = 0; i < 300; ++i) {
      scene.col(i) = posed.col(rng.UniformInt(static_cast<int>(posed.cols()))) + 0.1 * rng.UnitVector() * rng.Uniform();
    }
    Eigen::VectorXi indices;
    Eigen::VectorXd squared;
    model.NearestInPosedModel(scene, pose, &indices, &squared);
    CHECK(model.grid().listed_cells() > 0);   // the grid answered (nearest_grid_test checks it against brute force)
    const Eigen::VectorXd distances = model.DistancesToPosedModel(scene, pose);
    REQUIRE(indices.size() == 300);
    for (int i = 0; i < 300; ++i) {
      double best = std::numeric_limits<double>::infinity();
      for (Eigen::Index j = 0; j < posed.cols(); ++j) best = std::min(best, (scene.col(i) - posed.col(j)).squaredNorm());
      CHECK(squared(i) == doctest::Approx(best).epsilon(1e-9).scale(1e-12));
      CHECK((scene.col(i) - posed.col(indices(i))).squaredNorm() == doctest::Approx(best).epsilon(1e-9).scale(1e-12));
      CHECK(distances(i) == doctest::Approx(std::sqrt(best)).epsilon(1e-9).scale(1e-12));
    }
  }
}

TEST_CASE("SampleSpacing is the mean nearest-other-point distance") {
  const ObjectModel model(CubeSpec(), BoxMesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()), {400, 9});
  const PointSet& s = model.sample();
  double total = 0.0;
  for (Eigen::Index i = 0; i < s.cols(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (Eigen::Index j = 0; j < s.cols(); ++j) {
      if (j != i) best = std::min(best, (s.col(i) - s.col(j)).norm());
    }
    total += best;
  }
  CHECK(model.SampleSpacing() == doctest::Approx(total / s.cols()).epsilon(1e-12));
}

TEST_CASE("the sample is deterministic per seed") {
  const Mesh cube = BoxMesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  const ObjectModel a(CubeSpec(), cube, {500, 17}), b(CubeSpec(), cube, {500, 17}), c(CubeSpec(), cube, {500, 18});
  CHECK(a.sample() == b.sample());
  CHECK(a.sample() != c.sample());
}

TEST_CASE("KeypointHash is stable and follows keypoints and name") {
  const Mesh cube = BoxMesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  const ObjectModel base(CubeSpec(), cube, {200, 1});
  const std::string hash = base.KeypointHash();
  CHECK(hash.size() == 16);
  CHECK(hash.find_first_not_of("0123456789abcdef") == std::string::npos);
  CHECK(ObjectModel(CubeSpec(), cube, {300, 2}).KeypointHash() == hash);  // not the sample
  ObjectSpec other_sets = CubeSpec();
  other_sets.indicator_sets.clear();
  other_sets.eps_oc = 1.0;
  CHECK(ObjectModel(other_sets, cube, {200, 1}).KeypointHash() == hash);

  std::set<std::string> seen{hash};
  for (int k = 0; k < 3; ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      ObjectSpec moved = CubeSpec();
      moved.keypoints(axis, k) += 1e-6;
      seen.insert(ObjectModel(moved, cube, {200, 1}).KeypointHash());
    }
  }
  CHECK(seen.size() == 10);  // each of the 9 single-coordinate moves gives a new hash
  ObjectSpec renamed = CubeSpec();
  renamed.name = "cube2";
  CHECK(ObjectModel(renamed, cube, {200, 1}).KeypointHash() != hash);
  ObjectSpec swapped = CubeSpec();
  swapped.keypoints.col(1).swap(swapped.keypoints.col(2));
  CHECK(ObjectModel(swapped, cube, {200, 1}).KeypointHash() != hash);
}

TEST_CASE("bad meshes and options are rejected") {
  Mesh cube = BoxMesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  CHECK_THROWS_AS(ObjectModel(CubeSpec(), cube, {99, 1}), std::invalid_argument);
  CHECK_THROWS_AS(c3po::ObjectModelOptions({0, 1}).Check(), std::invalid_argument);
  CHECK_NOTHROW(c3po::ObjectModelOptions().Check());
  CHECK_THROWS_AS(ObjectModel(CubeSpec(), Mesh()), std::invalid_argument);
  cube.vertices(0, 3) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(ObjectModel(CubeSpec(), cube), std::invalid_argument);
}
