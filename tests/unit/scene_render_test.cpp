// Scene depth images: composition against brute-force ray casting (instances
// and table plane), back-projection against the renderer's own depth cloud,
// silhouettes vs visible pixels, the plane's depth, degenerate scenes.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "c3po/base/random.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/geometry/scene_render.hpp"
#include "test_objects.hpp"

namespace {

using c3po::CameraIntrinsics;
using c3po::Pose;

// Möller–Trumbore ray parameter (ray from the origin), -1 on a miss; written
// independently of the renderer.
double RayTriangle(const Eigen::Vector3d& direction, const Eigen::Vector3d& a,
                   const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = direction.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-300) return -1.0;
  const Eigen::Vector3d s = -a;
  const double u = s.dot(p) / det;
  if (u < 0.0 || u > 1.0) return -1.0;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = direction.dot(q) / det;
  if (v < 0.0 || u + v > 1.0) return -1.0;
  return e2.dot(q) / det;
}

Pose Posed(const Eigen::Vector3d& axis_angle, const Eigen::Vector3d& t) {
  Pose pose;
  if (axis_angle.norm() > 0) pose.R = Eigen::AngleAxisd(axis_angle.norm(), axis_angle.normalized()).toRotationMatrix();
  pose.t = t;
  return pose;
}

}  // namespace

TEST_CASE("RenderScene: depth and labels equal brute-force ray casting over instances and plane") {
  CameraIntrinsics camera;
  camera.width = 160;
  camera.height = 120;
  camera.fx = camera.fy = 150.0;
  camera.cx = 79.5;
  camera.cy = 59.5;
  const c3po::ObjectModel object = c3po::test::AsymmetricObject(100);
  const c3po::Mesh box = c3po::test::BoxMesh({0, 0, 0}, {0.1, 0.1, 0.1});
  // The asymmetric object in front, partly hiding a box behind it.
  std::vector<c3po::SceneInstance> instances{
      {&object.mesh(), Posed({0.3, -0.5, 0.2}, {0.02, 0.0, 0.8}), c3po::IsClosedOutward(object.mesh())},
      {&box, Posed({0.1, 0.7, 0.0}, {0.1, 0.03, 1.0}), true}};
  c3po::Plane table;
  table.normal = Eigen::Vector3d(0.0, -std::sin(0.3), -std::cos(0.3));
  table.offset = -1.3;
  c3po::DepthRenderer renderer(camera);
  const c3po::SceneImage scene = c3po::RenderScene(renderer, instances, table);
  REQUIRE(scene.depth.size() == 160u * 120u);
  REQUIRE(scene.silhouettes.size() == 2);

  int mismatched_labels = 0, occluded_box_pixels = 0;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector3d ray = camera.Ray(u, v);
      double best = HUGE_VAL;
      int label = -1;
      std::vector<bool> hit(instances.size(), false);
      for (std::size_t i = 0; i < instances.size(); ++i) {
        const c3po::PointSet posed = instances[i].camera_from_model * instances[i].mesh->vertices;
        const Eigen::Matrix3Xi& tris = instances[i].mesh->triangles;
        for (Eigen::Index t = 0; t < tris.cols(); ++t) {
          const double s = RayTriangle(ray, posed.col(tris(0, t)), posed.col(tris(1, t)), posed.col(tris(2, t)));
          if (s <= 0.0) continue;
          hit[i] = true;
          if (s < best) {
            best = s;
            label = static_cast<int>(i);
          }
        }
      }
      const double plane_s = table.offset / table.normal.dot(ray);
      if (label < 0) best = plane_s;
      const std::size_t p = static_cast<std::size_t>(v) * camera.width + u;
      if (scene.label[p] != label) {
        ++mismatched_labels;   // only on a triangle edge through a pixel centre
        continue;
      }
      CHECK(scene.depth[p] == doctest::Approx(best).epsilon(1e-9));
      for (std::size_t i = 0; i < instances.size(); ++i) {
        const bool in = std::binary_search(scene.silhouettes[i].begin(), scene.silhouettes[i].end(),
                                           static_cast<int>(p));
        if (in != hit[i]) ++mismatched_labels;
      }
      if (hit[1] && label == 0) ++occluded_box_pixels;
    }
  }
  CHECK(mismatched_labels <= 2);
  CHECK(occluded_box_pixels > 20);   // the scene really has occlusion
  // Visible pixels are a subset of the silhouette.
  for (int i = 0; i < 2; ++i) {
    const std::vector<int> visible = scene.VisiblePixels(i);
    CHECK(std::includes(scene.silhouettes[static_cast<std::size_t>(i)].begin(),
                        scene.silhouettes[static_cast<std::size_t>(i)].end(), visible.begin(), visible.end()));
  }
  CHECK(scene.VisiblePixels(1).size() < scene.silhouettes[1].size());
}

TEST_CASE("RenderScene: the depth image back-projected equals the renderer's own depth cloud") {
  const CameraIntrinsics camera;   // 640 x 480
  const c3po::ObjectModel object = c3po::test::AsymmetricObject(100);
  const Pose pose = Posed({-0.4, 0.9, 0.3}, {-0.05, 0.04, 0.7});
  c3po::DepthRenderer renderer(camera);
  const c3po::SceneImage scene =
      c3po::RenderScene(renderer, {{&object.mesh(), pose, true}}, std::nullopt);
  // The renderer's cloud of every covered pixel (no noise, no dropout).
  renderer.Render(object.mesh(), pose, true);
  c3po::DepthSampleOptions all;
  all.points = 10000000;
  c3po::Rng rng(1);
  const c3po::PointSet cloud = renderer.SampleCloud(all, rng);
  REQUIRE(cloud.cols() == static_cast<Eigen::Index>(scene.silhouettes[0].size()));
  REQUIRE(cloud.cols() > 1000);
  std::map<int, Eigen::Vector3d> by_pixel;
  for (Eigen::Index i = 0; i < cloud.cols(); ++i) {
    const Eigen::Vector3d point = cloud.col(i);
    const int u = static_cast<int>(std::lround(camera.fx * point.x() / point.z() + camera.cx));
    const int v = static_cast<int>(std::lround(camera.fy * point.y() / point.z() + camera.cy));
    by_pixel[v * camera.width + u] = point;
  }
  REQUIRE(by_pixel.size() == static_cast<std::size_t>(cloud.cols()));
  int checked = 0;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const double z = scene.depth[static_cast<std::size_t>(v) * camera.width + u];
      const auto found = by_pixel.find(v * camera.width + u);
      CHECK((z > 0.0) == (found != by_pixel.end()));
      if (z <= 0.0 || found == by_pixel.end()) continue;
      // Pinhole back-projection written here: ((u - cx) z / fx, (v - cy) z / fy, z).
      const Eigen::Vector3d back((u - camera.cx) * z / camera.fx, (v - camera.cy) * z / camera.fy, z);
      CHECK((back - found->second).norm() < 1e-12);
      ++checked;
    }
  }
  CHECK(checked == cloud.cols());
  // No plane: the rest of the image has no measurement and no label.
  CHECK(std::count(scene.label.begin(), scene.label.end(), 0) == cloud.cols());
}

TEST_CASE("PlaneDepth: points on the plane, misses are 0, an empty scene is all plane") {
  CameraIntrinsics camera;
  camera.width = 64;
  camera.height = 48;
  camera.fx = camera.fy = 40.0;
  camera.cx = 31.5;
  camera.cy = 23.5;
  c3po::Plane plane;
  plane.normal = Eigen::Vector3d(0.0, -std::sin(0.5), -std::cos(0.5));
  plane.offset = -2.0;
  for (int v = 0; v < camera.height; v += 7) {
    for (int u = 0; u < camera.width; u += 5) {
      const double z = c3po::PlaneDepth(plane, camera, u, v);
      REQUIRE(z > 0.0);
      const Eigen::Vector3d x = z * camera.Ray(u, v);
      CHECK(plane.normal.dot(x) == doctest::Approx(plane.offset).epsilon(1e-12));
    }
  }
  // Rows above the centre look farther along a table tilted away at the top.
  CHECK(c3po::PlaneDepth(plane, camera, 32, 0) > c3po::PlaneDepth(plane, camera, 32, 47));
  // A plane behind the camera, or missed by the ray, gives no measurement.
  c3po::Plane behind{Eigen::Vector3d(0, 0, 1), -1.0};
  CHECK(c3po::PlaneDepth(behind, camera, 10, 10) == 0.0);
  c3po::Plane left{Eigen::Vector3d(1, 0, 0), 1.0};   // x = 1: rays left of the centre never reach it
  CHECK(c3po::PlaneDepth(left, camera, 31, 10) == 0.0);
  CHECK(c3po::PlaneDepth(left, camera, 32, 10) > 0.0);
  c3po::Plane through_camera{Eigen::Vector3d(0, 1, 0), 0.0};
  CHECK(c3po::PlaneDepth(through_camera, camera, 10, 10) == 0.0);
  c3po::DepthRenderer renderer(camera);
  const c3po::SceneImage empty = c3po::RenderScene(renderer, {}, plane);
  CHECK(std::count(empty.depth.begin(), empty.depth.end(), 0.0) == 0);
  CHECK(std::count(empty.label.begin(), empty.label.end(), c3po::SceneImage::kBackground) == 64 * 48);
  const c3po::SceneImage nothing = c3po::RenderScene(renderer, {}, std::nullopt);
  CHECK(std::count(nothing.depth.begin(), nothing.depth.end(), 0.0) == 64 * 48);
  // An instance without a mesh is a broken contract.
  CHECK_THROWS_AS(c3po::RenderScene(renderer, {{nullptr, Pose{}, false}}, std::nullopt), std::invalid_argument);
}
