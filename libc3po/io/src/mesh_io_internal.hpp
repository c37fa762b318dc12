#pragma once
// c3po's own mesh readers (PLY, OBJ, OFF, STL). Like the point-cloud readers
// they grow memory only with data actually present (a header's counts are
// never trusted), and every problem is an InputError naming the file (and the
// line for text formats). Private to libc3po; LoadMesh (mesh_io.cpp)
// dispatches on the extension. assimp reads only the other formats: the mesh
// fuzzer found its PLY path aborting and its OFF reader allocating tens of GB.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "c3po/base/types.hpp"

namespace c3po::mesh_detail {

// A mesh as read: every vertex of the file and its faces as triangles. The
// loader drops vertices no triangle uses.
struct MeshData {
  PointSet vertices;
  Eigen::Matrix3Xi triangles;
};

// Collects faces as triangles: the polygon (v0, v1, ..., vn-1) becomes the
// fan (v0, vk, vk+1), k = 1..n-2, as Open3D and assimp triangulate convex
// faces; faces of fewer than 3 vertices (points, edges) add nothing.
class TriangleCollector {
 public:
  explicit TriangleCollector(std::uint64_t vertex_count = 0) : vertex_count_(vertex_count) {}

  // Indices must name one of the first `count` vertices (OBJ: those so far).
  void set_vertex_count(std::uint64_t count) { vertex_count_ = count; }
  std::uint64_t vertex_count() const { return vertex_count_; }

  void BeginPolygon() { polygon_.clear(); }
  // False (and nothing added) when the index does not name a vertex.
  bool AddIndex(std::uint64_t index) {
    if (index >= vertex_count_) return false;
    polygon_.push_back(static_cast<int>(index));
    return true;
  }
  void EndPolygon() {
    for (std::size_t k = 1; k + 1 < polygon_.size(); ++k) {
      triangles_.push_back({polygon_[0], polygon_[k], polygon_[k + 1]});
    }
  }
  Eigen::Matrix3Xi Take() const;

 private:
  std::uint64_t vertex_count_;
  std::vector<int> polygon_;
  std::vector<std::array<int, 3>> triangles_;
};

// Meshes of more vertices than an int can index are refused.
constexpr std::uint64_t kMaxMeshVertices = 2147483647u;

MeshData ParsePlyMesh(std::string_view bytes, const std::string& name);   // cloud_io_ply.cpp
MeshData ParseObjMesh(std::string_view bytes, const std::string& name);   // mesh_io_obj.cpp
MeshData ParseOffMesh(std::string_view bytes, const std::string& name);   // mesh_io_off.cpp
MeshData ParseStlMesh(std::string_view bytes, const std::string& name);   // mesh_io_stl.cpp

}  // namespace c3po::mesh_detail
