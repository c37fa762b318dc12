// Object File Format meshes (Geomview OFF): a header keyword (OFF, or COFF,
// NOFF, CNOFF, STOFF, ... whose extra per-vertex values are skipped), the
// counts "vertices faces [edges]" (on the header line or the next), then one
// vertex "x y z ..." per line and one face "n i1 ... in [colour]" per line.
// '#' starts a comment. The counts are never trusted for allocation.
// ModelNet's "OFF490 518 0" (count glued to the keyword) is read as well.
#include "c3po/base/error.hpp"
#include "cloud_io_internal.hpp"
#include "mesh_io_internal.hpp"

namespace c3po::mesh_detail {
namespace {

using cloud_detail::Quote;

class OffReader {
 public:
  OffReader(std::string_view bytes, const std::string& name) : reader_(bytes), name_(name) {}

  MeshData Read() {
    ReadHeader();
    for (std::uint64_t i = 0; i < vertex_count_; ++i) ReadVertex(i);
    triangles_.set_vertex_count(vertex_count_);
    for (std::uint64_t f = 0; f < face_count_; ++f) ReadFace(f);
    return {vertices_.Take(), triangles_.Take()};
  }

 private:
  [[noreturn]] void Fail(const std::string& problem) const {
    throw InputError(name_, "line " + std::to_string(reader_.line_number()) + ": " + problem);
  }

  // The next line with tokens (comments removed); false at the end.
  bool NextTokens() {
    std::string_view line;
    while (reader_.Next(&line)) {
      cloud_detail::SplitTokens(line.substr(0, line.find('#')), false, &tokens_);
      if (!tokens_.empty()) return true;
    }
    return false;
  }

  void ReadHeader() {
    if (!NextTokens()) throw InputError(name_, "empty file (no OFF header)");
    SplitGluedCount();
    const std::string_view keyword = tokens_[0];
    if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF") {
      Fail("not an OFF file (first word " + Quote(keyword) + ", expected OFF)");
    }
    if (keyword.find('4') != std::string_view::npos || keyword.find("nOFF") != std::string_view::npos) {
      Fail("only 3-D OFF files are supported, not " + Quote(keyword));
    }
    std::size_t first = 1;
    if (tokens_.size() > 1 && tokens_[1] == "BINARY") Fail("binary OFF is not supported");
    if (tokens_.size() == 1) {
      if (!NextTokens()) throw InputError(name_, "truncated: no vertex and face counts after the OFF header");
      first = 0;
    }
    if (tokens_.size() < first + 2 || !cloud_detail::ParseCount(tokens_[first], &vertex_count_) ||
        !cloud_detail::ParseCount(tokens_[first + 1], &face_count_)) {
      Fail("expected the counts 'vertices faces edges'");
    }
    if (vertex_count_ > kMaxMeshVertices) Fail("more vertices than a mesh can index");
  }

  // ModelNet's OFF files glue the vertex count to the keyword ("OFF490 518 0").
  void SplitGluedCount() {
    const std::string_view first = tokens_[0];
    if (first.size() > 3 && first.substr(0, 3) == "OFF" && first[3] >= '0' && first[3] <= '9') {
      tokens_[0] = first.substr(0, 3);
      tokens_.insert(tokens_.begin() + 1, first.substr(3));
    }
  }

  void ReadVertex(std::uint64_t i) {
    if (!NextTokens()) Truncated("vertices", vertex_count_, i);
    if (tokens_.size() < 3) Fail("vertex " + std::to_string(i) + " needs 3 coordinates");
    double xyz[3];
    const std::string problem = cloud_detail::ParseCoordinates(tokens_.data(), xyz);
    if (!problem.empty()) Fail(problem);
    vertices_.Add(xyz[0], xyz[1], xyz[2]);
  }

  void ReadFace(std::uint64_t f) {
    if (!NextTokens()) Truncated("faces", face_count_, f);
    std::uint64_t corners = 0;
    if (!cloud_detail::ParseCount(tokens_[0], &corners)) Fail("face " + std::to_string(f) + ": " + Quote(tokens_[0]) + " is not a vertex count");
    if (corners > tokens_.size() - 1) {
      Fail("face " + std::to_string(f) + " says " + std::to_string(corners) + " vertices, the line has " +
           std::to_string(tokens_.size() - 1) + " values");
    }
    triangles_.BeginPolygon();
    for (std::size_t k = 1; k <= corners; ++k) {
      std::uint64_t index = 0;
      if (!cloud_detail::ParseCount(tokens_[k], &index) || !triangles_.AddIndex(index)) {
        Fail("face " + std::to_string(f) + ": vertex index " + Quote(tokens_[k]) + " is not one of the " +
             std::to_string(vertex_count_) + " vertices");
      }
    }
    triangles_.EndPolygon();
  }

  [[noreturn]] void Truncated(const char* what, std::uint64_t expected, std::uint64_t found) const {
    throw InputError(name_, std::string("truncated: header says ") + std::to_string(expected) + " " + what +
                                ", file holds " + std::to_string(found));
  }

  cloud_detail::LineReader reader_;
  const std::string& name_;
  std::vector<std::string_view> tokens_;
  std::uint64_t vertex_count_ = 0;
  std::uint64_t face_count_ = 0;
  cloud_detail::PointCollector vertices_;
  TriangleCollector triangles_;
};

}  // namespace

MeshData ParseOffMesh(std::string_view bytes, const std::string& name) {
  return OffReader(bytes, name).Read();
}

}  // namespace c3po::mesh_detail
