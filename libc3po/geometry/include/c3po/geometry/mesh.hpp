#pragma once
// Triangle meshes: geometry (area, bounding box, diameter), area-weighted
// surface sampling and closest-point queries. Mesh files are read and written
// by io/mesh_io.hpp.
#include <cstdint>
#include <string>

#include "c3po/base/types.hpp"

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
