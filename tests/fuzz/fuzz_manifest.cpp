// libFuzzer target: c3po::ParseManifestLine on one arbitrary line.
#include "c3po/base/error.hpp"
#include "c3po/io/dataset.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    c3po::ParseManifestLine(c3po_fuzz::Bytes(data, size), "fuzz/manifest.jsonl: line 1");
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
