#pragma once
// Triangle meshes: loading (PLY: own reader; OBJ, STL, OFF, glTF, ...: assimp), writing
// OBJ, area-weighted surface sampling and closest-point queries.
#include <cstdint>
#include <string>

#include "c3po/types.hpp"

namespace c3po {

struct Mesh {
  PointSet vertices;            // 3 x V
  Eigen::Matrix3Xi triangles;   // 3 x T, vertex indices

  bool empty() const { return triangles.cols() == 0; }
  double SurfaceArea() const;
  Eigen::AlignedBox3d BoundingBox() const;
  // Length of the axis-aligned bounding-box diagonal (the paper's d).
  double Diameter() const { return BoundingBox().diagonal().norm(); }
  // Throws std::invalid_argument on out-of-range indices or non-finite vertices.
  void Validate() const;
};

// Loads a triangle mesh (PLY with c3po's own reader, every other format --
// OBJ, STL, OFF, glTF, ... -- with assimp), merges all its meshes, drops
// vertices no triangle uses and scales coordinates by `scale` (e.g. 0.001 for
// a mesh in millimetres). Throws InputError("path: ...") when the file is
// missing, unreadable or has no triangles.
Mesh LoadMesh(const std::string& path, double scale = 1.0);

// Writes a Wavefront OBJ atomically.
void WriteObj(const Mesh& mesh, const std::string& path);

// `count` points uniformly distributed (by area) over the surface.
PointSet SampleSurface(const Mesh& mesh, int count, std::uint64_t seed);

// Area-weighted uniform surface sample with the index of the triangle of each
// point (used by renderers and tests).
struct SurfaceSample {
  PointSet points;
  Eigen::VectorXi triangle;
};
SurfaceSample SampleSurfaceWithTriangles(const Mesh& mesh, int count, std::uint64_t seed);

// Closest point on a triangle (Ericson, Real-Time Collision Detection 5.1.5).
Eigen::Vector3d ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c);

struct SurfacePoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int triangle = -1;
  double distance = 0.0;
};
// Exact closest surface point by scanning all triangles (O(T); for snapping and
// for test oracles, not for hot loops).
SurfacePoint ClosestSurfacePoint(const Mesh& mesh, const Eigen::Vector3d& p);

}  // namespace c3po
