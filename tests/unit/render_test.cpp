// Depth renderer: points on the surface, nothing occluded (brute-force ray
// casting oracle), face-on box, keypoint visibility, sampling options.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <tuple>

#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/io/mesh_io.hpp"
#include "c3po/object/procedural.hpp"
#include "test_helpers.hpp"

namespace {

// Möller–Trumbore: ray parameter s of origin + s * direction hitting triangle
// (a, b, c), or -1 when it misses. Written independently of the renderer.
double RayTriangle(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                   const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = direction.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-300) return -1.0;
  const Eigen::Vector3d s = origin - a;
  const double u = s.dot(p) / det;
  if (u < 0.0 || u > 1.0) return -1.0;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = direction.dot(q) / det;
  if (v < 0.0 || u + v > 1.0) return -1.0;
  return e2.dot(q) / det;
}

// Smallest positive ray parameter of the ray from the camera centre through
// `target` (parameter 1 = the target) over all triangles of the posed mesh.
double FirstHit(const c3po::PointSet& camera_vertices, const Eigen::Matrix3Xi& triangles,
                const Eigen::Vector3d& target) {
  double first = HUGE_VAL;
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    const double s = RayTriangle(Eigen::Vector3d::Zero(), target, camera_vertices.col(triangles(0, t)),
                                 camera_vertices.col(triangles(1, t)),
                                 camera_vertices.col(triangles(2, t)));
    if (s > 0.0) first = std::min(first, s);
  }
  return first;
}

c3po::Pose PoseAtDistance(c3po::Rng& rng, const c3po::Mesh& mesh, double distance) {
  c3po::Pose pose;
  pose.R = rng.Rotation();
  pose.t = Eigen::Vector3d(rng.Uniform(-0.05, 0.05), rng.Uniform(-0.05, 0.05), distance) -
           pose.R * mesh.BoundingBox().center();
  return pose;
}

c3po::Mesh LoadYcbDrill() {
  return c3po::LoadMesh(c3po::test::SharedData() + "/ycb/035_power_drill/textured.obj");
}

}  // namespace

TEST_CASE("rendered points lie on the posed mesh and nothing occludes them") {
  std::vector<std::pair<std::string, c3po::Mesh>> meshes;
  meshes.emplace_back("mug", c3po::MakeBundledObject("mug").mesh);
  meshes.emplace_back("drill", c3po::MakeBundledObject("drill").mesh);
  if (std::filesystem::exists(c3po::test::SharedData() + "/ycb/035_power_drill/textured.obj")) {
    meshes.emplace_back("ycb drill", LoadYcbDrill());
  } else {
    MESSAGE("skipping the YCB drill: " << c3po::test::SharedData() << "/ycb not found");
  }
  c3po::DepthRenderer renderer(c3po::CameraIntrinsics{});
  c3po::Rng rng(11);
  for (const auto& [name, mesh] : meshes) {
    const std::string& mesh_name = name;  // CAPTURE's lambda may not name a structured binding (C++17)
    CAPTURE(mesh_name);
    const double d = mesh.Diameter();
    for (int view = 0; view < 3; ++view) {
      const c3po::Pose pose = PoseAtDistance(rng, mesh, 2.5 * d);
      renderer.Render(mesh, pose);
      c3po::DepthSampleOptions options;
      options.points = 150;
      Eigen::VectorXi triangles;
      const c3po::PointSet cloud = renderer.SampleCloud(options, rng, &triangles);
      REQUIRE(cloud.cols() == 150);
      const c3po::Mesh posed{pose * mesh.vertices, mesh.triangles};
      double worst_surface = 0.0, worst_occlusion = 0.0;
      for (Eigen::Index i = 0; i < cloud.cols(); ++i) {
        const Eigen::Vector3d p = cloud.col(i);
        worst_surface = std::max(worst_surface, c3po::ClosestSurfacePoint(posed, p).distance);
        // Parameter 1 is the point itself: any hit before it is an occluder.
        worst_occlusion = std::max(worst_occlusion, (1.0 - FirstHit(posed.vertices, posed.triangles, p)) * p.norm());
      }
      CHECK(worst_surface < 1e-6 * d);
      CHECK(worst_occlusion < 1e-9 * d);
    }
  }
}

TEST_CASE("a box seen face-on shows exactly that face, one point per pixel centre inside it") {
  // Box [-0.06, 0.05] x [-0.04, 0.035] x [0, 0.2]; camera looks along +z at its
  // z = 0 face from 0.7731 m away (non-integer pixel boundaries).
  const c3po::Mesh box = c3po::MakeCuboid({-0.06, -0.04, 0.0}, {0.05, 0.035, 0.2}, 0.02);
  c3po::Pose pose;
  pose.t = Eigen::Vector3d(0.0113, -0.0071, 0.7731);
  const c3po::CameraIntrinsics camera;
  c3po::DepthRenderer renderer(camera);
  renderer.Render(box, pose);
  // Pixel centres (u, v) whose ray hits the face: u0 <= u <= u1 etc.
  const double z = pose.t.z();
  const auto count_between = [](double lo, double hi) {
    return static_cast<long>(std::floor(hi) - std::ceil(lo) + 1);
  };
  const long expected =
      count_between(camera.fx * (-0.06 + pose.t.x()) / z + camera.cx,
                    camera.fx * (0.05 + pose.t.x()) / z + camera.cx) *
      count_between(camera.fy * (-0.04 + pose.t.y()) / z + camera.cy,
                    camera.fy * (0.035 + pose.t.y()) / z + camera.cy);
  CHECK(static_cast<long>(renderer.covered_pixels().size()) == expected);
  c3po::DepthSampleOptions all;
  all.points = 1000000;
  c3po::Rng rng(3);
  const c3po::PointSet cloud = renderer.SampleCloud(all, rng);
  CHECK(cloud.cols() == expected);
  for (Eigen::Index i = 0; i < cloud.cols(); ++i) {
    CHECK(std::abs(cloud(2, i) - z) < 1e-12);
    CHECK(cloud(0, i) - pose.t.x() >= -0.06 - 1e-12);
    CHECK(cloud(0, i) - pose.t.x() <= 0.05 + 1e-12);
    CHECK(cloud(1, i) - pose.t.y() >= -0.04 - 1e-12);
    CHECK(cloud(1, i) - pose.t.y() <= 0.035 + 1e-12);
  }
  // Front corners visible, back corners hidden behind the front face.
  c3po::PointSet corners(3, 2);
  corners << -0.06, -0.06, -0.04, -0.04, 0.0, 0.2;
  const auto visible = renderer.KeypointsVisible(pose * corners, 1e-3);
  CHECK(visible[0]);
  CHECK_FALSE(visible[1]);
}

TEST_CASE("keypoint visibility agrees with brute-force ray casting") {
  const c3po::BundledObject mug = c3po::MakeBundledObject("mug");
  const double d = mug.mesh.Diameter();
  const double tolerance = 0.002 * d;
  c3po::DepthRenderer renderer(c3po::CameraIntrinsics{});
  c3po::Rng rng(5);
  int seen = 0, hidden = 0;
  for (int view = 0; view < 40; ++view) {
    const c3po::Pose pose = PoseAtDistance(rng, mug.mesh, 2.0 * d);
    renderer.Render(mug.mesh, pose);
    const c3po::PointSet keypoints = pose * mug.spec.keypoints;
    const auto visible = renderer.KeypointsVisible(keypoints, tolerance);
    const c3po::PointSet posed = pose * mug.mesh.vertices;
    for (Eigen::Index k = 0; k < keypoints.cols(); ++k) {
      const Eigen::Vector3d p = keypoints.col(k);
      const bool oracle = (1.0 - FirstHit(posed, mug.mesh.triangles, p)) * p.norm() <= tolerance;
      CHECK(visible[static_cast<std::size_t>(k)] == oracle);
      (oracle ? seen : hidden) += 1;
    }
  }
  CHECK(seen > 50);     // both outcomes are exercised
  CHECK(hidden > 50);
}

TEST_CASE("keypoints outside the image or behind the camera are not visible") {
  const c3po::Mesh box = c3po::MakeCuboid({-0.05, -0.05, -0.05}, {0.05, 0.05, 0.05}, 0.05);
  c3po::Pose pose;
  pose.t = Eigen::Vector3d(0, 0, 1);
  c3po::DepthRenderer renderer(c3po::CameraIntrinsics{});
  renderer.Render(box, pose);
  c3po::PointSet points(3, 3);
  points << 0.0, 5.0, 0.0,   //
      0.0, 0.0, 0.0,         //
      0.5, 1.0, -1.0;        // in front of the box, far right, behind the camera
  const auto visible = renderer.KeypointsVisible(points, 1e-3);
  CHECK(visible[0]);
  CHECK_FALSE(visible[1]);
  CHECK_FALSE(visible[2]);
}

TEST_CASE("re-rendering clears the previous view, empty views are empty") {
  const c3po::BundledObject drill = c3po::MakeBundledObject("drill");
  const double d = drill.mesh.Diameter();
  c3po::Rng rng(9);
  const c3po::Pose first = PoseAtDistance(rng, drill.mesh, 1.5 * d);
  c3po::Pose second = PoseAtDistance(rng, drill.mesh, 4.0 * d);
  second.t.x() += 0.3;
  c3po::DepthRenderer reused(c3po::CameraIntrinsics{});
  c3po::DepthRenderer fresh(c3po::CameraIntrinsics{});
  reused.Render(drill.mesh, first);
  reused.Render(drill.mesh, second);
  fresh.Render(drill.mesh, second);
  REQUIRE(!fresh.covered_pixels().empty());
  CHECK(reused.covered_pixels() == fresh.covered_pixels());
  for (int v = 0; v < 480; v += 7) {
    for (int u = 0; u < 640; u += 7) CHECK(reused.TriangleAt(u, v) == fresh.TriangleAt(u, v));
  }
  // Behind the camera, or entirely outside the image: nothing covered.
  c3po::Pose behind = first;
  behind.t.z() = -behind.t.z();
  reused.Render(drill.mesh, behind);
  CHECK(reused.covered_pixels().empty());
  c3po::Pose aside = first;
  aside.t.x() += 50.0;
  reused.Render(drill.mesh, aside);
  CHECK(reused.covered_pixels().empty());
  c3po::DepthSampleOptions options;
  CHECK(reused.SampleCloud(options, rng).cols() == 0);
}

TEST_CASE("subsampling, dropout and depth noise") {
  const c3po::BundledObject box = c3po::MakeBundledObject("box");
  c3po::Pose pose;
  pose.R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  pose.t = Eigen::Vector3d(0, 0, 0.8);
  c3po::DepthRenderer renderer(c3po::CameraIntrinsics{});
  renderer.Render(box.mesh, pose);
  const auto covered = static_cast<Eigen::Index>(renderer.covered_pixels().size());
  REQUIRE(covered > 5000);
  c3po::Rng rng(1);
  c3po::DepthSampleOptions options;
  options.points = 1000;
  const c3po::PointSet exact = renderer.SampleCloud(options, rng);
  CHECK(exact.cols() == 1000);
  std::set<std::tuple<double, double, double>> distinct;
  for (Eigen::Index i = 0; i < exact.cols(); ++i) distinct.emplace(exact(0, i), exact(1, i), exact(2, i));
  CHECK(distinct.size() == 1000);   // without replacement

  options.points = 4000;
  options.dropout = 0.25;
  const Eigen::Index kept = renderer.SampleCloud(options, rng).cols();
  // Binomial(4000, 0.75): mean 3000, sd 27.
  CHECK(std::abs(kept - 3000) < 150);

  // Noise moves points along their pixel ray with depth sd sigma.
  options.dropout = 0.0;
  options.points = static_cast<int>(covered);
  options.noise_sigma = 0.002;
  c3po::Rng a(4), b(4);
  c3po::DepthSampleOptions clean = options;
  clean.noise_sigma = 0.0;
  const c3po::PointSet noisy = renderer.SampleCloud(options, a);
  const c3po::PointSet reference = renderer.SampleCloud(clean, b);
  REQUIRE(noisy.cols() == covered);
  double sum = 0.0, sum_sq = 0.0;
  for (Eigen::Index i = 0; i < covered; ++i) {
    CHECK(noisy.col(i).normalized().cross(reference.col(i).normalized()).norm() < 1e-12);
    const double dz = noisy(2, i) - reference(2, i);
    sum += dz;
    sum_sq += dz * dz;
  }
  const double mean = sum / covered;
  const double sd = std::sqrt(sum_sq / covered - mean * mean);
  CHECK(std::abs(mean) < 5 * 0.002 / std::sqrt(static_cast<double>(covered)));
  CHECK(sd == doctest::Approx(0.002).epsilon(0.05));
}

TEST_CASE("intrinsics parsing and checks") {
  const c3po::CameraIntrinsics camera = c3po::ParseIntrinsics("600,610,320.5,240.5,641,481");
  CHECK(camera.fx == 600.0);
  CHECK(camera.fy == 610.0);
  CHECK(camera.cx == 320.5);
  CHECK(camera.width == 641);
  CHECK(camera.height == 481);
  CHECK_THROWS_AS(c3po::ParseIntrinsics("600,610,320.5,240.5,641"), c3po::InputError);
  CHECK_THROWS_AS(c3po::ParseIntrinsics("600,x,320.5,240.5,641,481"), c3po::InputError);
  CHECK_THROWS_AS(c3po::ParseIntrinsics("-1,610,320.5,240.5,641,481"), c3po::InputError);
  CHECK_THROWS_AS(c3po::ParseIntrinsics("600,610,320.5,240.5,640.5,480"), c3po::InputError);
  CHECK_THROWS_AS(c3po::ParseIntrinsics("600,610,320.5,240.5,0,480"), c3po::InputError);
  CHECK_THROWS_AS(c3po::ParseIntrinsics("nan,610,320.5,240.5,640,480"), c3po::InputError);
}

TEST_CASE("back-face culling is exact on closed outward meshes") {
  std::vector<c3po::Mesh> meshes{c3po::MakeBundledObject("mug").mesh,
                                 c3po::MakeBundledObject("chair").mesh};
  if (std::filesystem::exists(c3po::test::SharedData() + "/ycb/035_power_drill/textured.obj")) {
    meshes.push_back(LoadYcbDrill());   // split at texture seams, with a zero-thickness fin
  }
  c3po::DepthRenderer culled(c3po::CameraIntrinsics{});
  c3po::DepthRenderer full(c3po::CameraIntrinsics{});
  c3po::Rng rng(21);
  for (const c3po::Mesh& mesh : meshes) {
    REQUIRE(c3po::IsClosedOutward(mesh));
    const double d = mesh.Diameter();
    for (int view = 0; view < 5; ++view) {
      const c3po::Pose pose = PoseAtDistance(rng, mesh, 2.0 * d);
      culled.Render(mesh, pose, true);
      full.Render(mesh, pose, false);
      REQUIRE(culled.covered_pixels() == full.covered_pixels());
      for (int pixel : full.covered_pixels()) {
        const int u = pixel % 640, v = pixel / 640;
        CHECK(std::abs(culled.DepthAt(u, v) - full.DepthAt(u, v)) < 1e-12 * d);
      }
    }
  }
}

TEST_CASE("IsClosedOutward rejects open, inverted and inconsistent meshes") {
  const c3po::Mesh box = c3po::MakeCuboid({0, 0, 0}, {1, 2, 3}, 0.5);
  CHECK(c3po::IsClosedOutward(box));
  c3po::Mesh open = box;
  open.triangles = box.triangles.leftCols(box.triangles.cols() - 1);
  CHECK_FALSE(c3po::IsClosedOutward(open));
  c3po::Mesh inverted = box;
  c3po::FlipTriangles(&inverted);
  CHECK_FALSE(c3po::IsClosedOutward(inverted));
  c3po::Mesh one_flipped = box;
  std::swap(one_flipped.triangles(1, 3), one_flipped.triangles(2, 3));
  CHECK_FALSE(c3po::IsClosedOutward(one_flipped));
  // Splitting vertices (as loaders do at texture seams) keeps it closed.
  c3po::Mesh split = box;
  split.vertices.conservativeResize(3, box.vertices.cols() + 1);
  split.vertices.col(box.vertices.cols()) = box.vertices.col(split.triangles(0, 0));
  split.triangles(0, 0) = static_cast<int>(box.vertices.cols());
  CHECK(c3po::IsClosedOutward(split));
  CHECK_FALSE(c3po::IsClosedOutward(c3po::Mesh{}));
}

TEST_CASE("IsClosedOutward leaves out zero-thickness fins, not repeated triangles") {
  const c3po::Mesh box = c3po::MakeCuboid({0, 0, 0}, {1, 2, 3}, 0.5);
  const auto with_extra = [&box](std::vector<Eigen::Vector3i> extra) {
    c3po::Mesh mesh = box;
    const Eigen::Index n = box.triangles.cols();
    mesh.triangles.conservativeResize(3, n + static_cast<Eigen::Index>(extra.size()));
    for (std::size_t k = 0; k < extra.size(); ++k) mesh.triangles.col(n + static_cast<Eigen::Index>(k)) = extra[k];
    return mesh;
  };
  // A fin inside the box: a triangle over its diagonal and the reversed copy (drawn either way).
  const Eigen::Vector3i diagonal(box.triangles(0, 0), box.triangles(1, 0), box.triangles(1, 6));
  CHECK(c3po::IsClosedOutward(with_extra({diagonal, Eigen::Vector3i(diagonal(0), diagonal(2), diagonal(1))})));
  // A face repeated with the same winding: its directed edges occur twice, so the rule refuses it.
  const Eigen::Vector3i face = box.triangles.col(4);
  CHECK_FALSE(c3po::IsClosedOutward(with_extra({face})));
  CHECK_FALSE(c3po::IsClosedOutward(with_extra({face, face, Eigen::Vector3i(face(0), face(2), face(1))})));
}
