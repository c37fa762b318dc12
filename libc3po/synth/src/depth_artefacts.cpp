// Depth-sensor artefacts on rendered depth images (depth_artefacts.hpp).
#include "c3po/synth/depth_artefacts.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "c3po/base/error.hpp"

namespace c3po {
namespace {

bool Finite(double x) { return std::isfinite(x); }

// Step 1: flying pixels, judged on the depth before any artefact.
long AddFlyingPixels(const DepthArtefactOptions& options, int width, int height,
                     std::vector<double>* depth, Rng& rng) {
  const std::vector<double> clean = *depth;
  const int du[4] = {1, -1, 0, 0};
  const int dv[4] = {0, 0, 1, -1};
  long flying = 0;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const std::size_t p = static_cast<std::size_t>(v) * width + u;
      const double z = clean[p];
      if (z <= 0.0) continue;
      double jump = 0.0;   // signed difference to the neighbour differing most
      for (int k = 0; k < 4; ++k) {
        const int nu = u + du[k], nv = v + dv[k];
        if (nu < 0 || nv < 0 || nu >= width || nv >= height) continue;
        const double zn = clean[static_cast<std::size_t>(nv) * width + nu];
        if (zn <= 0.0) continue;
        if (std::abs(zn - z) > options.discontinuity * z && std::abs(zn - z) > std::abs(jump)) {
          jump = zn - z;
        }
      }
      if (jump == 0.0) continue;
      // Two draws per discontinuity pixel whether it flies or not.
      const bool flies = rng.Uniform() < options.flying_fraction;
      const double mix = rng.Uniform();
      if (!flies) continue;
      (*depth)[p] = z + mix * jump;
      ++flying;
    }
  }
  return flying;
}

}  // namespace

void DepthArtefactOptions::Check() const {
  if (!(flying_fraction >= 0.0 && flying_fraction <= 1.0)) {
    throw InputError("--flying-pixels: must be in [0, 1]");
  }
  if (!(discontinuity > 0.0) || !Finite(discontinuity)) {
    throw InputError("--discontinuity: must be a finite fraction > 0");
  }
  if (!(noise_a >= 0.0) || !Finite(noise_a) || !(noise_b >= 0.0) || !Finite(noise_b)) {
    throw InputError("--depth-noise: a and b must be finite and >= 0");
  }
  if (!(quantisation >= 0.0) || !Finite(quantisation)) {
    throw InputError("--quantisation: must be finite and >= 0");
  }
  if (!(dropout >= 0.0 && dropout < 1.0)) throw InputError("--holes: must be in [0, 1)");
  if (hole_blobs < 0 || hole_blobs > 10000) throw InputError("--hole-blobs: must be in [0, 10000]");
  if (!(hole_blob_radius >= 1.0 && hole_blob_radius <= 1000.0)) {
    throw InputError("--hole-blob-radius: must be in [1, 1000] pixels");
  }
  if (bleed < 0 || bleed > 100) throw InputError("--bleed: must be in [0, 100] pixels");
}

bool DepthArtefactOptions::AnyDepth() const {
  return flying_fraction > 0.0 || noise_a > 0.0 || noise_b > 0.0 || quantisation > 0.0 ||
         dropout > 0.0 || hole_blobs > 0;
}

DepthArtefactOptions RealisticArtefacts() {
  DepthArtefactOptions options;
  options.flying_fraction = 0.3;
  options.discontinuity = 0.02;
  options.noise_a = 0.5e-3;
  options.noise_b = 1.0e-3;
  options.quantisation = 2.85e-3;
  options.dropout = 0.02;
  options.hole_blobs = 2;
  options.hole_blob_radius = 5.0;
  options.bleed = 2;
  return options;
}

ArtefactCounts ApplyDepthArtefacts(const DepthArtefactOptions& options, int width, int height,
                                   const std::vector<int>& blob_centres,
                                   std::vector<double>* depth, Rng& rng) {
  options.Check();
  if (!depth || width < 0 || height < 0 ||
      depth->size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    throw std::invalid_argument("ApplyDepthArtefacts: depth is not a width x height image");
  }
  ArtefactCounts counts;
  if (options.flying_fraction > 0.0) counts.flying = AddFlyingPixels(options, width, height, depth, rng);
  if (options.noise_a > 0.0 || options.noise_b > 0.0) {
    for (double& z : *depth) {
      if (z <= 0.0) continue;
      const double noisy = z + options.Sigma(z) * rng.Normal();
      z = noisy > 0.0 ? noisy : 0.0;   // a sensor reports no negative depth
    }
  }
  if (options.quantisation > 0.0) {
    const double q = options.quantisation;
    for (double& z : *depth) {
      if (z <= 0.0) continue;
      const double level = std::round(1.0 / (z * q));   // 1/z = level * q
      z = level >= 1.0 ? 1.0 / (level * q) : 0.0;         // beyond the range: no measurement
    }
  }
  if (options.dropout > 0.0) {
    for (double& z : *depth) {
      if (z <= 0.0) continue;
      if (rng.Uniform() < options.dropout) {
        z = 0.0;
        ++counts.dropped;
      }
    }
  }
  if (options.hole_blobs > 0 && !blob_centres.empty()) {
    for (int b = 0; b < options.hole_blobs; ++b) {
      const int centre = blob_centres[static_cast<std::size_t>(
          rng.UniformInt(static_cast<int>(blob_centres.size())))];
      const double radius = rng.Uniform(1.0, options.hole_blob_radius);
      const int cu = centre % width, cv = centre / width;
      const int r = static_cast<int>(std::floor(radius));
      for (int v = std::max(0, cv - r); v <= std::min(height - 1, cv + r); ++v) {
        for (int u = std::max(0, cu - r); u <= std::min(width - 1, cu + r); ++u) {
          const double du = u - cu, dv = v - cv;
          if (du * du + dv * dv > radius * radius) continue;
          double& z = (*depth)[static_cast<std::size_t>(v) * width + u];
          if (z > 0.0) {
            z = 0.0;
            ++counts.dropped;
          }
        }
      }
    }
  }
  return counts;
}

namespace {

// Pixel rectangle [u0, u1] x [v0, v1]; empty when u1 < u0.
struct PixelBox {
  int u0, v0, u1, v1;
  int width() const { return u1 - u0 + 1; }
};

// The bounding box of the mask's non-zero pixels grown by `pixels`, within the image.
PixelBox GrownMaskBox(const std::vector<std::uint8_t>& mask, int width, int height, int pixels) {
  PixelBox box{width, height, -1, -1};
  for (int v = 0; v < height; ++v) {
    const std::uint8_t* row = mask.data() + static_cast<std::size_t>(v) * width;
    for (int u = 0; u < width; ++u) {
      if (!row[u]) continue;
      box.u0 = std::min(box.u0, u), box.u1 = std::max(box.u1, u);
      box.v0 = std::min(box.v0, v), box.v1 = std::max(box.v1, v);
    }
  }
  if (box.u1 < 0) return box;
  return {std::max(0, box.u0 - pixels), std::max(0, box.v0 - pixels), std::min(width - 1, box.u1 + pixels),
          std::min(height - 1, box.v1 + pixels)};
}

constexpr int kFar = 1 << 29;

// nearest[(v - v0) * box width + (u - u0)] = |u - the nearest mask column in row v| (kFar: none):
// a pass from the left and one from the right per row.
std::vector<int> NearestMaskColumn(const std::vector<std::uint8_t>& mask, int width, const PixelBox& box) {
  const auto in = [&](int u, int v) { return mask[static_cast<std::size_t>(v) * width + u] != 0; };
  std::vector<int> nearest(static_cast<std::size_t>(box.width()) * (box.v1 - box.v0 + 1), kFar);
  for (int v = box.v0; v <= box.v1; ++v) {
    int* row = nearest.data() + static_cast<std::size_t>(v - box.v0) * box.width();
    int last = -kFar;
    for (int u = box.u0; u <= box.u1; ++u) {
      if (in(u, v)) last = u;
      row[u - box.u0] = std::min(kFar, u - last);
    }
    last = 2 * kFar;
    for (int u = box.u1; u >= box.u0; --u) {
      if (in(u, v)) last = u;
      row[u - box.u0] = std::min(row[u - box.u0], last - u);
    }
  }
  return nearest;
}

// half_width[dv] = floor(sqrt(k^2 - dv^2)): the disc of radius k's half width at row offset dv.
std::vector<int> DiscHalfWidths(int k) {
  std::vector<int> half_width(static_cast<std::size_t>(k) + 1);
  for (int dv = 0; dv <= k; ++dv) {
    int w = 0;
    while ((w + 1) * (w + 1) + dv * dv <= k * k) ++w;
    half_width[static_cast<std::size_t>(dv)] = w;
  }
  return half_width;
}

}  // namespace

long BleedMask(int width, int height, int pixels, std::vector<std::uint8_t>* mask,
               std::uint8_t value) {
  if (!mask || width < 0 || height < 0 ||
      mask->size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    throw std::invalid_argument("BleedMask: mask is not a width x height image");
  }
  if (pixels < 0) throw std::invalid_argument("BleedMask: negative radius");
  if (pixels == 0 || value == 0) return 0;
  // Exact Euclidean dilation, row by row: (u, v) is within `pixels` of a mask
  // pixel iff for some row offset dv the nearest mask pixel in row v + dv is
  // within floor(sqrt(k^2 - dv^2)) columns. Only the mask's bounding box grown
  // by k can change.
  const PixelBox box = GrownMaskBox(*mask, width, height, pixels);
  if (box.u1 < box.u0) return 0;
  const std::vector<std::uint8_t> original = *mask;
  const std::vector<int> nearest = NearestMaskColumn(original, width, box);
  const std::vector<int> half_width = DiscHalfWidths(pixels);
  long added = 0;
  for (int v = box.v0; v <= box.v1; ++v) {
    for (int u = box.u0; u <= box.u1; ++u) {
      if (original[static_cast<std::size_t>(v) * width + u]) continue;
      for (int dv = -pixels; dv <= pixels; ++dv) {
        const int nv = v + dv;
        if (nv < box.v0 || nv > box.v1) continue;
        if (nearest[static_cast<std::size_t>(nv - box.v0) * box.width() + (u - box.u0)] <=
            half_width[static_cast<std::size_t>(std::abs(dv))]) {
          (*mask)[static_cast<std::size_t>(v) * width + u] = value;
          ++added;
          break;
        }
      }
    }
  }
  return added;
}

}  // namespace c3po
