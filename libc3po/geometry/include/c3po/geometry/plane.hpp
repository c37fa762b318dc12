#pragma once
// A plane in the camera frame: the table of a rendered scene
// (scene_render.hpp), the support plane found in a depth frame
// (io/support_plane.hpp).
#include <cmath>

#include "c3po/base/types.hpp"

namespace c3po {

// The plane {x : normal . x = offset} (normal of unit length).
struct Plane {
  Eigen::Vector3d normal = -Eigen::Vector3d::UnitZ();
  double offset = -1.0;
  // Positive on the side the normal points to.
  double Signed(const Eigen::Vector3d& x) const { return normal.dot(x) - offset; }
  double Distance(const Eigen::Vector3d& x) const { return std::abs(Signed(x)); }
};

}  // namespace c3po
