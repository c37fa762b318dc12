#include "c3po/geometry/camera.hpp"

#include <cmath>

#include "c3po/base/error.hpp"

namespace c3po {

void PinholeCamera::Check(const std::string& where) const {
  if (!std::isfinite(fx) || !std::isfinite(fy) || !std::isfinite(cx) || !std::isfinite(cy)) {
    throw InputError(where, "camera intrinsics are not finite");
  }
  if (fx <= 0.0 || fy <= 0.0) {
    throw InputError(where, "focal lengths must be positive (fx = " + std::to_string(fx) +
                                ", fy = " + std::to_string(fy) + ")");
  }
}

}  // namespace c3po
