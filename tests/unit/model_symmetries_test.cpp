// Rotational symmetries of the model surface (model_symmetries.hpp) against
// analytic symmetry groups: a cuboid with three different sides has exactly
// the three half-turns about its axes, a 64-sided cylinder its rotations
// about its axis, an asymmetric object none; the symmetric labellings equal
// the keypoints posed at T·S, computed directly from the pose.
#include <doctest/doctest.h>

#include <cmath>

#include "c3po/base/random.hpp"
#include "c3po/method/model_symmetries.hpp"
#include "c3po/object/procedural.hpp"
#include "test_objects.hpp"

namespace {

using namespace c3po;

// A cuboid 0.20 x 0.10 x 0.06 centred off the origin, keypoints at its corners.
ObjectModel Cuboid() {
  const Eigen::Vector3d centre(0.03, -0.02, 0.01);
  ObjectSpec spec;
  spec.name = "cuboid";
  spec.keypoints.resize(3, 8);
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d sign((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
    spec.keypoints.col(i) = centre + 0.5 * sign.cwiseProduct(Eigen::Vector3d(0.20, 0.10, 0.06));
  }
  spec.eps_oc = 0.006;
  spec.delta_nd = 0.004;
  return ObjectModel(spec, test::BoxMesh(centre, {0.20, 0.10, 0.06}));
}

ObjectModel Cylinder() {
  ObjectSpec spec;
  spec.name = "can";
  spec.keypoints.resize(3, 4);
  spec.keypoints << 0.04, -0.04, 0.0, 0.0,  //
      0.0, 0.0, 0.04, 0.0,                  //
      0.0, 0.0, 0.12, 0.12;
  spec.eps_oc = 0.004;
  spec.delta_nd = 0.003;
  ObjectModelOptions options;
  options.sample_size = 8000;
  return ObjectModel(spec, MakeCylinder({0, 0, 0}, {0, 0, 0.12}, 0.04, 64), options);
}

SymmetrySearchOptions Tolerance(double tolerance) {
  SymmetrySearchOptions options;
  options.tolerance = tolerance;
  return options;
}

}  // namespace

TEST_CASE("a cuboid with three different sides has exactly the half-turns about its axes") {
  const ObjectModel cuboid = Cuboid();
  const std::vector<ModelSymmetry> symmetries = FindModelSymmetries(cuboid, Tolerance(0.002));
  REQUIRE(symmetries.size() == 3);
  int axes_seen = 0;
  for (const ModelSymmetry& s : symmetries) {
    CHECK(s.angle == doctest::Approx(M_PI).epsilon(1e-3));
    CHECK(s.hausdorff <= 0.002);
    // About a coordinate axis through the cuboid's centre (which it fixes).
    int axis = -1;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(s.axis(k)) > 0.999) axis = k;
    }
    REQUIRE(axis >= 0);
    axes_seen |= 1 << axis;
    const Eigen::Vector3d centre(0.03, -0.02, 0.01);
    CHECK((s.model_from_model * centre - centre).norm() < 1e-4);
    // The corners map onto corners (exact analytic group).
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d moved = s.model_from_model * Eigen::Vector3d(cuboid.keypoints().col(i));
      double nearest = 1e9;
      for (int j = 0; j < 8; ++j) nearest = std::min(nearest, (moved - cuboid.keypoints().col(j)).norm());
      CHECK(nearest < 1e-4);
    }
  }
  CHECK(axes_seen == 7);
  // A quarter turn about the long axis moves the 0.10 x 0.06 section: > 2 cm.
  CHECK(FindModelSymmetries(cuboid, Tolerance(0.015)).size() == 3);
}

ObjectModel Prism(const Eigen::Vector3d& size) {
  ObjectSpec spec;
  spec.name = "prism";
  spec.keypoints = test::BoxMesh({0, 0, 0}, size).vertices;
  spec.eps_oc = 0.006;
  spec.delta_nd = 0.004;
  return ObjectModel(spec, test::BoxMesh({0, 0, 0}, size));
}

TEST_CASE("equal extents: a cube's 23 rotations and a square prism's 7 are found (from the face normals)") {
  // Analytic: the rotation group of the cube has order 24; of a square
  // prism 8 (4 about its axis, 4 half-turns about axes across it).
  const std::vector<ModelSymmetry> cube = FindModelSymmetries(Prism({0.1, 0.1, 0.1}), Tolerance(0.002));
  CHECK(cube.size() == 23);
  const std::vector<ModelSymmetry> prism = FindModelSymmetries(Prism({0.1, 0.1, 0.2}), Tolerance(0.002));
  CHECK(prism.size() == 7);
  int about_long_axis = 0;
  for (const ModelSymmetry& s : prism) {
    CHECK(s.hausdorff <= 0.002);
    if (std::abs(s.axis.z()) > 0.999) {
      ++about_long_axis;
    } else {
      CHECK(s.angle == doctest::Approx(M_PI).epsilon(1e-3));
    }
  }
  CHECK(about_long_axis == 3);
}

TEST_CASE("a 64-sided cylinder: its rotations about the axis are symmetries") {
  const ObjectModel can = Cylinder();
  const std::vector<ModelSymmetry> symmetries = FindModelSymmetries(can, Tolerance(0.002));
  // Every angle 2πk/n, n <= 8, about z: 21 distinct rotations in (0, 2π).
  int about_axis = 0;
  bool quarter = false;
  for (const ModelSymmetry& s : symmetries) {
    CHECK(s.hausdorff <= 0.002);
    if (std::abs(s.axis.z()) > 0.999) {
      ++about_axis;
      quarter = quarter || std::abs(s.angle - M_PI / 2) < 1e-3;
    } else {
      // Otherwise a half-turn about an axis perpendicular to z through the middle.
      CHECK(s.angle == doctest::Approx(M_PI).epsilon(1e-3));
      CHECK(std::abs(s.axis.z()) < 1e-2);
    }
  }
  CHECK(about_axis == 21);
  CHECK(quarter);
}

TEST_CASE("an asymmetric object has no symmetry, an absurd tolerance admits the candidates") {
  const ObjectModel object = test::AsymmetricObject();
  CHECK(FindModelSymmetries(object, Tolerance(0.005)).empty());
  CHECK(FindModelSymmetries(object, Tolerance(10.0)).size() > 20);
  SymmetrySearchOptions bad = Tolerance(-1.0);
  CHECK_THROWS_AS(FindModelSymmetries(object, bad), std::invalid_argument);
  bad = Tolerance(std::nan(""));
  CHECK_THROWS_AS(FindModelSymmetries(object, bad), std::invalid_argument);
}

TEST_CASE("symmetric labellings are the keypoints posed at T·S") {
  const ObjectModel cuboid = Cuboid();
  const std::vector<ModelSymmetry> symmetries = FindModelSymmetries(cuboid, Tolerance(0.002));
  REQUIRE(symmetries.size() == 3);
  Rng rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    Pose truth;
    truth.R = rng.Rotation();
    truth.t = Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(1, 2));
    const PointSet posed = truth * cuboid.keypoints();
    const std::vector<PointSet> labellings = SymmetricLabellings(cuboid, symmetries, posed);
    REQUIRE(labellings.size() == 3);
    for (std::size_t j = 0; j < 3; ++j) {
      const PointSet direct = (truth * symmetries[j].model_from_model) * cuboid.keypoints();
      CHECK((labellings[j] - direct).cwiseAbs().maxCoeff() < 1e-9);
      // A relabelling of the same corners: the same point set, other order.
      CHECK((labellings[j] - posed).colwise().norm().maxCoeff() > 0.05);
    }
  }
  // Not a rigid copy of the keypoints, or no symmetry: no other labelling.
  PointSet stretched = cuboid.keypoints();
  stretched.row(0) *= 1.5;
  CHECK(SymmetricLabellings(cuboid, symmetries, stretched).empty());
  CHECK(SymmetricLabellings(cuboid, {}, cuboid.keypoints()).empty());
  CHECK(SymmetricLabellings(cuboid, symmetries, PointSet(3, 2)).empty());
}
