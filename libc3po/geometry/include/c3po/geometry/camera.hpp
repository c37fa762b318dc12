#pragma once
// Pinhole camera and back-projection of depth pixels (issue 15). The one
// pinhole model: render.hpp's CameraIntrinsics is this plus an image size.
// Pixel (u, v) is column u, row v, with integer coordinates at pixel centres
// (OpenCV / BOP convention: cam_K = [fx 0 cx; 0 fy cy; 0 0 1]). A pixel with
// depth z (along the optical axis) back-projects to the camera-frame point
//   x = (u - cx) z / fx,  y = (v - cy) z / fy,  z.
#include <string>
#include <vector>

#include "c3po/base/types.hpp"

namespace c3po {

struct PinholeCamera {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  // Throws InputError("where: ...") unless fx, fy > 0 and all are finite.
  void Check(const std::string& where) const;
  Eigen::Vector3d BackProject(double u, double v, double z) const {
    return {(u - cx) * z / fx, (v - cy) * z / fy, z};
  }
  // Inverse of BackProject for z > 0: pixel coordinates (u, v).
  Eigen::Vector2d Project(const Eigen::Vector3d& point) const {
    return {fx * point.x() / point.z() + cx, fy * point.y() / point.z() + cy};
  }
};

// A depth image in object units (metres; ObjectModel converts every mesh to
// metres on loading), row-major; 0 (or a non-finite value) = no measurement.
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<float> z;
  float at(int u, int v) const { return z[static_cast<std::size_t>(v) * width + u]; }
  static bool Valid(float depth) { return depth > 0.0f && depth < 1e30f; }  // false for NaN
};

// Metres per millimetre: depth values are millimetres x depth_scale (BOP).
inline constexpr double kMetresPerMillimetre = 1e-3;

}  // namespace c3po
