#pragma once
// Sensor artefacts of structured-light / time-of-flight depth cameras, applied
// to a rendered depth image (metres, 0 = no measurement) so that every path
// that reads real depth images is tested on data with known truth. Each
// artefact is off unless asked; RealisticArtefacts() switches on a
// Kinect/Xtion-like set (docs/synth_bop.md gives the sources of the numbers).
//
// Order (each step sees the previous one's output):
//  1. flying pixels: a pixel at a depth discontinuity (a 4-neighbour whose
//     depth differs by more than `discontinuity` times the pixel's depth)
//     becomes, with probability `flying_fraction`, a mixture
//     z + U(0, 1) (z_neighbour - z) of its own depth and that of the neighbour
//     differing most (both sides of an edge, as real sensors do);
//  2. noise: z += sigma(z) N(0, 1), sigma(z) = noise_a + noise_b z^2 (the
//     axial noise model of Nguyen, Izadi and Lovell 2012, without its offset);
//  3. disparity quantisation: 1/z rounded to a multiple of `quantisation`, so
//     the depth step grows as quantisation * z^2;
//  4. holes: each valid pixel dropped with probability `dropout`, plus
//     `hole_blobs` discs of radius U(1, hole_blob_radius) pixels centred on
//     random pixels of `blob_centres` (the objects), set to 0.
// Mask bleeding (BleedMask) dilates a visible mask by `bleed` pixels onto its
// surroundings, as a detector's mask does.
#include <cstdint>
#include <vector>

#include "c3po/base/random.hpp"

namespace c3po {

struct DepthArtefactOptions {
  double flying_fraction = 0.0;   // probability that a discontinuity pixel flies
  double discontinuity = 0.02;    // relative depth jump that makes a discontinuity
  double noise_a = 0.0;           // metres
  double noise_b = 0.0;           // 1/metre (sigma = a + b z^2, z in metres)
  double quantisation = 0.0;      // 1/metre: step of 1/z (depth step ~ q z^2)
  double dropout = 0.0;           // fraction of valid pixels dropped, in [0, 1)
  int hole_blobs = 0;             // per image
  double hole_blob_radius = 6.0;  // pixels (largest)
  int bleed = 0;                  // mask_visib dilated by this many pixels
  void Check() const;             // throws InputError("--flag: problem")
  bool AnyDepth() const;          // some step 1-4 changes depth
  double Sigma(double z) const { return noise_a + noise_b * z * z; }
};

// The preset `--artefacts realistic`: flying 0.3 at 2 % jumps, sigma(z) =
// 0.5 mm + 1.0 mm/m^2 z^2, quantisation 2.85e-3 / m, 2 % dropout, 2 blobs of
// up to 5 px, bleeding 2 px.
DepthArtefactOptions RealisticArtefacts();

// What the artefacts did to one image.
struct ArtefactCounts {
  long flying = 0;    // pixels turned into flying pixels
  long dropped = 0;   // valid pixels set to 0 (dropout and blobs)
  long bled = 0;      // mask pixels added by bleeding (BleedMask)
};

// Applies steps 1-4 in place to a width x height depth image in metres
// (row-major, 0 = no measurement). `blob_centres`: candidate centres of hole
// blobs (pixel indices; no blobs when empty). Draws from `rng` in a fixed
// order, so the result is a pure function of (inputs, rng state).
ArtefactCounts ApplyDepthArtefacts(const DepthArtefactOptions& options, int width, int height,
                                   const std::vector<int>& blob_centres,
                                   std::vector<double>* depth, Rng& rng);

// Dilation of `mask` (width x height, non-zero = in) by a disc of radius
// `pixels` (Euclidean, pixel centres): the added pixels get `value`. Returns
// how many pixels were added.
long BleedMask(int width, int height, int pixels, std::vector<std::uint8_t>* mask,
               std::uint8_t value = 255);

}  // namespace c3po
