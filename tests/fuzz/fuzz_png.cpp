// libFuzzer target: c3po::DecodePng (libspng) on arbitrary bytes.
#include "c3po/base/error.hpp"
#include "c3po/io/png_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const c3po::Image image = c3po::DecodePng(c3po_fuzz::Bytes(data, size), "fuzz.png");
    if (image.pixels.size() != static_cast<std::size_t>(image.width) * image.height) std::abort();
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
