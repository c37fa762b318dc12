// Mask -> point cloud with preprocessing (segment.hpp).
#include "c3po/io/segment.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "c3po/base/error.hpp"
#include "c3po/io/support_plane.hpp"

namespace c3po {

std::size_t Mask::Count() const {
  return static_cast<std::size_t>(std::count_if(inside.begin(), inside.end(), [](std::uint8_t m) { return m != 0; }));
}

Mask MaskFromImage(const Image& image, int label_id) {
  Mask mask{image.width, image.height, std::vector<std::uint8_t>(image.pixels.size())};
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    mask.inside[i] = label_id < 0 ? image.pixels[i] != 0 : image.pixels[i] == label_id;
  }
  return mask;
}

Mask ErodeMask(const Mask& mask, int k) {
  if (k < 0) throw std::invalid_argument("ErodeMask: negative k");
  if (k == 0) return mask;
  // Separable: a pixel survives when its row window and then its column
  // window of half-width k (clipped at the border) are all inside.
  const int w = mask.width, h = mask.height;
  std::vector<std::uint8_t> rows(mask.inside.size());
  for (int v = 0; v < h; ++v) {
    const std::uint8_t* in = mask.inside.data() + static_cast<std::size_t>(v) * w;
    // outside[u] prefix counts of pixels not in the mask
    std::vector<int> prefix(static_cast<std::size_t>(w) + 1, 0);
    for (int u = 0; u < w; ++u) prefix[u + 1] = prefix[u] + (in[u] == 0);
    for (int u = 0; u < w; ++u) {
      const int lo = std::max(0, u - k), hi = std::min(w - 1, u + k);
      rows[static_cast<std::size_t>(v) * w + u] = prefix[hi + 1] - prefix[lo] == 0;
    }
  }
  Mask out{w, h, std::vector<std::uint8_t>(mask.inside.size())};
  std::vector<int> prefix(static_cast<std::size_t>(h) + 1);
  for (int u = 0; u < w; ++u) {
    prefix[0] = 0;
    for (int v = 0; v < h; ++v) prefix[v + 1] = prefix[v] + (rows[static_cast<std::size_t>(v) * w + u] == 0);
    for (int v = 0; v < h; ++v) {
      const int lo = std::max(0, v - k), hi = std::min(h - 1, v + k);
      out.inside[static_cast<std::size_t>(v) * w + u] = prefix[hi + 1] - prefix[lo] == 0;
    }
  }
  return out;
}

std::vector<int> MaskDistance(const Mask& mask) {
  // Two chamfer passes with unit steps to all 8 neighbours: exact for the
  // chessboard metric.
  const int w = mask.width, h = mask.height;
  std::vector<int> d(mask.inside.size());
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = mask.inside[i] != 0 ? 0 : w + h;
  const auto at = [&](int u, int v) -> int& { return d[static_cast<std::size_t>(v) * w + u]; };
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      int& x = at(u, v);
      if (u > 0) x = std::min(x, at(u - 1, v) + 1);
      if (v > 0) {
        x = std::min(x, at(u, v - 1) + 1);
        if (u > 0) x = std::min(x, at(u - 1, v - 1) + 1);
        if (u + 1 < w) x = std::min(x, at(u + 1, v - 1) + 1);
      }
    }
  }
  for (int v = h - 1; v >= 0; --v) {
    for (int u = w - 1; u >= 0; --u) {
      int& x = at(u, v);
      if (u + 1 < w) x = std::min(x, at(u + 1, v) + 1);
      if (v + 1 < h) {
        x = std::min(x, at(u, v + 1) + 1);
        if (u + 1 < w) x = std::min(x, at(u + 1, v + 1) + 1);
        if (u > 0) x = std::min(x, at(u - 1, v + 1) + 1);
      }
    }
  }
  return d;
}

void SegmentOptions::Check() const {
  if (erode_mask < 0 || erode_mask > 1000) throw std::invalid_argument("erode_mask must be in [0, 1000]");
  if (!(std::isfinite(erode_mask_metres) && erode_mask_metres >= 0.0 && erode_mask_metres <= 1.0)) {
    throw std::invalid_argument("erode_mask_metres must be in [0, 1] m");
  }
  if (!(min_eroded_fraction >= 0.0 && min_eroded_fraction < 1.0)) {
    throw std::invalid_argument("min_eroded_fraction must be in [0, 1)");
  }
  if (evidence_erode_mask < -1 || evidence_erode_mask > 1000) {
    throw std::invalid_argument("evidence_erode_mask must be -1 (none) or in [0, 1000]");
  }
  if (!(max_relative_depth_step >= 0.0) || !std::isfinite(max_relative_depth_step)) {
    throw std::invalid_argument("max_relative_depth_step must be >= 0");
  }
  if (max_points < 0) throw std::invalid_argument("max_points must be >= 0");
  if (!(support_plane_distance >= 0.0) || !std::isfinite(support_plane_distance)) {
    throw std::invalid_argument("support_plane_distance must be >= 0");
  }
}

namespace {

// Step 3: does an 8-neighbour with depth differ by more than step x z?
bool OnDepthDiscontinuity(const DepthImage& depth, int u, int v, double step) {
  const double z = depth.at(u, v);
  const double limit = step * z;
  for (int dv = -1; dv <= 1; ++dv) {
    for (int du = -1; du <= 1; ++du) {
      const int nu = u + du, nv = v + dv;
      if ((du == 0 && dv == 0) || nu < 0 || nv < 0 || nu >= depth.width || nv >= depth.height) continue;
      const float zn = depth.at(nu, nv);
      if (DepthImage::Valid(zn) && std::abs(zn - z) > limit) return true;
    }
  }
  return false;
}

}  // namespace

int ErosionPixels(const DepthImage& depth, const Mask& mask, const PinholeCamera& camera, const SegmentOptions& options) {
  // A pixel survives erosion by k iff its chessboard distance to the nearest
  // in-image pixel outside the mask exceeds k: one distance transform of the
  // complement gives, for every k at once, how many pixels with depth remain.
  if (depth.width != mask.width || depth.height != mask.height) throw std::invalid_argument("ErosionPixels: sizes differ");
  Mask outside = mask;
  for (std::uint8_t& m : outside.inside) m = m == 0;
  const std::vector<int> depth_in = MaskDistance(outside);
  std::vector<float> z;
  std::vector<std::size_t> at_distance;   // pixels with depth by distance to the outside
  for (std::size_t i = 0; i < mask.inside.size(); ++i) {
    if (mask.inside[i] == 0 || !DepthImage::Valid(depth.z[i])) continue;
    z.push_back(depth.z[i]);
    const std::size_t d = static_cast<std::size_t>(std::min(depth_in[i], 1001));
    if (at_distance.size() <= d) at_distance.resize(d + 1, 0);
    ++at_distance[d];
  }
  if (z.empty()) return 0;
  int k = options.erode_mask;
  if (options.erode_mask_metres > 0.0) {
    const auto middle = z.begin() + static_cast<std::ptrdiff_t>(z.size() / 2);
    std::nth_element(z.begin(), middle, z.end());
    const double f = 0.5 * (camera.fx + camera.fy);
    k = static_cast<int>(std::min(1000.0, std::round(f * options.erode_mask_metres / static_cast<double>(*middle))));
  }
  if (options.min_eroded_fraction <= 0.0) return k;
  // kept(k) = pixels with depth at distance > k; lower k until it keeps the fraction.
  const double keep = options.min_eroded_fraction * static_cast<double>(z.size());
  std::vector<std::size_t> beyond(at_distance.size() + 1, 0);
  for (std::size_t d = at_distance.size(); d-- > 0;) beyond[d] = beyond[d + 1] + at_distance[d];
  const auto kept = [&](int radius) {
    const std::size_t first = static_cast<std::size_t>(radius) + 1;
    return first < beyond.size() ? beyond[first] : std::size_t{0};
  };
  while (k > 0 && static_cast<double>(kept(k)) < keep) --k;
  return k;
}

SegmentCloud ExtractSegment(const DepthImage& depth, const Mask& mask, const PinholeCamera& camera,
                            const SegmentOptions& options, const std::string& name) {
  options.Check();
  if (depth.width != mask.width || depth.height != mask.height) {
    throw InputError(name, "depth is " + std::to_string(depth.width) + " x " + std::to_string(depth.height) +
                               " but the mask is " + std::to_string(mask.width) + " x " + std::to_string(mask.height));
  }
  SegmentCloud result;
  result.depth = std::make_shared<const DepthImage>(depth);
  result.mask = std::make_shared<const Mask>(mask);
  result.camera = camera;
  result.erode_pixels = ErosionPixels(depth, mask, camera, options);
  const Mask eroded = ErodeMask(mask, result.erode_pixels);
  const bool own_evidence = options.evidence_erode_mask >= 0 && options.evidence_erode_mask != result.erode_pixels;
  const Mask evidence_eroded = own_evidence ? ErodeMask(mask, options.evidence_erode_mask) : Mask{};
  std::optional<SupportPlaneFit> support;
  if (options.support_plane_distance > 0.0) {
    support = FitSupportPlane(depth, mask, camera, options.support_plane_distance);
  }
  if (support) {
    result.support_plane = support->plane;
    result.support_plane_distance = options.support_plane_distance;
  }
  std::vector<Eigen::Vector3d> kept, evidence;
  std::vector<std::int32_t> kept_pixels;
  for (int v = 0; v < mask.height; ++v) {
    for (int u = 0; u < mask.width; ++u) {
      if (!mask.at(u, v)) continue;
      ++result.mask_pixels;
      const float z = depth.at(u, v);
      if (!DepthImage::Valid(z)) {
        ++result.no_depth;
        continue;
      }
      const bool in_core = eroded.at(u, v), in_evidence = own_evidence && evidence_eroded.at(u, v);
      if (!in_core) ++result.removed_by_erosion;   // the counts describe `cloud`
      if (!in_core && !in_evidence) continue;
      if (options.max_relative_depth_step > 0.0 && OnDepthDiscontinuity(depth, u, v, options.max_relative_depth_step)) {
        if (in_core) ++result.removed_by_discontinuity;
        continue;
      }
      const Eigen::Vector3d point = camera.BackProject(u, v, z);
      if (support && support->plane.Distance(point) <= options.support_plane_distance) {
        if (in_core) ++result.removed_by_plane;
        continue;
      }
      if (in_evidence) evidence.push_back(point);
      if (!in_core) continue;
      kept.push_back(point);
      kept_pixels.push_back(v * mask.width + u);
    }
  }
  const auto columns = [&](const std::vector<Eigen::Vector3d>& points) {
    PointSet all(3, static_cast<Eigen::Index>(points.size()));
    for (std::size_t i = 0; i < points.size(); ++i) all.col(static_cast<Eigen::Index>(i)) = points[i];
    return StridedColumns(all, options.max_points);
  };
  result.cloud = columns(kept);
  if (own_evidence) result.evidence = columns(evidence);
  result.evidence_points = static_cast<std::size_t>(result.evidence ? result.evidence->cols() : result.cloud.cols());
  // The same columns as StridedColumns: floor(j n / k).
  const std::size_t n = kept.size(), k = static_cast<std::size_t>(result.cloud.cols());
  result.pixels.resize(k);
  for (std::size_t j = 0; j < k; ++j) result.pixels[j] = kept_pixels[k == n ? j : j * n / k];
  result.removed_by_subsampling = kept.size() - static_cast<std::size_t>(result.cloud.cols());
  return result;
}

}  // namespace c3po

namespace c3po {

void RequireUsableSegment(const SegmentCloud& segment, const std::string& name) {
  const std::size_t with_depth = segment.mask_pixels - segment.no_depth;
  if (segment.removed_by_plane > 0 &&
      static_cast<double>(segment.removed_by_plane) > kMaxSupportPlaneFraction * static_cast<double>(with_depth)) {
    throw InputError(name, "the mask is mostly the support plane (" + std::to_string(segment.removed_by_plane) + " of " +
                               std::to_string(with_depth) +
                               " pixels with depth lie on the table's plane): it does not outline an object");
  }
  if (segment.cloud.cols() >= kMinSegmentPoints) return;
  if (segment.mask_pixels == 0) throw InputError(name, "mask has no pixels");
  if (segment.no_depth == segment.mask_pixels) {
    throw InputError(name, "no valid depth under the mask (" + std::to_string(segment.mask_pixels) + " pixels)");
  }
  throw InputError(name, "only " + std::to_string(segment.cloud.cols()) + " points left after preprocessing (" +
                             std::to_string(segment.mask_pixels) + " mask pixels, " + std::to_string(segment.no_depth) +
                             " without depth, " + std::to_string(segment.removed_by_erosion) + " eroded, " +
                             std::to_string(segment.removed_by_discontinuity) + " on depth edges, " +
                             std::to_string(segment.removed_by_plane) + " on the support plane)");
}

SegmentCloud LoadFrameSegment(const FrameInput& frame, const SegmentOptions& options) {
  const DepthImage depth = ReadDepth(frame.depth_path, frame.camera.depth_scale);
  const Mask mask = MaskFromImage(ReadPng(frame.mask_path), frame.label_id);
  if (depth.width != mask.width || depth.height != mask.height) {
    throw InputError(frame.mask_path, "mask is " + std::to_string(mask.width) + " x " + std::to_string(mask.height) +
                                          " but the depth image " + frame.depth_path + " is " +
                                          std::to_string(depth.width) + " x " + std::to_string(depth.height));
  }
  return ExtractSegment(depth, mask, frame.camera.K, options, frame.mask_path);
}

}  // namespace c3po
