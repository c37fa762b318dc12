// libFuzzer target: c3po::LoadMesh on arbitrary bytes; the first byte picks
// the file extension (.obj, .ply, .off, .stl: c3po's own readers), the rest is
// the file. Leak checks are on (assimp, which leaked, no longer reads these).
#include "c3po/base/error.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/io/mesh_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".obj", ".ply", ".off", ".stl"};
  const std::string name = std::string("mesh") + kExtensions[data[0] % 4];
  const std::string path = c3po_fuzz::WriteScratch(name, c3po_fuzz::Bytes(data + 1, size - 1));
  try {
    c3po::LoadMesh(path);
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
