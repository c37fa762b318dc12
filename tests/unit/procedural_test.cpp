// Procedural meshes and the bundled objects (annotations/).
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "c3po/base/random.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/object/procedural.hpp"
#include "test_helpers.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// Triangles [begin, end) of a mesh as a mesh of their own.
c3po::Mesh Part(const c3po::Mesh& mesh, int begin, int end) {
  c3po::Mesh part;
  part.vertices = mesh.vertices;
  part.triangles = mesh.triangles.middleCols(begin, end - begin);
  return part;
}

}  // namespace

TEST_CASE("primitives are closed, outward and have the right volume") {
  const c3po::Mesh cuboid = c3po::MakeCuboid({-0.1, 0.0, 0.2}, {0.3, 0.05, 0.27}, 0.02);
  CHECK(c3po::CheckClosed(cuboid).closed());
  CHECK(c3po::SignedVolume(cuboid) == doctest::Approx(0.4 * 0.05 * 0.07).epsilon(1e-12));
  CHECK(cuboid.SurfaceArea() ==
        doctest::Approx(2 * (0.4 * 0.05 + 0.4 * 0.07 + 0.05 * 0.07)).epsilon(1e-12));

  // A cylinder with n sides is a prism over a regular n-gon.
  const int n = 24;
  const c3po::Mesh cylinder = c3po::MakeCylinder({0.1, 0.2, 0.3}, {0.4, -0.1, 0.5}, 0.05, n);
  const double length = std::sqrt(0.09 + 0.09 + 0.04);
  CHECK(c3po::CheckClosed(cylinder).closed());
  CHECK(c3po::SignedVolume(cylinder) ==
        doctest::Approx(0.5 * n * 0.05 * 0.05 * std::sin(2 * kPi / n) * length).epsilon(1e-9));

  // A cone: revolution with an apex; volume of the n-gon pyramid.
  const c3po::Mesh cone = c3po::MakeRevolution({{0, 0}, {0.1, 0}, {0, 0.3}}, n);
  CHECK(c3po::CheckClosed(cone).closed());
  CHECK(c3po::SignedVolume(cone) ==
        doctest::Approx(0.5 * n * 0.01 * std::sin(2 * kPi / n) * 0.3 / 3).epsilon(1e-9));

  // A half torus tube: volume close to (pi r^2)(pi R) (Pappus), from below.
  const c3po::Mesh tube = c3po::MakeArcTube({0, 0, 0}, 0.1, 0.0, kPi, 0.01, 64, 32);
  CHECK(c3po::CheckClosed(tube).closed());
  const double pappus = kPi * 0.01 * 0.01 * kPi * 0.1;
  CHECK(c3po::SignedVolume(tube) < pappus);
  CHECK(c3po::SignedVolume(tube) > 0.99 * pappus);
}

TEST_CASE("CheckClosed finds holes, flipped and degenerate triangles") {
  const c3po::Mesh cuboid = c3po::MakeCuboid({0, 0, 0}, {1, 1, 1}, 1.0);
  c3po::Mesh open = cuboid;
  open.triangles = cuboid.triangles.leftCols(cuboid.triangles.cols() - 1);
  CHECK(c3po::CheckClosed(open).boundary_edges == 3);
  CHECK_FALSE(c3po::CheckClosed(open).closed());

  c3po::Mesh flipped = cuboid;
  std::swap(flipped.triangles(1, 0), flipped.triangles(2, 0));
  CHECK(c3po::CheckClosed(flipped).inconsistent_edges == 3);

  c3po::Mesh degenerate = cuboid;
  degenerate.triangles(1, 0) = degenerate.triangles(0, 0);
  CHECK(c3po::CheckClosed(degenerate).degenerate_triangles == 1);

  c3po::Mesh inward = cuboid;
  c3po::FlipTriangles(&inward);
  CHECK(c3po::CheckClosed(inward).closed());
  CHECK(c3po::SignedVolume(inward) == doctest::Approx(-1.0));
}

TEST_CASE("MakeRevolution rejects profiles off the axis") {
  CHECK_THROWS_AS(c3po::MakeRevolution({{0.1, 0}, {0.1, 1}, {0, 1}}, 8), std::invalid_argument);
  CHECK_THROWS_AS(c3po::MakeRevolution({{0, 0}, {0, 0.5}, {0, 1}}, 8), std::invalid_argument);
  CHECK_THROWS_AS(c3po::MakeCuboid({0, 0, 0}, {0, 1, 1}, 0.1), std::invalid_argument);
}

TEST_CASE("bundled objects: closed parts, keypoints on the surface, valid specs") {
  for (const std::string& name : c3po::BundledObjectNames()) {
    CAPTURE(name);
    const c3po::BundledObject object = c3po::MakeBundledObject(name);
    const c3po::Mesh& mesh = object.mesh;
    const double d = mesh.Diameter();
    MESSAGE(name << ": " << mesh.triangles.cols() << " triangles, d = " << d << " m, eps_oc = "
                 << object.spec.eps_oc << ", delta_nd = " << object.spec.delta_nd);
    CHECK(mesh.triangles.cols() >= 1000);
    CHECK(mesh.triangles.cols() <= 6000);
    CHECK_NOTHROW(mesh.Validate());
    CHECK_NOTHROW(object.spec.Validate(name));
    // Every part is a closed outward 2-manifold.
    for (std::size_t k = 0; k < object.part_begin.size(); ++k) {
      const int end = k + 1 < object.part_begin.size() ? object.part_begin[k + 1]
                                                       : static_cast<int>(mesh.triangles.cols());
      const c3po::Mesh part = Part(mesh, object.part_begin[k], end);
      CHECK(c3po::CheckClosed(part).closed());
      CHECK(c3po::SignedVolume(part) > 0.0);
    }
    // Coordinates survive a float round trip (32-bit mesh loaders).
    CHECK(mesh.vertices == mesh.vertices.cast<float>().cast<double>());
    // Keypoints: 8-16, named uniquely, exactly on the surface.
    const int n = object.spec.num_keypoints();
    CHECK(n >= 8);
    CHECK(n <= 16);
    REQUIRE(object.spec.keypoint_names.size() == static_cast<std::size_t>(n));
    CHECK(std::set<std::string>(object.spec.keypoint_names.begin(),
                                object.spec.keypoint_names.end())
              .size() == static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      CAPTURE(object.spec.KeypointName(i));
      CHECK(c3po::ClosestSurfacePoint(mesh, object.spec.keypoints.col(i)).distance < 1e-9 * d);
    }
    CHECK_FALSE(object.spec.indicator_sets.empty());
    CHECK(object.spec.eps_oc >= 0.03 * d);
    CHECK(object.spec.eps_oc <= 0.05 * d);
    CHECK(object.spec.delta_nd >= 0.015 * d);
    CHECK(object.spec.delta_nd <= 0.035 * d);
  }
}

TEST_CASE("box indicator sets are a corner with its three edge neighbours") {
  const c3po::BundledObject box = c3po::MakeBundledObject("box");
  REQUIRE(box.spec.indicator_sets.size() == 8);
  std::set<int> first_corners;
  for (const auto& set : box.spec.indicator_sets) {
    REQUIRE(set.size() == 4);
    first_corners.insert(set[0]);
    const Eigen::Vector3d corner = box.spec.keypoints.col(set[0]);
    std::set<int> axes;
    for (int j = 1; j < 4; ++j) {
      const Eigen::Vector3d diff = box.spec.keypoints.col(set[static_cast<std::size_t>(j)]) - corner;
      int changed = 0, axis = -1;
      for (int a = 0; a < 3; ++a) {
        if (std::abs(diff[a]) > 1e-6) {
          ++changed;
          axis = a;
        }
      }
      CHECK(changed == 1);   // an edge neighbour differs along one axis only
      axes.insert(axis);
    }
    CHECK(axes.size() == 3);
  }
  CHECK(first_corners.size() == 8);
}

TEST_CASE("mug indicator keypoints are on the handle, off the symmetric body") {
  const c3po::BundledObject mug = c3po::MakeBundledObject("mug");
  // The body is a surface of revolution about z; its radius is the largest
  // distance from the z axis among the rim keypoints.
  double body_radius = 0.0;
  for (int i = 0; i < mug.spec.num_keypoints(); ++i) {
    if (mug.spec.KeypointName(i).rfind("rim_", 0) == 0) {
      body_radius = std::max(body_radius, mug.spec.keypoints.col(i).head<2>().norm());
    }
  }
  REQUIRE(body_radius > 0.0);
  for (const auto& set : mug.spec.indicator_sets) {
    for (int i : set) CHECK(mug.spec.keypoints.col(i).head<2>().norm() > body_radius + 0.01);
  }
}

TEST_CASE("every keypoint of every bundled object is seen from some viewpoint") {
  for (const std::string& name : c3po::BundledObjectNames()) {
    CAPTURE(name);
    const c3po::BundledObject object = c3po::MakeBundledObject(name);
    const double d = object.mesh.Diameter();
    const Eigen::Vector3d centre = object.mesh.BoundingBox().center();
    c3po::DepthRenderer renderer(c3po::CameraIntrinsics{});
    c3po::Rng rng(7);
    std::vector<bool> ever_seen(static_cast<std::size_t>(object.spec.num_keypoints()), false);
    for (int view = 0; view < 150; ++view) {
      c3po::Pose pose;
      pose.R = rng.Rotation();
      pose.t = Eigen::Vector3d(0, 0, 3 * d) - pose.R * centre;
      renderer.Render(object.mesh, pose);
      const auto visible = renderer.KeypointsVisible(pose * object.spec.keypoints, 0.002 * d);
      for (std::size_t i = 0; i < visible.size(); ++i) ever_seen[i] = ever_seen[i] || visible[i];
    }
    for (std::size_t i = 0; i < ever_seen.size(); ++i) {
      CAPTURE(object.spec.KeypointName(static_cast<int>(i)));
      CHECK(ever_seen[i]);
    }
  }
}

TEST_CASE("committed annotations/ files are the generator's output, and load back") {
  const std::string committed = c3po::test::SourceDir() + "/annotations";
  c3po::test::TempDir dir("procedural_regenerate");
  for (const std::string& name : c3po::BundledObjectNames()) {
    CAPTURE(name);
    const c3po::BundledObject object = c3po::MakeBundledObject(name);
    c3po::WriteBundledObject(object, dir.path());
    for (const char* extension : {".obj", ".json"}) {
      const std::string fresh = ReadBytes(dir / (name + extension));
      CHECK(!fresh.empty());
      CHECK(fresh == ReadBytes(committed + "/" + name + extension));   // regenerate if this fails
    }
    // The committed object loads to the same mesh and keypoints.
    const c3po::ObjectModel loaded = c3po::LoadObject(committed + "/" + name + ".json");
    CHECK(loaded.mesh().triangles.cols() == object.mesh.triangles.cols());
    CHECK(loaded.keypoints() == object.spec.keypoints);
    CHECK(loaded.spec().indicator_sets == object.spec.indicator_sets);
    for (int i = 0; i < loaded.num_keypoints(); ++i) {
      CHECK(c3po::ClosestSurfacePoint(loaded.mesh(), loaded.keypoints().col(i)).distance <
            1e-9 * loaded.diameter());
    }
  }
}
