// Wavefront OBJ meshes: `v x y z [w | r g b]` vertices and `f` polygons whose
// corners are `v`, `v/vt`, `v//vn` or `v/vt/vn`, 1-based or negative
// (relative to the vertices so far). Everything else (vt, vn, o, g, s,
// mtllib, usemtl, l, p, ...) carries no surface and is skipped.
#include <charconv>

#include "c3po/base/error.hpp"
#include "cloud_io_internal.hpp"
#include "mesh_io_internal.hpp"

namespace c3po::mesh_detail {
namespace {

using cloud_detail::Quote;

class ObjReader {
 public:
  ObjReader(std::string_view bytes, const std::string& name) : reader_(bytes), name_(name) {}

  MeshData Read() {
    std::string_view line;
    while (reader_.Next(&line)) {
      cloud_detail::SplitTokens(line, false, &tokens_);
      if (tokens_.empty()) continue;
      if (tokens_[0] == "v") ReadVertex();
      if (tokens_[0] == "f") ReadFace();
    }
    return {vertices_.Take(), triangles_.Take()};
  }

 private:
  [[noreturn]] void Fail(const std::string& problem) const {
    throw InputError(name_, "line " + std::to_string(reader_.line_number()) + ": " + problem);
  }

  void ReadVertex() {
    if (tokens_.size() < 4) Fail("a vertex needs 3 coordinates ('v x y z')");
    double xyz[3];
    const std::string problem = cloud_detail::ParseCoordinates(tokens_.data() + 1, xyz);
    if (!problem.empty()) Fail(problem);
    if (vertices_.size() >= kMaxMeshVertices) Fail("more vertices than a mesh can index");
    vertices_.Add(xyz[0], xyz[1], xyz[2]);
    triangles_.set_vertex_count(vertices_.size());
  }

  void ReadFace() {
    triangles_.BeginPolygon();
    for (std::size_t k = 1; k < tokens_.size(); ++k) {
      const std::string_view corner = tokens_[k];
      const std::string_view position = corner.substr(0, corner.find('/'));
      long long index = 0;
      const auto result = std::from_chars(position.data(), position.data() + position.size(), index);
      if (result.ec != std::errc() || result.ptr != position.data() + position.size() || index == 0) {
        Fail("face corner " + Quote(corner) + " is not a vertex index");
      }
      // 1-based, or negative: -1 is the last vertex defined so far.
      const long long count = static_cast<long long>(vertices_.size());
      const long long zero_based = index > 0 ? index - 1 : count + index;
      if (zero_based < 0 || !triangles_.AddIndex(static_cast<std::uint64_t>(zero_based))) {
        Fail("face corner " + Quote(corner) + " is not one of the " + std::to_string(count) +
             " vertices defined so far");
      }
    }
    triangles_.EndPolygon();
  }

  cloud_detail::LineReader reader_;
  const std::string& name_;
  std::vector<std::string_view> tokens_;
  cloud_detail::PointCollector vertices_;
  TriangleCollector triangles_;
};

}  // namespace

MeshData ParseObjMesh(std::string_view bytes, const std::string& name) {
  return ObjReader(bytes, name).Read();
}

}  // namespace c3po::mesh_detail
