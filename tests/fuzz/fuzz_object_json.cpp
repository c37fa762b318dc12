// libFuzzer target: c3po::ReadObjectSpec on arbitrary bytes (no parse-from-
// string entry point exists, so the bytes go through a scratch file). A valid
// cube.obj sits next to it so that well-formed JSON reaches the mesh checks.
#include "c3po/base/error.hpp"
#include "c3po/object/object_io.hpp"
#include "fuzz_common.hpp"

namespace {
const char kCubeObj[] =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
    "f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\n"
    "f 3 7 4\nf 4 7 8\nf 1 5 3\nf 3 5 7\nf 2 4 6\nf 4 8 6\n";
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string mesh = c3po_fuzz::WriteScratch("cube.obj", kCubeObj);
  (void)mesh;
  const std::string path = c3po_fuzz::WriteScratch("object.json", c3po_fuzz::Bytes(data, size));
  try {
    c3po::ReadObjectSpec(path);
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
