// libFuzzer target: c3po::ParseNpyDepth on arbitrary bytes, then the
// segmenter on the depth it gives (NaN, huge and negative depths included):
// the support-plane fit and every preprocessing count must hold.
#include <cstdlib>

#include "c3po/io/camera_io.hpp"
#include "c3po/io/segment.hpp"
#include "c3po/base/error.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const c3po::DepthImage depth = c3po::ParseNpyDepth(c3po_fuzz::Bytes(data, size), "fuzz.npy");
    if (depth.z.size() != static_cast<std::size_t>(depth.width) * depth.height) std::abort();
    if (depth.z.empty() || depth.z.size() > (1u << 16)) return 0;
    c3po::Mask mask{depth.width, depth.height, std::vector<std::uint8_t>(depth.z.size(), 0)};
    for (std::size_t i = 0; i < depth.z.size(); i += 3) mask.inside[i] = 1;
    const c3po::PinholeCamera camera{500.0, 500.0, depth.width / 2.0, depth.height / 2.0};
    c3po::SegmentOptions options;
    options.erode_mask_metres = 0.0;
    options.erode_mask = 1;
    const c3po::SegmentCloud s = c3po::ExtractSegment(depth, mask, camera, options, "fuzz.npy");
    if (s.mask_pixels != s.no_depth + s.removed_by_erosion + s.removed_by_discontinuity + s.removed_by_plane +
                             s.removed_by_subsampling + static_cast<std::size_t>(s.cloud.cols())) {
      std::abort();
    }
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
