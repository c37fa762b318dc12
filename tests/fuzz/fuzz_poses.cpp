// libFuzzer target: c3po::ParsePoseList (BOP results CSV and JSON lines).
#include "c3po/base/error.hpp"
#include "c3po/io/pose_list.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    c3po::ParsePoseList(c3po_fuzz::Bytes(data, size), "fuzz/poses");
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
