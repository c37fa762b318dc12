// Depth artefacts: measured noise std vs sigma(z), quantisation levels, hole
// fraction and blob extent, flying pixels only at discontinuities and between
// the two depths, bleeding against a brute-force dilation, determinism,
// option checks.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "c3po/synth/depth_artefacts.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"

namespace {

constexpr int kW = 400, kH = 300;

// Left half at z_left, right half at z_right (metres).
std::vector<double> StepImage(double z_left, double z_right) {
  std::vector<double> depth(static_cast<std::size_t>(kW) * kH);
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) depth[static_cast<std::size_t>(v) * kW + u] = u < kW / 2 ? z_left : z_right;
  }
  return depth;
}

}  // namespace

TEST_CASE("Depth noise: measured std matches sigma(z) = a + b z^2 at two depths") {
  c3po::DepthArtefactOptions options;
  options.noise_a = 0.5e-3;
  options.noise_b = 1.5e-3;
  std::vector<double> depth = StepImage(1.0, 2.5);
  c3po::Rng rng(3);
  c3po::ApplyDepthArtefacts(options, kW, kH, {}, &depth, rng);
  for (const double z : {1.0, 2.5}) {
    double sum = 0.0, sum2 = 0.0;
    long n = 0;
    for (int v = 0; v < kH; ++v) {
      for (int u = (z == 1.0 ? 0 : kW / 2); u < (z == 1.0 ? kW / 2 : kW); ++u) {
        const double e = depth[static_cast<std::size_t>(v) * kW + u] - z;
        sum += e;
        sum2 += e * e;
        ++n;
      }
    }
    const double mean = sum / n, std = std::sqrt(sum2 / n - mean * mean);
    const double sigma = options.noise_a + options.noise_b * z * z;
    CHECK(std::abs(mean) < 5.0 * sigma / std::sqrt(static_cast<double>(n)));
    CHECK(std == doctest::Approx(sigma).epsilon(0.03));   // 60000 samples: ~0.3 % standard error
  }
}

TEST_CASE("Disparity quantisation: 1/z on multiples of q, error within half a step") {
  c3po::DepthArtefactOptions options;
  options.quantisation = 2.85e-3;
  std::vector<double> depth(10000);
  c3po::Rng draw(5);
  for (double& z : depth) z = draw.Uniform(0.3, 4.0);
  const std::vector<double> clean = depth;
  c3po::Rng rng(6);
  c3po::ApplyDepthArtefacts(options, 100, 100, {}, &depth, rng);
  std::vector<double> levels;
  for (std::size_t i = 0; i < depth.size(); ++i) {
    const double k = 1.0 / (depth[i] * options.quantisation);
    CHECK(std::abs(k - std::round(k)) < 1e-6);
    CHECK(std::abs(1.0 / depth[i] - 1.0 / clean[i]) <= 0.5 * options.quantisation * (1 + 1e-9));
    levels.push_back(depth[i]);
  }
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  CHECK(levels.size() < 1000);   // far fewer distinct depths than pixels
  // The depth step grows as q z^2: about 2.85 mm at 1 m, 45.6 mm at 4 m.
  const double at_one = 1.0 / (std::round(1.0 / options.quantisation) * options.quantisation);
  const double next = 1.0 / ((std::round(1.0 / options.quantisation) - 1) * options.quantisation);
  CHECK(next - at_one == doctest::Approx(2.85e-3).epsilon(0.01));
}

TEST_CASE("Holes: dropout fraction and blobs confined to their discs") {
  c3po::DepthArtefactOptions options;
  options.dropout = 0.05;
  std::vector<double> depth = StepImage(1.0, 1.0);
  depth[0] = 0.0;   // already invalid: not counted
  c3po::Rng rng(7);
  const c3po::ArtefactCounts counts = c3po::ApplyDepthArtefacts(options, kW, kH, {}, &depth, rng);
  const long zeros = std::count(depth.begin(), depth.end(), 0.0);
  CHECK(counts.dropped == zeros - 1);
  const double fraction = static_cast<double>(counts.dropped) / (kW * kH - 1);
  CHECK(fraction == doctest::Approx(0.05).epsilon(0.05));   // 120000 pixels: ~1.8 % relative error

  c3po::DepthArtefactOptions blobs;
  blobs.hole_blobs = 3;
  blobs.hole_blob_radius = 8.0;
  std::vector<double> image = StepImage(1.0, 1.0);
  const int centre = 150 * kW + 200;
  c3po::Rng blob_rng(8);
  const c3po::ArtefactCounts blob_counts = c3po::ApplyDepthArtefacts(blobs, kW, kH, {centre}, &image, blob_rng);
  CHECK(blob_counts.dropped > 0);
  long inside = 0;
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      if (image[static_cast<std::size_t>(v) * kW + u] != 0.0) continue;
      CHECK(std::hypot(u - 200, v - 150) <= 8.0);
      ++inside;
    }
  }
  CHECK(inside == blob_counts.dropped);
  // No candidate centres: no blobs.
  std::vector<double> untouched = StepImage(1.0, 1.0);
  c3po::Rng none_rng(8);
  CHECK(c3po::ApplyDepthArtefacts(blobs, kW, kH, {}, &untouched, none_rng).dropped == 0);
}

TEST_CASE("Flying pixels: only next to a discontinuity, between the two depths") {
  c3po::DepthArtefactOptions options;
  options.flying_fraction = 0.5;
  options.discontinuity = 0.02;
  std::vector<double> depth = StepImage(1.0, 1.5);
  c3po::Rng rng(9);
  const c3po::ArtefactCounts counts = c3po::ApplyDepthArtefacts(options, kW, kH, {}, &depth, rng);
  long changed = 0;
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      const double z = depth[static_cast<std::size_t>(v) * kW + u];
      const double clean = u < kW / 2 ? 1.0 : 1.5;
      if (z == clean) continue;
      ++changed;
      CHECK((u == kW / 2 - 1 || u == kW / 2));   // the two columns at the step
      CHECK(z >= 1.0);
      CHECK(z <= 1.5);
    }
  }
  CHECK(changed == counts.flying);
  // 2 * kH edge pixels, each flying with probability 0.5.
  CHECK(static_cast<double>(changed) == doctest::Approx(kH).epsilon(0.2));
  // A 1 % step is no discontinuity at 2 %: nothing flies.
  std::vector<double> gentle = StepImage(1.0, 1.01);
  c3po::Rng gentle_rng(9);
  CHECK(c3po::ApplyDepthArtefacts(options, kW, kH, {}, &gentle, gentle_rng).flying == 0);
  // Neighbours without a measurement make no discontinuity.
  std::vector<double> holes = StepImage(1.0, 0.0);
  c3po::Rng holes_rng(9);
  CHECK(c3po::ApplyDepthArtefacts(options, kW, kH, {}, &holes, holes_rng).flying == 0);
}

TEST_CASE("BleedMask: equals brute-force Euclidean dilation, a rectangle grows by k pixels") {
  const int w = 60, h = 40;
  c3po::Rng rng(11);
  for (const int k : {1, 2, 3, 5}) {
    std::vector<std::uint8_t> mask(static_cast<std::size_t>(w) * h, 0);
    for (int i = 0; i < 30; ++i) mask[static_cast<std::size_t>(rng.UniformInt(w * h))] = 255;
    for (int v = 10; v < 20; ++v) for (int u = 5; u < 12; ++u) mask[static_cast<std::size_t>(v) * w + u] = 255;
    std::vector<std::uint8_t> expected = mask;
    long expected_added = 0;
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        if (mask[static_cast<std::size_t>(v) * w + u]) continue;
        bool near = false;
        for (int y = 0; y < h && !near; ++y) {
          for (int x = 0; x < w && !near; ++x) {
            near = mask[static_cast<std::size_t>(y) * w + x] && (x - u) * (x - u) + (y - v) * (y - v) <= k * k;
          }
        }
        if (near) {
          expected[static_cast<std::size_t>(v) * w + u] = 255;
          ++expected_added;
        }
      }
    }
    std::vector<std::uint8_t> bled = mask;
    CHECK(c3po::BleedMask(w, h, k, &bled) == expected_added);
    CHECK(bled == expected);
  }
  // Bleeding width: a rectangle's bounding box grows by exactly k per side.
  std::vector<std::uint8_t> rect(static_cast<std::size_t>(w) * h, 0);
  for (int v = 15; v < 25; ++v) for (int u = 20; u < 40; ++u) rect[static_cast<std::size_t>(v) * w + u] = 255;
  c3po::BleedMask(w, h, 3, &rect);
  int u0 = w, u1 = -1, v0 = h, v1 = -1;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (!rect[static_cast<std::size_t>(v) * w + u]) continue;
      u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
    }
  }
  CHECK(u0 == 17);
  CHECK(u1 == 42);
  CHECK(v0 == 12);
  CHECK(v1 == 27);
  // Degenerate: empty mask, radius 0, wrong size.
  std::vector<std::uint8_t> empty(static_cast<std::size_t>(w) * h, 0);
  CHECK(c3po::BleedMask(w, h, 4, &empty) == 0);
  CHECK(std::count(empty.begin(), empty.end(), 0) == w * h);
  CHECK(c3po::BleedMask(w, h, 0, &rect) == 0);
  std::vector<std::uint8_t> wrong(10, 0);
  CHECK_THROWS_AS(c3po::BleedMask(w, h, 1, &wrong), std::invalid_argument);
}

TEST_CASE("Artefacts: the same seed gives the same image, options are checked") {
  const c3po::DepthArtefactOptions realistic = c3po::RealisticArtefacts();
  CHECK(realistic.AnyDepth());
  std::vector<int> centres;
  for (int p = 0; p < kW * kH; p += 97) centres.push_back(p);
  std::vector<double> a = StepImage(0.8, 1.6), b = a, c = a;
  c3po::Rng ra(42), rb(42), rc(43);
  c3po::ApplyDepthArtefacts(realistic, kW, kH, centres, &a, ra);
  c3po::ApplyDepthArtefacts(realistic, kW, kH, centres, &b, rb);
  c3po::ApplyDepthArtefacts(realistic, kW, kH, centres, &c, rc);
  CHECK(a == b);
  CHECK(a != c);
  CHECK_FALSE(c3po::DepthArtefactOptions{}.AnyDepth());
  // No artefact: the image is untouched and no random number matters.
  std::vector<double> d = StepImage(0.8, 1.6);
  c3po::Rng rd(1);
  c3po::ApplyDepthArtefacts(c3po::DepthArtefactOptions{}, kW, kH, centres, &d, rd);
  CHECK(d == StepImage(0.8, 1.6));

  const auto refused = [](auto change) {
    c3po::DepthArtefactOptions options;
    change(options);
    CHECK_THROWS_AS(options.Check(), c3po::InputError);
  };
  refused([](auto& o) { o.flying_fraction = 1.5; });
  refused([](auto& o) { o.discontinuity = 0.0; });
  refused([](auto& o) { o.noise_a = -1.0; });
  refused([](auto& o) { o.noise_b = NAN; });
  refused([](auto& o) { o.quantisation = INFINITY; });
  refused([](auto& o) { o.dropout = 1.0; });
  refused([](auto& o) { o.hole_blobs = -1; });
  refused([](auto& o) { o.hole_blob_radius = 0.5; });
  refused([](auto& o) { o.bleed = 101; });
  std::vector<double> small(5, 1.0);
  c3po::Rng r(1);
  CHECK_THROWS_AS(c3po::ApplyDepthArtefacts(realistic, 3, 3, {}, &small, r), std::invalid_argument);
}
