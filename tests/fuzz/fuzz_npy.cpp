// libFuzzer target: c3po::ParseNpyDepth on arbitrary bytes.
#include "c3po/io/camera_io.hpp"
#include "c3po/base/error.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const c3po::DepthImage depth = c3po::ParseNpyDepth(c3po_fuzz::Bytes(data, size), "fuzz.npy");
    if (depth.z.size() != static_cast<std::size_t>(depth.width) * depth.height) std::abort();
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
