// c3po_make_objects OUT_DIR [NAME...]: writes the bundled objects (procedural
// meshes + object JSON) into OUT_DIR. The committed annotations/ files are the
// output of `c3po_make_objects annotations`; a test checks they are identical.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "c3po/object/procedural.hpp"

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    std::fprintf(stderr, "usage: c3po_make_objects OUT_DIR [NAME...]\nobjects:");
    for (const auto& name : c3po::BundledObjectNames()) std::fprintf(stderr, " %s", name.c_str());
    std::fprintf(stderr, "\n");
    return 2;
  }
  std::vector<std::string> names(argv + 2, argv + argc);
  if (names.empty()) names = c3po::BundledObjectNames();
  try {
    std::filesystem::create_directories(argv[1]);
    for (const auto& name : names) {
      const c3po::BundledObject object = c3po::MakeBundledObject(name);
      c3po::WriteBundledObject(object, argv[1]);
      std::printf("%s: %ld vertices, %ld triangles, %d keypoints, %zu indicator sets, d = %.4f m\n",
                  name.c_str(), static_cast<long>(object.mesh.vertices.cols()),
                  static_cast<long>(object.mesh.triangles.cols()), object.spec.num_keypoints(),
                  object.spec.indicator_sets.size(), object.mesh.Diameter());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "c3po_make_objects: %s\n", e.what());
    return 2;
  }
  return 0;
}
