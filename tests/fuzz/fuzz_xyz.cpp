// libFuzzer target: c3po::ParseCloud on arbitrary bytes as XYZ.
#include "c3po/base/error.hpp"
#include "c3po/io/cloud_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    c3po::ParseCloud(c3po_fuzz::Bytes(data, size), c3po::CloudFormat::kXyz, "fuzz.xyz");
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
