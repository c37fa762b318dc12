// libFuzzer target: COCO RLE strings (ParseRleString) and their decoding to a
// mask whose size comes from the first two bytes; encoding the decoded mask
// must give back the runs (a round-trip check, aborting on mismatch).
#include "c3po/base/error.hpp"
#include "c3po/io/rle.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const int height = 1 + data[0] % 64, width = 1 + data[1] % 64;
  try {
    const c3po::RleCounts counts = c3po::ParseRleString(c3po_fuzz::Bytes(data + 2, size - 2), "fuzz.rle");
    const c3po::Mask mask = c3po::DecodeRle(height, width, counts, "fuzz.rle");
    // Runs of length 0 (other than the first) merge on re-encoding; compare pixels instead.
    if (c3po::DecodeRle(height, width, c3po::EncodeRle(mask), "again").inside != mask.inside) std::abort();
    if (c3po::ParseRleString(c3po::RleString(counts), "again") != counts) std::abort();
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
