// STL meshes, binary (80-byte header, uint32 triangle count, 50 bytes per
// triangle: normal, 3 float32 corners, uint16 attribute; little-endian) and
// ASCII (solid / facet / outer loop / vertex x y z / endloop / endfacet).
// STL repeats each corner per triangle; equal corners are merged into one
// vertex, so the mesh is indexed like every other format's.
#include <cstring>
#include <unordered_map>

#include "c3po/base/error.hpp"
#include "cloud_io_internal.hpp"
#include "mesh_io_internal.hpp"

namespace c3po::mesh_detail {
namespace {

constexpr std::size_t kHeaderBytes = 84;     // 80-byte comment + uint32 count
constexpr std::size_t kTriangleBytes = 50;   // 12 float32 + uint16

// Gives equal corners (bit for bit) one vertex index.
class CornerIndex {
 public:
  int IndexOf(double x, double y, double z) {
    Key key;
    const double xyz[3] = {x, y, z};
    std::memcpy(key.data(), xyz, sizeof xyz);
    const auto [it, inserted] = index_.emplace(key, static_cast<int>(vertices_.size()));
    if (inserted) vertices_.Add(x, y, z);
    return it->second;
  }
  std::size_t size() const { return vertices_.size(); }
  PointSet Take() const { return vertices_.Take(); }

 private:
  using Key = std::array<std::uint64_t, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      return std::hash<std::uint64_t>()(k[0] ^ (k[1] * 0x9E3779B97F4A7C15ull) ^ (k[2] * 0xC2B2AE3D27D4EB4Full));
    }
  };
  std::unordered_map<Key, int, KeyHash> index_;
  cloud_detail::PointCollector vertices_;
};

bool StartsWithSolid(std::string_view bytes) {
  const std::size_t start = bytes.find_first_not_of(" \t\r\n");
  return start != std::string_view::npos && bytes.substr(start, 5) == "solid";
}

std::uint32_t BinaryTriangleCount(std::string_view bytes) {
  std::uint32_t count = 0;
  for (int i = 3; i >= 0; --i) count = (count << 8) | static_cast<unsigned char>(bytes[80 + static_cast<std::size_t>(i)]);
  return count;
}

// Binary files may begin with "solid" too; their size then gives them away.
bool IsBinary(std::string_view bytes) {
  if (bytes.size() >= kHeaderBytes &&
      kHeaderBytes + kTriangleBytes * std::uint64_t{BinaryTriangleCount(bytes)} == bytes.size()) {
    return true;
  }
  return !StartsWithSolid(bytes);
}

MeshData ParseBinary(std::string_view bytes, const std::string& name) {
  if (bytes.size() < kHeaderBytes) {
    throw InputError(name, "not an STL file: " + std::to_string(bytes.size()) +
                               " bytes, neither 'solid ...' text nor an 84-byte binary header");
  }
  const std::uint32_t count = BinaryTriangleCount(bytes);
  const std::uint64_t fits = (bytes.size() - kHeaderBytes) / kTriangleBytes;
  if (count > fits) {
    throw InputError(name, "truncated binary STL: header says " + std::to_string(count) +
                               " triangles, file holds " + std::to_string(fits));
  }
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  CornerIndex corners;
  TriangleCollector triangles(kMaxMeshVertices);
  for (std::uint32_t t = 0; t < count; ++t) {
    const unsigned char* item = data + kHeaderBytes + t * kTriangleBytes + 12;   // after the normal
    triangles.BeginPolygon();
    for (int c = 0; c < 3; ++c) {
      double xyz[3];
      for (int k = 0; k < 3; ++k) {
        xyz[k] = cloud_detail::DecodeScalar(item + 12 * c + 4 * k, cloud_detail::Scalar::kFloat32, true);
      }
      if (!cloud_detail::AllFinite(xyz[0], xyz[1], xyz[2])) {
        throw InputError(name, "triangle " + std::to_string(t) + ": non-finite coordinate");
      }
      triangles.AddIndex(static_cast<std::uint64_t>(corners.IndexOf(xyz[0], xyz[1], xyz[2])));
    }
    triangles.EndPolygon();
  }
  return {corners.Take(), triangles.Take()};
}

MeshData ParseAscii(std::string_view bytes, const std::string& name) {
  cloud_detail::LineReader reader(bytes);
  std::vector<std::string_view> tokens;
  std::string_view line;
  CornerIndex corners;
  TriangleCollector triangles(kMaxMeshVertices);
  const auto fail = [&](const std::string& problem) {
    throw InputError(name, "line " + std::to_string(reader.line_number()) + ": " + problem);
  };
  while (reader.Next(&line)) {
    cloud_detail::SplitTokens(line, false, &tokens);
    if (tokens.empty()) continue;
    if (tokens[0] == "outer") triangles.BeginPolygon();
    if (tokens[0] == "endloop") triangles.EndPolygon();
    if (tokens[0] != "vertex") continue;
    if (tokens.size() != 4) fail("expected 'vertex x y z'");
    double xyz[3];
    const std::string problem = cloud_detail::ParseCoordinates(tokens.data() + 1, xyz);
    if (!problem.empty()) fail(problem);
    triangles.AddIndex(static_cast<std::uint64_t>(corners.IndexOf(xyz[0], xyz[1], xyz[2])));
  }
  return {corners.Take(), triangles.Take()};
}

}  // namespace

MeshData ParseStlMesh(std::string_view bytes, const std::string& name) {
  return IsBinary(bytes) ? ParseBinary(bytes, name) : ParseAscii(bytes, name);
}

}  // namespace c3po::mesh_detail
