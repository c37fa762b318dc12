// Camera inputs (issue 15): back-projection against analytic surfaces and the
// renderer's own points, depth_scale and .npy depth, masks, erosion and the
// depth-discontinuity filter against brute force, COCO RLE against brute
// force, camera JSON forms and errors, sharding.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "c3po/base/atomic_file.hpp"
#include "c3po/io/camera_io.hpp"
#include "c3po/base/error.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/io/rle.hpp"
#include "c3po/io/segment.hpp"
#include "c3po/io/shard.hpp"
#include "c3po/io/support_plane.hpp"
#include "test_helpers.hpp"

using c3po::test::InputErrorOf;

namespace {

using c3po::DepthImage;
using c3po::Mask;

const c3po::PinholeCamera kCamera{600.0, 610.0, 159.5, 121.0};

Mask FullMask(int w, int h) { return Mask{w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h, 1)}; }

c3po::SegmentOptions NoPreprocessing() {
  c3po::SegmentOptions options;
  options.erode_mask_metres = 0.0;
  options.erode_mask = 0;
  options.max_relative_depth_step = 0.0;
  options.support_plane_distance = 0.0;
  options.max_points = 0;
  return options;
}

// Depth of the sphere |X - c| = r along the ray of pixel (u, v) (0 = miss).
double SphereDepth(const c3po::PinholeCamera& K, int u, int v, const Eigen::Vector3d& c, double r) {
  const Eigen::Vector3d d((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);   // X = z d
  const double a = d.squaredNorm(), b = -2.0 * d.dot(c), cc = c.squaredNorm() - r * r;
  const double disc = b * b - 4 * a * cc;
  if (disc < 0) return 0.0;
  return (-b - std::sqrt(disc)) / (2 * a);
}

// A near box (0.5 m) in front of a far wall (1.5 m), holes, noise.
DepthImage BoxBeforeWall(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> noise(-0.002, 0.002);
  DepthImage depth{w, h, std::vector<float>(static_cast<std::size_t>(w) * h)};
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      double z = (u > 10 && u < 30 && v > 8 && v < 22) ? 0.5 : 1.5;
      if ((u * 7 + v * 3) % 29 == 0) z = 0.0;
      depth.z[static_cast<std::size_t>(v) * w + u] = static_cast<float>(z > 0 ? z + noise(rng) : 0.0);
    }
  }
  return depth;
}

Mask RandomMask(int w, int h, unsigned seed, double p) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution on(p);
  Mask mask{w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h)};
  for (auto& m : mask.inside) m = on(rng);
  return mask;
}

}  // namespace

TEST_CASE("back-projection: a tilted plane and a sphere, exact in float and within quantisation in 16-bit PNG") {
  const int w = 320, h = 240;
  // Plane n.X = 0.8 (n unit, tilted): z = 0.8 / (n . ray).
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  DepthImage plane{w, h, std::vector<float>(static_cast<std::size_t>(w) * h)};
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      plane.z[static_cast<std::size_t>(v) * w + u] =
          static_cast<float>(0.8 / n.dot(Eigen::Vector3d((u - kCamera.cx) / kCamera.fx, (v - kCamera.cy) / kCamera.fy, 1.0)));
    }
  }
  const c3po::SegmentCloud flat = c3po::ExtractSegment(plane, FullMask(w, h), kCamera, NoPreprocessing(), "plane");
  REQUIRE(flat.cloud.cols() == w * h);
  CHECK(((n.transpose() * flat.cloud).array() - 0.8).abs().maxCoeff() < 1e-6);   // float32 depth
  // Each point projects back onto its own pixel centre.
  for (Eigen::Index i = 0; i < flat.cloud.cols(); i += 997) {
    const Eigen::Vector2d uv = kCamera.Project(flat.cloud.col(i));
    CHECK(uv.x() == doctest::Approx(flat.pixels[static_cast<std::size_t>(i)] % w).epsilon(1e-9));
    CHECK(uv.y() == doctest::Approx(flat.pixels[static_cast<std::size_t>(i)] / w).epsilon(1e-9));
  }

  // Sphere through a 16-bit PNG: value = round(z_mm / depth_scale).
  const Eigen::Vector3d centre(0.02, -0.01, 0.7);
  const double radius = 0.12;
  for (double depth_scale : {1.0, 0.1}) {
    c3po::Image png(w, h, 16);
    Mask mask{w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h)};
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        const double z = SphereDepth(kCamera, u, v, centre, radius);
        png.at(u, v) = static_cast<std::uint16_t>(std::lround(z * 1000.0 / depth_scale));
        mask.inside[static_cast<std::size_t>(v) * w + u] = z > 0;
      }
    }
    c3po::test::TempDir dir("backproject_sphere");
    c3po::WritePng(dir / "d.png", png);
    const DepthImage depth = c3po::ReadDepth(dir / "d.png", depth_scale);
    const c3po::SegmentCloud sphere = c3po::ExtractSegment(depth, mask, kCamera, NoPreprocessing(), "sphere");
    CHECK(sphere.cloud.cols() == static_cast<Eigen::Index>(mask.Count()));
    CHECK(sphere.no_depth == 0);
    // Quantisation: |dz| <= depth_scale/2 mm, moving the point along its ray
    // (|ray| <= 1.1 here) changes |X - c| by at most that much.
    const double tolerance = 1.1 * 0.5 * depth_scale * 1e-3 + 1e-6;
    const double worst = ((sphere.cloud.colwise() - centre).colwise().norm().array() - radius).abs().maxCoeff();
    CHECK(worst <= tolerance);
    CHECK(worst > 0.0);
  }
}

TEST_CASE("back-projection of a rendered object equals the renderer's own points") {
  const c3po::ObjectModel object = c3po::LoadObject(c3po::test::SourceDir() + "/annotations/drill.json");
  c3po::CameraIntrinsics intrinsics;   // 640 x 480, f = 525
  c3po::DepthRenderer renderer(intrinsics);
  c3po::Rng rng(5);
  const c3po::Pose camera_from_model{rng.Rotation(), Eigen::Vector3d(0.03, -0.02, 0.8)};
  renderer.Render(object.mesh(), camera_from_model);
  REQUIRE(renderer.covered_pixels().size() > 1000);
  DepthImage depth{intrinsics.width, intrinsics.height,
                   std::vector<float>(static_cast<std::size_t>(intrinsics.width) * intrinsics.height, 0.0f)};
  Mask mask{intrinsics.width, intrinsics.height, std::vector<std::uint8_t>(depth.z.size(), 0)};
  for (int pixel : renderer.covered_pixels()) {
    depth.z[static_cast<std::size_t>(pixel)] = static_cast<float>(renderer.DepthAt(pixel % intrinsics.width, pixel / intrinsics.width));
    mask.inside[static_cast<std::size_t>(pixel)] = 1;
  }
  // Through a .npy file (float32 metres).
  c3po::test::TempDir dir("backproject_render");
  c3po::WriteFileAtomically(dir / "d.npy", c3po::EncodeNpyDepth(depth));
  const DepthImage read = c3po::ReadDepth(dir / "d.npy", 123.0 /* unused for .npy */);
  CHECK(read.z == depth.z);
  const c3po::PinholeCamera K{intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy};
  const c3po::SegmentCloud segment = c3po::ExtractSegment(read, mask, K, NoPreprocessing(), "render");
  REQUIRE(segment.cloud.cols() == static_cast<Eigen::Index>(renderer.covered_pixels().size()));
  double worst = 0.0;
  for (std::size_t i = 0; i < segment.pixels.size(); ++i) {
    const Eigen::Vector3d theirs = renderer.BackProject(segment.pixels[i]);
    worst = std::max(worst, (segment.cloud.col(static_cast<Eigen::Index>(i)) - theirs).norm());
  }
  CHECK(worst < 1e-6);   // float32 depth at 0.8 m: ~1e-7 relative
  // And they lie on the posed mesh (exact closest-point oracle on a subset).
  for (Eigen::Index i = 0; i < segment.cloud.cols(); i += 211) {
    const Eigen::Vector3d model_point = camera_from_model.InverseApply(segment.cloud.col(i));
    CHECK(c3po::ClosestSurfacePoint(object.mesh(), model_point).distance < 1e-6);
  }
}

TEST_CASE("masks: non-zero and label images, sizes must match the depth") {
  c3po::Image label(4, 3, 8);
  label.pixels = {0, 1, 2, 2, 5, 0, 2, 1, 0, 0, 7, 2};
  CHECK(c3po::MaskFromImage(label).Count() == 8);
  CHECK(c3po::MaskFromImage(label, 2).Count() == 4);
  CHECK(c3po::MaskFromImage(label, 9).Count() == 0);
  DepthImage depth{5, 3, std::vector<float>(15, 1.0f)};
  const std::string error = InputErrorOf([&] {
    c3po::ExtractSegment(depth, c3po::MaskFromImage(label), kCamera, NoPreprocessing(), "m.png");
  });
  CHECK(error.find("m.png: depth is 5 x 3 but the mask is 4 x 3") == 0);
}

TEST_CASE("erosion equals the brute-force (2k+1)^2 window test, the image border does not erode") {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const Mask mask = RandomMask(23 + static_cast<int>(seed), 17, seed, 0.85);
    for (int k : {0, 1, 2, 4}) {
      const Mask eroded = c3po::ErodeMask(mask, k);
      for (int v = 0; v < mask.height; ++v) {
        for (int u = 0; u < mask.width; ++u) {
          bool all = true;
          for (int dv = -k; dv <= k; ++dv) {
            for (int du = -k; du <= k; ++du) {
              const int x = u + du, y = v + dv;
              if (x >= 0 && y >= 0 && x < mask.width && y < mask.height && !mask.at(x, y)) all = false;
            }
          }
          REQUIRE(eroded.at(u, v) == all);
        }
      }
    }
  }
  CHECK(c3po::ErodeMask(FullMask(5, 4), 3).Count() == 20);
}

TEST_CASE("mask distance equals the brute-force chessboard distance to the nearest mask pixel") {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const Mask mask = RandomMask(29 + static_cast<int>(seed), 19, seed, 0.03 * seed);   // sparse to dense
    const std::vector<int> distance = c3po::MaskDistance(mask);
    REQUIRE(distance.size() == mask.inside.size());
    for (int v = 0; v < mask.height; ++v) {
      for (int u = 0; u < mask.width; ++u) {
        int nearest = mask.width + mask.height;
        for (int y = 0; y < mask.height; ++y) {
          for (int x = 0; x < mask.width; ++x) {
            if (mask.at(x, y)) nearest = std::min(nearest, std::max(std::abs(x - u), std::abs(y - v)));
          }
        }
        REQUIRE(distance[static_cast<std::size_t>(v) * mask.width + u] == nearest);
      }
    }
  }
  Mask empty = FullMask(6, 4);
  std::fill(empty.inside.begin(), empty.inside.end(), 0);
  const std::vector<int> none = c3po::MaskDistance(empty);
  CHECK(std::all_of(none.begin(), none.end(), [](int d) { return d == 10; }));
}

TEST_CASE("preprocessing: counts add up, the discontinuity filter equals brute force, the bound strides") {
  const int w = 40, h = 30;
  const DepthImage depth = BoxBeforeWall(w, h, 3);
  Mask mask{w, h, std::vector<std::uint8_t>(depth.z.size(), 0)};
  for (int v = 7; v < 24; ++v) for (int u = 9; u < 32; ++u) mask.inside[static_cast<std::size_t>(v) * w + u] = 1;   // bleeds by ~2 px
  for (int erode : {0, 1, 2}) {
    for (double step : {0.0, 0.02, 0.1}) {
      c3po::SegmentOptions options;
      options.erode_mask_metres = 0.0;   // pixel widths, no floor: the oracle erodes by exactly `erode`
      options.min_eroded_fraction = 0.0;
      options.erode_mask = erode;
      options.max_relative_depth_step = step;
      options.support_plane_distance = 0.0;   // the support plane has its own test
      options.max_points = 0;
      const c3po::SegmentCloud s = c3po::ExtractSegment(depth, mask, kCamera, options, "x");
      CHECK(s.mask_pixels == mask.Count());
      CHECK(s.removed_by_plane == 0);
      CHECK(s.mask_pixels == s.no_depth + s.removed_by_erosion + s.removed_by_discontinuity + s.removed_by_subsampling +
                                 static_cast<std::size_t>(s.cloud.cols()));
      // Brute force over the eroded mask's pixels with depth.
      const Mask eroded = c3po::ErodeMask(mask, erode);
      std::vector<std::int32_t> expected;
      for (int v = 0; v < h; ++v) {
        for (int u = 0; u < w; ++u) {
          const float z = depth.at(u, v);
          if (!mask.at(u, v) || !(z > 0) || !eroded.at(u, v)) continue;
          bool edge = false;
          for (int dv = -1; dv <= 1; ++dv) {
            for (int du = -1; du <= 1; ++du) {
              const int x = u + du, y = v + dv;
              if (x < 0 || y < 0 || x >= w || y >= h) continue;
              const float zn = depth.at(x, y);
              if (zn > 0 && std::abs(zn - z) > step * z) edge = true;
            }
          }
          if (step > 0 && edge) continue;
          expected.push_back(v * w + u);
        }
      }
      CHECK(s.pixels == expected);
      if (step > 0.0 && erode == 0) CHECK(s.removed_by_discontinuity > 0);
      // No kept point is on the far wall once the filter or erosion is on.
      if (erode + (step > 0.0 ? 1 : 0) >= 2) {   // the mask bleeds 2 px; the filter takes the ring next to the box
        CHECK((s.cloud.row(2).array() < 1.0).all());
      }
    }
  }
  c3po::SegmentOptions bounded = NoPreprocessing();
  bounded.max_points = 50;
  const c3po::SegmentCloud all = c3po::ExtractSegment(depth, mask, kCamera, NoPreprocessing(), "x");
  const c3po::SegmentCloud few = c3po::ExtractSegment(depth, mask, kCamera, bounded, "x");
  REQUIRE(few.cloud.cols() == 50);
  CHECK(few.removed_by_subsampling == static_cast<std::size_t>(all.cloud.cols() - 50));
  CHECK(few.cloud == c3po::StridedColumns(all.cloud, 50));
  for (Eigen::Index j = 0; j < 50; ++j) CHECK(few.pixels[static_cast<std::size_t>(j)] == all.pixels[static_cast<std::size_t>(j * all.cloud.cols() / 50)]);
}

namespace {

// Ray direction of pixel (u, v) with unit z: the point at depth z is z * ray.
Eigen::Vector3d Ray(const c3po::PinholeCamera& K, int u, int v) { return {(u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0}; }

// A table n.X = c (n unit, tilted towards the camera) with a ball of radius r
// resting on it; the ball's mask is dilated by `bleed` pixels onto the table.
struct TableScene {
  Eigen::Vector3d n = Eigen::Vector3d(0.0, -0.6, -0.8).normalized();   // table normal, towards the camera
  double c = -0.8;                                                    // n.X = c: 0.8 m from the camera
  double r = 0.06;
  Eigen::Vector3d ball;                                               // ball centre
  DepthImage depth;
  Mask ball_mask, mask;                                               // visible ball; dilated
};

TableScene MakeTableScene(int w, int h, int bleed) {
  TableScene s;
  const Eigen::Vector3d foot = Eigen::Vector3d::UnitZ() * (s.c / s.n.z());   // the table on the optical axis
  s.ball = foot + s.r * s.n;
  s.depth = DepthImage{w, h, std::vector<float>(static_cast<std::size_t>(w) * h)};
  s.ball_mask = Mask{w, h, std::vector<std::uint8_t>(s.depth.z.size(), 0)};
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const double table = s.c / s.n.dot(Ray(kCamera, u, v));
      const double ball = SphereDepth(kCamera, u, v, s.ball, s.r);
      const bool on_ball = ball > 0.0 && ball < table;
      s.depth.z[static_cast<std::size_t>(v) * w + u] = static_cast<float>(on_ball ? ball : table);
      s.ball_mask.inside[static_cast<std::size_t>(v) * w + u] = on_ball;
    }
  }
  // Dilation = complement of the eroded complement.
  Mask outside = s.ball_mask;
  for (auto& m : outside.inside) m = !m;
  s.mask = c3po::ErodeMask(outside, bleed);
  for (auto& m : s.mask.inside) m = !m;
  return s;
}

}  // namespace

TEST_CASE("support plane: the table under a ball is found, the mask's bleed onto it is dropped, the ball is kept") {
  const int w = 320, h = 240;
  const TableScene scene = MakeTableScene(w, h, 6);
  const double distance = 0.01;
  REQUIRE(scene.mask.Count() > scene.ball_mask.Count() + 500);
  const std::optional<c3po::SupportPlaneFit> fit = c3po::FitSupportPlane(scene.depth, scene.mask, kCamera, distance);
  REQUIRE(fit.has_value());
  // The analytic table (float depth: micrometre agreement).
  CHECK(std::abs(std::abs(fit->plane.normal.dot(scene.n)) - 1.0) < 1e-6);
  for (int v = 0; v < h; v += 37) {
    for (int u = 0; u < w; u += 41) {
      if (scene.mask.at(u, v)) continue;
      CHECK(fit->plane.Distance(kCamera.BackProject(u, v, scene.depth.at(u, v))) < 1e-5);
    }
  }
  CHECK(fit->inlier_samples == fit->background_samples);   // every background sample is table
  // Same frame, same plane.
  const std::optional<c3po::SupportPlaneFit> again = c3po::FitSupportPlane(scene.depth, scene.mask, kCamera, distance);
  CHECK(again->plane.normal == fit->plane.normal);
  CHECK(again->plane.offset == fit->plane.offset);

  c3po::SegmentOptions options = NoPreprocessing();
  options.support_plane_distance = distance;
  const c3po::SegmentCloud segment = c3po::ExtractSegment(scene.depth, scene.mask, kCamera, options, "x");
  CHECK(segment.support_plane.has_value());
  CHECK(segment.mask_pixels == segment.no_depth + segment.removed_by_erosion + segment.removed_by_discontinuity +
                                   segment.removed_by_plane + segment.removed_by_subsampling +
                                   static_cast<std::size_t>(segment.cloud.cols()));
  // Brute force against the analytic table: a mask pixel is kept exactly when
  // its point is farther than `distance` from the table (a 1e-5 m guard band
  // for the fitted plane's rounding; no pixel falls inside it here).
  std::vector<std::int32_t> expected;
  std::size_t bleed = 0, ball_points_near_table = 0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (!scene.mask.at(u, v)) continue;
      const Eigen::Vector3d p = kCamera.BackProject(u, v, scene.depth.at(u, v));
      const double height = std::abs(scene.n.dot(p) - scene.c);
      REQUIRE(std::abs(height - distance) > 1e-5);
      if (height > distance) expected.push_back(v * w + u);
      if (!scene.ball_mask.at(u, v)) ++bleed;
      if (scene.ball_mask.at(u, v) && height <= distance) ++ball_points_near_table;
    }
  }
  CHECK(segment.pixels == expected);
  // Every bleeding pixel went; of the ball only the band within `distance` of
  // the table (its points there are within 1 cm of where it touches).
  CHECK(segment.removed_by_plane == bleed + ball_points_near_table);
  CHECK(ball_points_near_table < scene.ball_mask.Count() / 10);
  CHECK(segment.cloud.cols() + static_cast<Eigen::Index>(ball_points_near_table) ==
        static_cast<Eigen::Index>(scene.ball_mask.Count()));

  CHECK_NOTHROW(c3po::RequireUsableSegment(segment, "ball"));
  // A mask that is mostly table (the ball's mask dilated by 40 px) is refused
  // as input, naming the mask; with the plane off it is a segment as before.
  const TableScene wide = MakeTableScene(w, h, 40);
  const c3po::SegmentCloud mostly_table = c3po::ExtractSegment(wide.depth, wide.mask, kCamera, options, "wide.png");
  REQUIRE(mostly_table.removed_by_plane > (wide.mask.Count() - mostly_table.no_depth) / 2);
  const std::string error = InputErrorOf([&] { c3po::RequireUsableSegment(mostly_table, "wide.png"); });
  CHECK(error.find("wide.png: the mask is mostly the support plane") == 0);
  CHECK_NOTHROW(c3po::RequireUsableSegment(
      c3po::ExtractSegment(wide.depth, wide.mask, kCamera, NoPreprocessing(), "wide.png"), "wide.png"));

  // Off: nothing is dropped.
  const c3po::SegmentCloud kept_all = c3po::ExtractSegment(scene.depth, scene.mask, kCamera, NoPreprocessing(), "x");
  CHECK(kept_all.removed_by_plane == 0);
  CHECK(kept_all.cloud.cols() == static_cast<Eigen::Index>(scene.mask.Count()));
}

TEST_CASE("support plane: the object's own large face is not the support, no dominant plane, nothing dropped") {
  const int w = 320, h = 240;
  const double distance = 0.01;
  // A frontal box face at 0.6 m covering 56 % of the image, in front of the
  // tilted table: the mask is the face, the plane must be the table's (the
  // face would win were the mask's pixels not excluded).
  TableScene scene = MakeTableScene(w, h, 0);
  Mask face{w, h, std::vector<std::uint8_t>(scene.depth.z.size(), 0)};
  for (int v = h / 8; v < 7 * h / 8; ++v) {
    for (int u = w / 8; u < 7 * w / 8; ++u) {
      scene.depth.z[static_cast<std::size_t>(v) * w + u] = 0.6f;
      face.inside[static_cast<std::size_t>(v) * w + u] = 1;
    }
  }
  const std::optional<c3po::SupportPlaneFit> fit = c3po::FitSupportPlane(scene.depth, face, kCamera, distance);
  REQUIRE(fit.has_value());
  CHECK(std::abs(std::abs(fit->plane.normal.dot(scene.n)) - 1.0) < 1e-3);   // the ball is background here
  c3po::SegmentOptions options = NoPreprocessing();
  options.support_plane_distance = distance;
  const c3po::SegmentCloud segment = c3po::ExtractSegment(scene.depth, face, kCamera, options, "face");
  CHECK(segment.removed_by_plane == 0);
  CHECK(segment.cloud.cols() == static_cast<Eigen::Index>(face.Count()));

  // Corrugated background (amplitude 10 cm, wavelength 10 cm): no plane holds
  // a fifth of it, so nothing is dropped.
  DepthImage wavy{w, h, std::vector<float>(static_cast<std::size_t>(w) * h)};
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const double x = Ray(kCamera, u, v).x();   // ~ metres at z = 1
      wavy.z[static_cast<std::size_t>(v) * w + u] = static_cast<float>(1.0 + 0.1 * std::sin(2.0 * M_PI * x / 0.1));
    }
  }
  Mask centre{w, h, std::vector<std::uint8_t>(wavy.z.size(), 0)};
  for (int v = h / 4; v < 3 * h / 4; ++v) {
    for (int u = w / 4; u < 3 * w / 4; ++u) centre.inside[static_cast<std::size_t>(v) * w + u] = 1;
  }
  CHECK_FALSE(c3po::FitSupportPlane(wavy, centre, kCamera, distance).has_value());
  const c3po::SegmentCloud on_wavy = c3po::ExtractSegment(wavy, centre, kCamera, options, "wavy");
  CHECK_FALSE(on_wavy.support_plane.has_value());
  CHECK(on_wavy.removed_by_plane == 0);

  // The only background is another object's face (a frontal square at 0.9 m,
  // a tenth of the image; no depth elsewhere), the target a ball beside it
  // whose points lie within 1 cm of that face's plane: the face is no
  // support, nothing is dropped (as on synth --format bop scenes).
  DepthImage objects{w, h, std::vector<float>(static_cast<std::size_t>(w) * h, 0.0f)};
  Mask target{w, h, std::vector<std::uint8_t>(objects.z.size(), 0)};
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      if (u < w / 3 && v > h / 3 && v < 2 * h / 3) objects.z[i] = 0.9f;
      const double ball = SphereDepth(kCamera, u, v, Eigen::Vector3d(0.05, 0.0, 0.9), 0.04);
      if (ball > 0.0) objects.z[i] = static_cast<float>(ball), target.inside[i] = 1;
    }
  }
  REQUIRE(target.Count() > 100);
  CHECK_FALSE(c3po::FitSupportPlane(objects, target, kCamera, distance).has_value());
  const c3po::SegmentCloud beside = c3po::ExtractSegment(objects, target, kCamera, options, "beside");
  CHECK(beside.removed_by_plane == 0);
  CHECK(beside.cloud.cols() == static_cast<Eigen::Index>(target.Count()));

  // Lying inputs: NaN and huge depths, an all-mask frame: no plane, no crash.
  DepthImage lying = scene.depth;
  for (std::size_t i = 0; i < lying.z.size(); i += 3) lying.z[i] = i % 2 ? std::nanf("") : 1e29f;
  (void)c3po::FitSupportPlane(lying, face, kCamera, distance);
  CHECK_FALSE(c3po::FitSupportPlane(scene.depth, FullMask(w, h), kCamera, distance).has_value());
  options.support_plane_distance = -1.0;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
}

TEST_CASE("unusable segments: no pixels, no depth, too few points left") {
  DepthImage depth{6, 6, std::vector<float>(36, 0.0f)};
  Mask empty{6, 6, std::vector<std::uint8_t>(36, 0)};
  auto message = [&](const Mask& mask, const DepthImage& d) {
    return InputErrorOf([&] { c3po::RequireUsableSegment(c3po::ExtractSegment(d, mask, kCamera, c3po::SegmentOptions{}, "m.png"), "m.png"); });
  };
  CHECK(message(empty, depth) == "m.png: mask has no pixels");
  CHECK(message(FullMask(6, 6), depth) == "m.png: no valid depth under the mask (36 pixels)");
  depth.z.assign(36, std::nanf(""));
  CHECK(message(FullMask(6, 6), depth) == "m.png: no valid depth under the mask (36 pixels)");
  depth.z.assign(36, 1.0f);
  Mask dot = empty;
  dot.inside[14] = 1;
  // A one-pixel segment: the default erosion (4 px) would remove all of it, so the floor
  // (min_eroded_fraction) keeps it uneroded; without the floor it is eroded away. (The flat frame would be one
  // support plane taking the dot: that step is off here.)
  c3po::SegmentOptions floor;
  floor.support_plane_distance = 0.0;
  c3po::SegmentOptions no_floor = floor;
  no_floor.min_eroded_fraction = 0.0;
  const auto error_with = [&](const c3po::SegmentOptions& options) {
    return InputErrorOf([&] { c3po::RequireUsableSegment(c3po::ExtractSegment(depth, dot, kCamera, options, "m.png"), "m.png"); });
  };
  CHECK(error_with(floor) == "m.png: only 1 points left after preprocessing (1 mask pixels, 0 without depth, 0 eroded, "
                             "0 on depth edges, 0 on the support plane)");
  CHECK(error_with(no_floor) == "m.png: only 0 points left after preprocessing (1 mask pixels, 0 without depth, 1 eroded, "
                                "0 on depth edges, 0 on the support plane)");
}

TEST_CASE("the erosion floor (one distance transform) equals lowering k through brute-force erosions") {
  std::mt19937 rng(5);
  const int w = 48, h = 36;
  for (int trial = 0; trial < 60; ++trial) {
    CAPTURE(trial);
    // A random blob: the union of a few rectangles (some touching the border), depth missing at random.
    Mask mask{w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h, 0)};
    for (int r = 0; r < 3; ++r) {
      const int u0 = static_cast<int>(rng() % w), v0 = static_cast<int>(rng() % h);
      const int u1 = std::min(w, u0 + 1 + static_cast<int>(rng() % 20)), v1 = std::min(h, v0 + 1 + static_cast<int>(rng() % 15));
      for (int v = v0; v < v1; ++v) for (int u = u0; u < u1; ++u) mask.inside[static_cast<std::size_t>(v) * w + u] = 1;
    }
    DepthImage depth{w, h, std::vector<float>(static_cast<std::size_t>(w) * h, 1.0f)};
    for (float& z : depth.z) if (rng() % 5 == 0) z = 0.0f;
    const auto with_depth = [&](const Mask& m) {
      std::size_t count = 0;
      for (std::size_t i = 0; i < m.inside.size(); ++i) count += m.inside[i] != 0 && depth.z[i] > 0.0f;
      return count;
    };
    for (int asked : {0, 1, 2, 4, 7}) {
      c3po::SegmentOptions options;
      options.erode_mask_metres = 0.0;
      options.erode_mask = asked;
      const double keep = options.min_eroded_fraction * static_cast<double>(with_depth(mask));
      int expected = with_depth(mask) == 0 ? 0 : asked;
      while (expected > 0 && static_cast<double>(with_depth(c3po::ErodeMask(mask, expected))) < keep) --expected;
      CHECK(c3po::ErosionPixels(depth, mask, kCamera, options) == expected);
    }
  }
}

TEST_CASE("metric erosion: k = round(f w / median depth), the same band in metres at any distance and focal length") {
  // A flat 120 x 90 px mask at depth z; a 3 mm band is round(f * 0.003 / z) px (at most 11 here, which keeps
  // 98 x 68 px, more than half: the floor does not act).
  const int w = 160, h = 120;
  Mask mask{w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h, 0)};
  for (int v = 15; v < 105; ++v) for (int u = 20; u < 140; ++u) mask.inside[static_cast<std::size_t>(v) * w + u] = 1;
  for (double z : {0.3, 0.6, 1.2}) {
    for (double f : {380.0, 572.0, 1067.0}) {
      CAPTURE(z);
      CAPTURE(f);
      const DepthImage depth{w, h, std::vector<float>(static_cast<std::size_t>(w) * h, static_cast<float>(z))};
      const c3po::PinholeCamera camera{f, f, 80.0, 60.0};
      c3po::SegmentOptions options;   // 3 mm, floor 0.5
      options.erode_mask_metres = 0.003;
      options.max_points = 0;
      options.support_plane_distance = 0.0;
      const int expected = static_cast<int>(std::round(f * 0.003 / z));
      CHECK(c3po::ErosionPixels(depth, mask, camera, options) == expected);
      const c3po::SegmentCloud s = c3po::ExtractSegment(depth, mask, camera, options, "x");
      CHECK(s.erode_pixels == expected);
      // Brute force: the eroded rectangle keeps (120 - 2k)(90 - 2k) pixels (the flat depth has no edges inside).
      CHECK(s.cloud.cols() == (120 - 2 * expected) * (90 - 2 * expected));
      CHECK(s.removed_by_erosion == static_cast<std::size_t>(120 * 90 - s.cloud.cols()));
    }
  }
  // The floor: a 6 px strip would be eroded away by 11 px (f 1067 at 0.3 m); k is lowered to the largest value
  // keeping half of it (6 - 2k >= 3: k = 1), whatever the width asked.
  Mask strip{w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h, 0)};
  for (int v = 20; v < 26; ++v) for (int u = 5; u < 75; ++u) strip.inside[static_cast<std::size_t>(v) * w + u] = 1;
  const DepthImage near{w, h, std::vector<float>(static_cast<std::size_t>(w) * h, 0.3f)};
  c3po::SegmentOptions options;
  options.erode_mask_metres = 0.003;
  CHECK(c3po::ErosionPixels(near, strip, c3po::PinholeCamera{1067.0, 1067.0, 40.0, 30.0}, options) == 1);
  options.erode_mask_metres = 0.0;
  options.erode_mask = 5;
  CHECK(c3po::ErosionPixels(near, strip, c3po::PinholeCamera{1067.0, 1067.0, 40.0, 30.0}, options) == 1);
  options.min_eroded_fraction = 0.0;
  CHECK(c3po::ErosionPixels(near, strip, c3po::PinholeCamera{1067.0, 1067.0, 40.0, 30.0}, options) == 5);
  // The median depth, not the mean: a few far pixels do not change k.
  DepthImage mixed = near;
  for (int u = 30; u < 40; ++u) mixed.z[static_cast<std::size_t>(50) * w + u] = 5.0f;
  options = c3po::SegmentOptions{};
  options.erode_mask_metres = 0.003;
  CHECK(c3po::ErosionPixels(mixed, mask, c3po::PinholeCamera{1067.0, 1067.0, 40.0, 30.0}, options) ==
        static_cast<int>(std::round(1067.0 * 0.003 / 0.3)));
}

TEST_CASE("COCO RLE: compressed == uncompressed == brute-force pixels (column-major runs)") {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const int w = 1 + static_cast<int>(seed * 7 % 31), h = 1 + static_cast<int>(seed * 5 % 23);
    const Mask mask = RandomMask(w, h, seed, seed % 3 == 0 ? 0.97 : 0.4);
    // Brute-force runs: column-major, starting with background.
    c3po::RleCounts brute;
    int current = 0;
    std::int64_t run = 0;
    for (int u = 0; u < w; ++u) {
      for (int v = 0; v < h; ++v) {
        const int value = mask.at(u, v);
        if (value != current) { brute.push_back(run); run = 0; current = value; }
        ++run;
      }
    }
    brute.push_back(run);
    const c3po::RleCounts counts = c3po::EncodeRle(mask);
    CHECK(counts == brute);
    const std::string compressed = c3po::RleString(counts);
    CHECK(c3po::ParseRleString(compressed, "d.json") == counts);
    CHECK(c3po::DecodeRle(h, w, counts, "d.json").inside == mask.inside);
    CHECK(c3po::DecodeRle(h, w, c3po::ParseRleString(compressed, "d.json"), "d.json").inside == mask.inside);
  }
  // Large runs use several 5-bit groups and the delta coding (negative deltas).
  const c3po::RleCounts big = {0, 100000, 3, 7, 250000, 1, 1};
  CHECK(c3po::ParseRleString(c3po::RleString(big), "d") == big);
  // Hand-encoded (maskApi.c rleToString): runs 0..2 as they are, run 3 as 5 - run 1 = 3.
  CHECK(c3po::RleString({1, 2, 1, 5}) == "1213");
  CHECK(c3po::ParseRleString("1213", "d") == c3po::RleCounts{1, 2, 1, 5});
}

TEST_CASE("malformed RLE is an InputError naming the file") {
  CHECK(InputErrorOf([] { c3po::ParseRleString("ab\x01", "d.json"); }).find("d.json: malformed RLE: character") == 0);
  CHECK(InputErrorOf([] { c3po::ParseRleString("1P", "d.json"); }).find("d.json: malformed RLE: string ends inside a run") == 0);
  CHECK(InputErrorOf([] { c3po::ParseRleString("oooooooooooooooo0", "d.json"); }).find("d.json: malformed RLE: run too long") == 0);
  CHECK(InputErrorOf([] { c3po::DecodeRle(4, 4, {3, 4}, "d.json"); }).find("d.json: malformed RLE: runs cover 7 pixels") == 0);
  CHECK(InputErrorOf([] { c3po::DecodeRle(4, 4, {3, 40}, "d.json"); }).find("d.json: malformed RLE: runs cover more") == 0);
  CHECK(InputErrorOf([] { c3po::DecodeRle(4, 4, {3, -1, 14}, "d.json"); }).find("d.json: malformed RLE: negative run") == 0);
  CHECK(InputErrorOf([] { c3po::DecodeRle(0, 4, {}, "d.json"); }).find("d.json: malformed RLE: bad size") == 0);
}

TEST_CASE("camera JSON: cam_K, BOP camera.json, one-entry scene_camera.json, --intrinsics, errors") {
  const auto k = c3po::ParseCameraJson(R"({"cam_K": [600, 0, 320.5, 0, 610, 240, 0, 0, 1], "depth_scale": 0.1})", "c.json");
  CHECK(k.K.fx == 600);
  CHECK(k.K.fy == 610);
  CHECK(k.K.cx == 320.5);
  CHECK(k.K.cy == 240);
  CHECK(k.depth_scale == 0.1);
  const auto bop = c3po::ParseCameraJson(R"({"cx": 1, "cy": 2, "fx": 3, "fy": 4, "width": 640, "height": 480, "depth_scale": 1.0})", "camera.json");
  CHECK((bop.K.fx == 3 && bop.K.fy == 4 && bop.K.cx == 1 && bop.K.cy == 2));
  const auto scene = c3po::ParseCameraJson(R"({"7": {"cam_K": [1, 0, 2, 0, 3, 4, 0, 0, 1], "depth_scale": 0.5}})", "s.json");
  CHECK(scene.depth_scale == 0.5);
  CHECK(c3po::ParseCameraJson(R"({"cam_K": [1, 0, 2, 0, 3, 4, 0, 0, 1]})", "c.json", 2.0).depth_scale == 2.0);
  const auto intrinsics = c3po::CameraFromIntrinsics("500,501,300,200", 0.1);
  CHECK((intrinsics.K.fx == 500 && intrinsics.K.cy == 200 && intrinsics.depth_scale == 0.1));

  CHECK(InputErrorOf([] { c3po::ParseCameraJson(R"({"depth_scale": 1})", "c.json"); }) == "c.json: cam_K: missing (nor fx, fy, cx, cy)");
  CHECK(InputErrorOf([] { c3po::ParseCameraJson(R"({"cam_K": [1, 0, 2, 0, 3, 4, 0, 0, 1]})", "c.json"); }) ==
        "c.json: depth_scale: missing (give --depth-scale S)");
  CHECK(InputErrorOf([] { c3po::ParseCameraJson(R"({"cam_K": [1, 0, 2, 0, 3, 4, 0, 0, 1], "depth_scale": 0})", "c.json"); })
            .find("c.json: depth_scale must be a positive number") == 0);
  CHECK(InputErrorOf([] { c3po::ParseCameraJson(R"({"cam_K": [1, 0, 2, 0, 3, 4, 0, 0, 1], "depth_scale": -1})", "c.json"); })
            .find("c.json: depth_scale must be a positive number") == 0);
  CHECK(InputErrorOf([] { c3po::ParseCameraJson(R"({"cam_K": [1, 0, 2, 0, 3, 4], "depth_scale": 1})", "c.json"); }) ==
        "c.json: cam_K: expected 9 numbers (row-major 3x3)");
  CHECK(InputErrorOf([] { c3po::ParseCameraJson(R"({"cam_K": [1, 0.5, 2, 0, 3, 4, 0, 0, 1], "depth_scale": 1})", "c.json"); })
            .find("c.json: cam_K: expected [fx, 0, cx, 0, fy, cy, 0, 0, 1]") == 0);
  CHECK(InputErrorOf([] { c3po::ParseCameraJson(R"({"cam_K": [-1, 0, 2, 0, 3, 4, 0, 0, 1], "depth_scale": 1})", "c.json"); })
            .find("c.json: focal lengths must be positive") == 0);
  CHECK(InputErrorOf([] { c3po::ParseCameraJson(R"({"1": {}, "2": {}})", "s.json"); }).find("s.json: a scene_camera.json of 2 images") == 0);
  // --im-id picks one entry of a scene_camera.json of several images.
  const std::string two = R"({"3": {"cam_K": [1, 0, 2, 0, 3, 4, 0, 0, 1], "depth_scale": 0.5},
                              "4": {"cam_K": [5, 0, 6, 0, 7, 8, 0, 0, 1], "depth_scale": 0.25}})";
  const auto four = c3po::ParseCameraJson(two, "s.json", std::nullopt, 4);
  CHECK((four.K.fx == 5 && four.K.fy == 7 && four.K.cx == 6 && four.K.cy == 8 && four.depth_scale == 0.25));
  const auto three = c3po::ParseCameraJson(two, "s.json", 2.0, 3);
  CHECK((three.K.fx == 1 && three.depth_scale == 2.0));
  CHECK(InputErrorOf([&] { c3po::ParseCameraJson(two, "s.json"); }).find("s.json: a scene_camera.json of 2 images; give --im-id") == 0);
  CHECK(InputErrorOf([&] { c3po::ParseCameraJson(two, "s.json", std::nullopt, 5); }).find("s.json: --im-id 5: no such image") == 0);
  CHECK(InputErrorOf([&] { c3po::ParseCameraJson(two, "s.json", std::nullopt, -3); }).find("s.json: --im-id -3: no such image") == 0);
  // A single camera serves every image: --im-id has nothing to pick.
  CHECK(c3po::ParseCameraJson(R"({"cam_K": [1, 0, 2, 0, 3, 4, 0, 0, 1], "depth_scale": 0.1})", "c.json", std::nullopt, 9).K.fx == 1);
  CHECK(InputErrorOf([] { c3po::ParseCameraJson("{", "c.json"); }).find("c.json: not valid JSON") == 0);
  CHECK(InputErrorOf([] { c3po::CameraFromIntrinsics("1,2,3", 1.0); }) == "--intrinsics: expected 4 numbers fx,fy,cx,cy");
  CHECK(InputErrorOf([] { c3po::CameraFromIntrinsics("1,2,3,4", 0.0); }).find("--intrinsics/--depth-scale: depth_scale must be") == 0);
}

TEST_CASE(".npy depth: C and Fortran order, float64, strict header and size") {
  DepthImage depth{3, 2, {0.5f, 0.0f, 1.5f, 2.0f, 2.5f, 3.0f}};
  const std::string npy = c3po::EncodeNpyDepth(depth);
  CHECK(c3po::ParseNpyDepth(npy, "d.npy").z == depth.z);
  // Hand-built Fortran-order float64 file of the same image.
  std::string header = "{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3), }";
  while ((10 + header.size() + 1) % 16 != 0) header += ' ';
  header += '\n';
  std::string f64("\x93NUMPY\x01\x00", 8);
  f64 += static_cast<char>(header.size());
  f64 += '\0';
  f64 += header;
  for (int u = 0; u < 3; ++u) {
    for (int v = 0; v < 2; ++v) {
      double z = depth.at(u, v);
      if (u == 1 && v == 0) z = std::nan("");   // NaN = no measurement
      f64.append(reinterpret_cast<const char*>(&z), 8);
    }
  }
  CHECK(c3po::ParseNpyDepth(f64, "f.npy").z == depth.z);
  CHECK(InputErrorOf([&] { c3po::ParseNpyDepth(npy.substr(0, npy.size() - 4), "d.npy"); }).find("d.npy: .npy data holds") == 0);
  CHECK(InputErrorOf([] { c3po::ParseNpyDepth("PK\x03\x04", "d.npy"); }) == "d.npy: not a .npy file (bad magic)");
  std::string i16 = npy;
  i16.replace(i16.find("<f4"), 3, "<i2");
  CHECK(InputErrorOf([&] { c3po::ParseNpyDepth(i16, "d.npy"); }).find("d.npy: .npy dtype '<i2' is not float32") == 0);
  std::string three = npy;
  three.replace(three.find("(2, 3)"), 6, "(2,3,1)");
  CHECK(InputErrorOf([&] { c3po::ParseNpyDepth(three, "d.npy"); }).find("d.npy: .npy depth must have shape (H, W)") == 0);
  std::string no_tuple = npy;   // found by fuzz_npy: an empty shape value
  no_tuple.replace(no_tuple.find("(2, 3)"), 6, " ,(23)");
  CHECK(InputErrorOf([&] { c3po::ParseNpyDepth(no_tuple, "d.npy"); }) == "d.npy: .npy header: shape must be a tuple (H, W)");
  DepthImage negative{1, 1, {-1.0f}};
  CHECK(InputErrorOf([&] { c3po::ParseNpyDepth(c3po::EncodeNpyDepth(negative), "d.npy"); }) == "d.npy: negative or infinite depth in .npy");
}

TEST_CASE("depth PNG: value x depth_scale = mm, converted to metres, 8-bit depth refused") {
  c3po::test::TempDir dir("depth_png");
  c3po::Image png(2, 1, 16);
  png.pixels = {1000, 65535};
  c3po::WritePng(dir / "d.png", png);
  CHECK(c3po::ReadDepth(dir / "d.png", 1.0).z == std::vector<float>{1.0f, 65.535f});
  CHECK(c3po::ReadDepth(dir / "d.png", 0.1).z == std::vector<float>{0.1f, static_cast<float>(6.5535)});
  c3po::Image eight(2, 1, 8);
  c3po::WritePng(dir / "m.png", eight);
  CHECK(InputErrorOf([&] { c3po::ReadDepth(dir / "m.png", 1.0); }).find("8-bit PNG given as depth") != std::string::npos);
}

TEST_CASE("--shard K/N: disjoint contiguous parts whose concatenation is the whole, groups kept together") {
  std::vector<std::int64_t> keys = {5, 5, 5, 6, 7, 7, 9, 10, 10, 10, 11};   // 6 groups
  for (int n = 1; n <= 8; ++n) {
    std::vector<std::size_t> all;
    for (int k = 1; k <= n; ++k) {
      const auto part = c3po::ShardJobs(keys, {k, n});
      for (std::size_t i = 1; i < part.size(); ++i) CHECK(part[i] == part[i - 1] + 1);   // contiguous
      all.insert(all.end(), part.begin(), part.end());
    }
    REQUIRE(all.size() == keys.size());
    for (std::size_t i = 0; i < all.size(); ++i) CHECK(all[i] == i);
  }
  // A group never splits: with 2 parts of 6 groups the cut is after group 3 (key 7).
  CHECK(c3po::ShardJobs(keys, {1, 2}) == std::vector<std::size_t>{0, 1, 2, 3, 4, 5});
  CHECK(c3po::ParseShard("3/8").index == 3);
  CHECK(InputErrorOf([] { c3po::ParseShard("0/4"); }) == "--shard: '0/4': need 1 <= K <= N");
  CHECK(InputErrorOf([] { c3po::ParseShard("5/4"); }) == "--shard: '5/4': need 1 <= K <= N");
  CHECK(InputErrorOf([] { c3po::ParseShard("2"); }) == "--shard: '2' is not K/N (e.g. 3/8)");
  CHECK(InputErrorOf([] { c3po::MergeShardOutputs({{"a.csv", "scene_id,im_id,obj_id,score,R,t,time\n1,2,3,4,5,6,7\n"}, {"b.csv", "x\n"}}, true); }) ==
        "b.csv: line 1: not a BOP results CSV header");
  CHECK(c3po::MergeShardOutputs({{"a.csv", "scene_id,im_id,obj_id,score,R,t,time\n1\n"}, {"b.csv", "scene_id,im_id,obj_id,score,R,t,time\n2\n"}}, true) ==
        "scene_id,im_id,obj_id,score,R,t,time\n1\n2\n");
  CHECK(InputErrorOf([] { c3po::MergeShardOutputs({{"a.jsonl", "{}\nnope\n"}}, false); }) == "a.jsonl: line 2: not a JSON object");
}

TEST_CASE("the certificate's evidence: the same steps with its own erosion, the counts describe the cloud") {
  const int w = 40, h = 30;
  const DepthImage depth = BoxBeforeWall(w, h, 5);
  Mask mask{w, h, std::vector<std::uint8_t>(depth.z.size(), 0)};
  for (int v = 7; v < 24; ++v) for (int u = 9; u < 32; ++u) mask.inside[static_cast<std::size_t>(v) * w + u] = 1;
  for (int erode : {0, 1, 3}) {
    for (int evidence_erode : {-1, 0, 1, 2, 4}) {
      for (int max_points : {0, 60}) {
        CAPTURE(erode);
        CAPTURE(evidence_erode);
        CAPTURE(max_points);
        c3po::SegmentOptions options;
        options.erode_mask_metres = 0.0;
        options.min_eroded_fraction = 0.0;
        options.erode_mask = erode;
        options.evidence_erode_mask = evidence_erode;
        options.max_points = max_points;
        options.support_plane_distance = 0.0;
        // Oracles: single-erosion extractions with each radius.
        c3po::SegmentOptions core = options, judged = options;
        core.evidence_erode_mask = -1;
        const int judged_erode = evidence_erode < 0 ? erode : evidence_erode;   // -1: the cloud itself
        judged.erode_mask = judged_erode;
        judged.evidence_erode_mask = judged_erode;
        const c3po::SegmentCloud s = c3po::ExtractSegment(depth, mask, kCamera, options, "x");
        const c3po::SegmentCloud a = c3po::ExtractSegment(depth, mask, kCamera, core, "x");
        const c3po::SegmentCloud b = c3po::ExtractSegment(depth, mask, kCamera, judged, "x");
        CHECK(!a.evidence.has_value());
        CHECK(a.evidence_points == static_cast<std::size_t>(a.cloud.cols()));
        CHECK(s.cloud == a.cloud);
        CHECK(s.pixels == a.pixels);
        CHECK(s.no_depth == a.no_depth);
        CHECK(s.removed_by_erosion == a.removed_by_erosion);
        CHECK(s.removed_by_discontinuity == a.removed_by_discontinuity);
        CHECK(s.removed_by_subsampling == a.removed_by_subsampling);
        CHECK(s.evidence.has_value() == (judged_erode != erode));
        CHECK((s.evidence ? *s.evidence : s.cloud) == b.cloud);
        CHECK(s.evidence_points == static_cast<std::size_t>(b.cloud.cols()));
      }
    }
  }
}
