// Free-space consistency of a pose with the depth frame (free_space.hpp).
#include "c3po/method/free_space.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>
#include <stdexcept>

namespace c3po {

void FreeSpaceOptions::Check() const {
  if (!(tolerance >= 0.0 && std::isfinite(tolerance))) throw std::invalid_argument("free-space tolerance must be >= 0");
  if (!(min_tolerance >= 0.0 && std::isfinite(min_tolerance))) {
    throw std::invalid_argument("free-space minimum tolerance must be >= 0");
  }
  if (!(max_fraction >= 0.0 && max_fraction < 1.0)) throw std::invalid_argument("free-space fraction must be in [0, 1)");
  if (!(accept_fraction >= 0.0 && accept_fraction <= max_fraction)) {
    throw std::invalid_argument("free-space acceptance fraction must be in [0, the free-space fraction]");
  }
  if (!(outside_mask_fraction >= 0.0 && outside_mask_fraction <= 1.0)) {
    throw std::invalid_argument("outside-mask fraction must be in [0, 1]");
  }
  if (!(uncovered_mask_fraction >= 0.0 && uncovered_mask_fraction <= 1.0)) {
    throw std::invalid_argument("uncovered-mask fraction must be in [0, 1]");
  }
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
  const bool mask_fits = view_.valid() && view_.mask && view_.mask->width == view_.depth->width &&
                         view_.mask->height == view_.depth->height;
  if (mask_fits) {
    mask_distance_ = MaskDistance(*view_.mask);
  }
}

namespace {

// A rendered pixel the test counts: where it is, and the depth behind which
// an observation is a violation (the farthest rendered depth among the
// samples at r and r/2 around it, plus the tolerance).
struct CountedPixel {
  int u, v;
  float z;      // the rendered depth
  float limit;
};

struct ShiftCount {
  int du = 0, dv = 0;
  int measured = 0, violations = 0;
  int seen_surface = 0, seen_outside_mask = 0;
};

// Pixels spanned by `length` metres at depth z (focal f in pixels), at most
// `limit` (the image's size: lying intrinsics cannot overflow the count).
int PixelsAcross(double focal, double length, double z, int limit) {
  const double pixels = std::ceil(focal * length / std::max(z, 1e-3));
  return pixels < limit ? static_cast<int>(pixels) : limit;
}

// The pixels of the rendered silhouette at least `border` pixels inside it
// (all samples at `border` covered), each with its violation limit (samples
// within r that are covered; an uncovered one is the silhouette's edge, which
// the image shift accounts for).
std::vector<CountedPixel> CountedPixels(const DepthRenderer& renderer, int w, int h, int border, double focal,
                                        double tolerance, double* nearest) {
  std::vector<CountedPixel> counted;
  *nearest = std::numeric_limits<double>::infinity();
  const auto covered = [&](int u, int v) { return u >= 0 && v >= 0 && u < w && v < h && renderer.TriangleAt(u, v) >= 0; };
  for (const int pixel : renderer.covered_pixels()) {
    const int u = pixel % w, v = pixel / w;
    const double z = renderer.DepthAt(u, v);
    *nearest = std::min(*nearest, z);
    bool interior = true;
    for (int du = -border; du <= border && interior; du += std::max(border, 1)) {
      for (int dv = -border; dv <= border && interior; dv += std::max(border, 1)) interior = covered(u + du, v + dv);
    }
    if (!interior) continue;
    const int r = border + PixelsAcross(focal, tolerance, z, std::max(w, h));
    double farthest = z;
    for (const int step : {std::max(r, 1), std::max((r + 1) / 2, 1)}) {
      for (int du = -step; du <= step; du += step) {
        for (int dv = -step; dv <= step; dv += step) {
          if (covered(u + du, v + dv)) farthest = std::max(farthest, renderer.DepthAt(u + du, v + dv));
        }
      }
    }
    counted.push_back({u, v, static_cast<float>(z), static_cast<float>(farthest + tolerance)});
  }
  return counted;
}

ShiftCount CountAtShift(const std::vector<CountedPixel>& counted, const DepthImage& depth, int du, int dv) {
  ShiftCount count;
  count.du = du;
  count.dv = dv;
  for (const CountedPixel& p : counted) {
    const int u = p.u + du, v = p.v + dv;
    if (u < 0 || v < 0 || u >= depth.width || v >= depth.height) continue;
    const float observed = depth.at(u, v);
    if (!DepthImage::Valid(observed)) continue;
    ++count.measured;
    if (observed > p.limit) ++count.violations;
  }
  return count;
}

// At the shift: the measured pixels whose observation lies on the rendered
// surface (within the tolerance in front, not behind the violation limit),
// and of them those more than `border` pixels from the mask.
void CountSeenOutsideMask(const std::vector<CountedPixel>& counted, const DepthImage& depth,
                          const std::vector<int>& mask_distance, int border, double tolerance, ShiftCount* count) {
  for (const CountedPixel& p : counted) {
    const int u = p.u + count->du, v = p.v + count->dv;
    if (u < 0 || v < 0 || u >= depth.width || v >= depth.height) continue;
    const float observed = depth.at(u, v);
    if (!DepthImage::Valid(observed) || observed > p.limit || observed < p.z - tolerance) continue;
    ++count->seen_surface;
    count->seen_outside_mask += mask_distance[static_cast<std::size_t>(v) * depth.width + u] > border;
  }
}

// The rendered silhouette as a mask, and the depth range it spans.
Mask RenderedSilhouette(const DepthRenderer& renderer, int w, int h, double* nearest, double* farthest) {
  Mask silhouette{w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h)};
  *nearest = std::numeric_limits<double>::infinity();
  *farthest = 0.0;
  for (const int pixel : renderer.covered_pixels()) {
    silhouette.inside[static_cast<std::size_t>(pixel)] = 1;
    const double z = renderer.DepthAt(pixel % w, pixel / w);
    *nearest = std::min(*nearest, z);
    *farthest = std::max(*farthest, z);
  }
  return silhouette;
}

// The mask's pixels whose observed depth lies within the rendered depth
// range ± tolerance (`at_depth`) and, of them, those more than `border`
// pixels from the silhouette moved by the shift (`uncovered`).
void CountUncoveredMask(const DepthRenderer& renderer, const Mask& mask, const DepthImage& depth, int du, int dv,
                        int border, double tolerance, int* at_depth, int* uncovered) {
  double nearest = 0.0, farthest = 0.0;
  const std::vector<int> distance =
      MaskDistance(RenderedSilhouette(renderer, depth.width, depth.height, &nearest, &farthest));
  *at_depth = *uncovered = 0;
  for (int v = 0; v < depth.height; ++v) {
    for (int u = 0; u < depth.width; ++u) {
      const float observed = depth.at(u, v);
      if (!mask.at(u, v) || !DepthImage::Valid(observed)) continue;
      if (observed < nearest - tolerance || observed > farthest + tolerance) continue;
      ++*at_depth;
      const int su = u - du, sv = v - dv;   // where the shifted silhouette's pixel came from
      const bool inside = su >= 0 && sv >= 0 && su < depth.width && sv < depth.height;
      *uncovered += !inside || distance[static_cast<std::size_t>(sv) * depth.width + su] > border;
    }
  }
}

// Violations beyond the allowed fraction (<= 0 passes): what the shift search minimises.
double Excess(const ShiftCount& c, double fraction) { return c.violations - fraction * c.measured; }

// Model sample points more than `margin` beyond the support plane whose
// pixel sees the plane (observed point within `distance` of it).
int CountThroughSupport(const PointSet& sample, const Pose& camera_from_model, const DepthImage& depth,
                        const PinholeCamera& camera, const Plane& plane, double distance, double margin) {
  int count = 0;
  for (Eigen::Index j = 0; j < sample.cols(); ++j) {
    const Eigen::Vector3d x = camera_from_model.R * sample.col(j) + camera_from_model.t;
    if (!(plane.Signed(x) < -margin) || !(x.z() > 0.0)) continue;
    const Eigen::Vector2d uv = camera.Project(x);
    if (!uv.allFinite() || uv.x() < -1.0 || uv.y() < -1.0 || uv.x() > depth.width || uv.y() > depth.height) continue;
    const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
    if (u < 0 || v < 0 || u >= depth.width || v >= depth.height) continue;
    const float observed = depth.at(u, v);
    if (!DepthImage::Valid(observed)) continue;
    count += plane.Distance(camera.BackProject(u, v, observed)) <= distance;
  }
  return count;
}

}  // namespace

FreeSpace FreeSpaceTest::Check(const Pose& camera_from_model) const {
  FreeSpace result = Evaluate(camera_from_model, options_.accept_fraction);
  if (!result.checked || mask_distance_.empty()) return result;
  // The estimate only (free_space.hpp "The mask").
  result.mask_checked = true;
  result.mask_limit = options_.outside_mask_fraction;
  result.mask_passed = !(result.seen_outside_mask > options_.outside_mask_fraction * result.measured);
  // The converse: the mask's surface the pose does not cover (free_space.hpp).
  renderer_->Render(object_.mesh(), camera_from_model);
  CountUncoveredMask(*renderer_, *view_.mask, *view_.depth, result.shift_u, result.shift_v, options_.border_pixels,
                     tolerance_, &result.mask_at_depth, &result.mask_uncovered);
  result.uncovered_limit = options_.uncovered_mask_fraction;
  result.uncovered_passed = !(result.mask_uncovered > options_.uncovered_mask_fraction * result.mask_at_depth);
  result.passed = result.passed && result.mask_passed && result.uncovered_passed;
  return result;
}

FreeSpace FreeSpaceTest::Evaluate(const Pose& camera_from_model, double limit) const {
  FreeSpace result = CheckSilhouette(camera_from_model, limit);
  if (!result.checked || !view_.support) return result;
  // The table is solid where it is seen (free_space.hpp "Support").
  const PointSet& sample = object_.sample();
  result.support_checked = true;
  result.support_points = static_cast<int>(sample.cols());
  result.through_support = CountThroughSupport(sample, camera_from_model, *view_.depth, view_.camera, *view_.support,
                                               view_.support_distance, tolerance_ + view_.support_distance);
  result.support_passed = !(result.through_support > limit * result.support_points);
  result.passed = result.passed && result.support_passed;
  return result;
}

FreeSpace FreeSpaceTest::CheckSilhouette(const Pose& camera_from_model, double limit) const {
  FreeSpace result;
  result.tolerance = tolerance_;
  result.limit = limit;
  if (!renderer_ || !options_.enabled) return result;
  result.checked = true;
  renderer_->Render(object_.mesh(), camera_from_model);
  const DepthImage& depth = *view_.depth;
  const double focal = std::max(view_.camera.fx, view_.camera.fy);
  double nearest = 0.0;
  const std::vector<CountedPixel> counted =
      CountedPixels(*renderer_, depth.width, depth.height, options_.border_pixels, focal, tolerance_, &nearest);
  result.silhouette = static_cast<int>(counted.size());
  if (counted.empty()) return result;
  // A pose within τ of one that explains the frame moves the model's image
  // by at most R = f·τ/z_nearest pixels, all of it together: the test is
  // passed when SOME shift of the whole silhouette within R explains the
  // frame. Search: a grid of step g = ⌈R/4⌉ over [-R, R]² (0 included), then
  // a compass search around the best with steps halving down to one pixel.
  const int reach = PixelsAcross(focal, tolerance_, nearest, std::max(depth.width, depth.height));
  ShiftCount best = CountAtShift(counted, depth, 0, 0);
  // Ties go to the smaller shift (the evidence then says how far the pose is off, not where a tie fell).
  const auto better = [&](const ShiftCount& a, const ShiftCount& b) {
    const double ea = Excess(a, limit), eb = Excess(b, limit);
    return ea < eb || (ea == eb && std::abs(a.du) + std::abs(a.dv) < std::abs(b.du) + std::abs(b.dv));
  };
  const auto consider = [&](int du, int dv) {
    if ((du == 0 && dv == 0) || std::max(std::abs(du), std::abs(dv)) > reach) return;
    const ShiftCount c = CountAtShift(counted, depth, du, dv);
    if (better(c, best)) best = c;
  };
  int step = std::max(1, (reach + 3) / 4);
  const int cells = (reach + step - 1) / step;
  for (int i = -cells; i <= cells; ++i) {
    for (int k = -cells; k <= cells; ++k) consider(std::clamp(i * step, -reach, reach), std::clamp(k * step, -reach, reach));
  }
  // Compass search: at each step, move to the best of the 8 neighbours until
  // none is better (at most R moves), then halve the step.
  while (step > 1) {
    step = (step + 1) / 2;
    for (int moves = 0; moves <= reach; ++moves) {
      const int cu = best.du, cv = best.dv;
      for (int du = -step; du <= step; du += step) {
        for (int dv = -step; dv <= step; dv += step) consider(cu + du, cv + dv);
      }
      if (best.du == cu && best.dv == cv) break;
    }
  }
  if (!mask_distance_.empty()) {
    // At the best shift the silhouette is aligned with the frame already.
    CountSeenOutsideMask(counted, depth, mask_distance_, options_.border_pixels, tolerance_, &best);
  }
  result.seen_surface = best.seen_surface;
  result.seen_outside_mask = best.seen_outside_mask;
  result.measured = best.measured;
  result.violations = best.violations;
  result.shift_u = best.du;
  result.shift_v = best.dv;
  result.reach = reach;
  result.silhouette_passed = Excess(best, limit) <= 0.0;
  result.passed = result.silhouette_passed;
  return result;
}

std::optional<FreeSpaceTest> MakeFreeSpaceTest(const ObjectModel& object, const DepthView& view,
                                               const FreeSpaceOptions& options, double eps_oc) {
  std::optional<FreeSpaceTest> test;
  if (view.valid() && options.enabled) test.emplace(object, view, options, eps_oc);
  return test;
}

bool FreeSpaceTest::Passes(const Pose& scene_from_model, int* violations) const {
  const FreeSpace result = Evaluate(scene_from_model, options_.max_fraction);
  if (violations) *violations = result.violations;
  return result.passed;
}

}  // namespace c3po
