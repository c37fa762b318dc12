// Free-space consistency of a pose with the depth frame (free_space.hpp).
#include "c3po/method/free_space.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace c3po {

void FreeSpaceOptions::Check() const {
  if (!(tolerance >= 0.0 && std::isfinite(tolerance))) throw std::invalid_argument("free-space tolerance must be >= 0");
  if (!(min_tolerance >= 0.0 && std::isfinite(min_tolerance))) {
    throw std::invalid_argument("free-space minimum tolerance must be >= 0");
  }
  if (!(max_fraction >= 0.0 && max_fraction < 1.0)) throw std::invalid_argument("free-space fraction must be in [0, 1)");
  if (border_pixels < 0 || border_pixels > 64) throw std::invalid_argument("free-space border must be in [0, 64] pixels");
}

FreeSpaceTest::FreeSpaceTest(const ObjectModel& object, DepthView view, const FreeSpaceOptions& options, double eps_oc)
    : object_(object), view_(std::move(view)), options_(options) {
  options_.Check();
  tolerance_ = options_.tolerance > 0.0 ? options_.tolerance : std::max(eps_oc, options_.min_tolerance);
  if (view_.valid()) {
    CameraIntrinsics camera;
    static_cast<PinholeCamera&>(camera) = view_.camera;
    camera.width = view_.depth->width;
    camera.height = view_.depth->height;
    renderer_ = std::make_unique<DepthRenderer>(camera);
  }
}

FreeSpace FreeSpaceTest::Check(const Pose& camera_from_model) const {
  FreeSpace result;
  result.tolerance = tolerance_;
  if (!renderer_ || !options_.enabled) return result;
  result.checked = true;
  renderer_->Render(object_.mesh(), camera_from_model);
  const DepthImage& depth = *view_.depth;
  const int w = depth.width, h = depth.height;
  const double focal = std::max(view_.camera.fx, view_.camera.fy);
  // A pixel is counted only on a smooth part of the rendered surface: the
  // samples at distances r and r/2 around it are covered and their rendered
  // depth is within the tolerance of its own. r = border_pixels + the image
  // shift of a tolerance-sized motion at this depth (f·τ/z): a pose within
  // the tolerance moves silhouette and self-occlusion edges by at most that.
  const auto smooth = [&](int u, int v, int du, int dv, double z) {
    if (u + du < 0 || v + dv < 0 || u + du >= w || v + dv >= h) return false;
    return renderer_->TriangleAt(u + du, v + dv) >= 0 && std::abs(renderer_->DepthAt(u + du, v + dv) - z) <= tolerance_;
  };
  for (const int pixel : renderer_->covered_pixels()) {
    const int u = pixel % w, v = pixel / w;
    const double z = renderer_->DepthAt(u, v);
    const int r = options_.border_pixels + static_cast<int>(std::ceil(focal * tolerance_ / std::max(z, 1e-3)));
    bool interior = true;
    for (const int step : {r, (r + 1) / 2}) {
      for (int du = -step; du <= step && interior; du += step) {
        for (int dv = -step; dv <= step && interior; dv += step) interior = smooth(u, v, du, dv, z);
      }
    }
    if (!interior) continue;
    ++result.silhouette;
    const float observed = depth.at(u, v);
    if (!DepthImage::Valid(observed)) continue;
    ++result.measured;
    if (observed > z + tolerance_) ++result.violations;
  }
  result.passed = result.violations <= options_.max_fraction * result.measured;
  return result;
}

bool FreeSpaceTest::Passes(const Pose& scene_from_model, int* violations) const {
  const FreeSpace result = Check(scene_from_model);
  if (violations) *violations = result.violations;
  return result.passed;
}

}  // namespace c3po
