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
  // A pose within the tolerance shifts the image of the model by at most
  // r = border_pixels + f·τ/z pixels, so a pixel is a violation only when no
  // such shift explains it: its observed depth lies behind the FARTHEST
  // rendered depth among samples within r (at r and r/2 around it, all
  // covered: pixels near the silhouette's edge are not counted). Curved
  // surfaces and self-occlusion edges (a mug's rim over its inside) are
  // thereby explained, not excluded.
  for (const int pixel : renderer_->covered_pixels()) {
    const int u = pixel % w, v = pixel / w;
    const double z = renderer_->DepthAt(u, v);
    const int r = options_.border_pixels + static_cast<int>(std::ceil(focal * tolerance_ / std::max(z, 1e-3)));
    bool interior = true;
    double farthest = z;
    for (const int step : {r, (r + 1) / 2}) {
      for (int du = -step; du <= step && interior; du += step) {
        for (int dv = -step; dv <= step && interior; dv += step) {
          const int uu = u + du, vv = v + dv;
          interior = uu >= 0 && vv >= 0 && uu < w && vv < h && renderer_->TriangleAt(uu, vv) >= 0;
          if (interior) farthest = std::max(farthest, renderer_->DepthAt(uu, vv));
        }
      }
    }
    if (!interior) continue;
    ++result.silhouette;
    const float observed = depth.at(u, v);
    if (!DepthImage::Valid(observed)) continue;
    ++result.measured;
    if (observed > farthest + tolerance_) ++result.violations;
  }
  result.passed = result.violations <= options_.max_fraction * result.measured;
  return result;
}

std::optional<FreeSpaceTest> MakeFreeSpaceTest(const ObjectModel& object, const DepthView& view,
                                               const FreeSpaceOptions& options, double eps_oc) {
  std::optional<FreeSpaceTest> test;
  if (view.valid() && options.enabled) test.emplace(object, view, options, eps_oc);
  return test;
}

bool FreeSpaceTest::Passes(const Pose& scene_from_model, int* violations) const {
  const FreeSpace result = Check(scene_from_model);
  if (violations) *violations = result.violations;
  return result.passed;
}

}  // namespace c3po
