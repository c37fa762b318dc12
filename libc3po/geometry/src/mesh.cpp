// Mesh geometry: area, bounding box, surface sampling, closest points.
// Reading and writing mesh files is io/mesh_io.
#include "c3po/geometry/mesh.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "c3po/base/random.hpp"

namespace c3po {
namespace {

Eigen::Vector3d Corner(const Mesh& mesh, int triangle, int k) {
  return mesh.vertices.col(mesh.triangles(k, triangle));
}

double TriangleArea(const Mesh& mesh, int t) {
  const Eigen::Vector3d a = Corner(mesh, t, 0), b = Corner(mesh, t, 1), c = Corner(mesh, t, 2);
  return 0.5 * (b - a).cross(c - a).norm();
}

Eigen::Vector3d ClosestPointOnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                      const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  if (!(length2 > 0.0)) return a;
  return a + std::clamp(ab.dot(p - a) / length2, 0.0, 1.0) * ab;
}

// A zero-area triangle is the union of its three edges.
Eigen::Vector3d ClosestPointOnDegenerateTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                                 const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  Eigen::Vector3d best = ClosestPointOnSegment(p, a, b);
  for (const Eigen::Vector3d& q : {ClosestPointOnSegment(p, b, c), ClosestPointOnSegment(p, c, a)}) {
    if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
  }
  return best;
}

}  // namespace

double Mesh::SurfaceArea() const {
  double area = 0.0;
  for (int t = 0; t < triangles.cols(); ++t) area += TriangleArea(*this, t);
  return area;
}

Eigen::AlignedBox3d Mesh::BoundingBox() const {
  Eigen::AlignedBox3d box;
  for (int i = 0; i < vertices.cols(); ++i) box.extend(vertices.col(i));
  return box;
}

void Mesh::Validate() const {
  if (!vertices.allFinite()) throw std::invalid_argument("mesh has non-finite vertices");
  if (triangles.size() > 0 &&
      (triangles.minCoeff() < 0 || triangles.maxCoeff() >= vertices.cols())) {
    throw std::invalid_argument("mesh has out-of-range triangle indices");
  }
}

SurfaceSample SampleSurfaceWithTriangles(const Mesh& mesh, int count, std::uint64_t seed) {
  if (mesh.empty()) throw std::invalid_argument("SampleSurface: mesh has no triangles");
  if (count < 0) throw std::invalid_argument("SampleSurface: negative count");
  // Cumulative area table; a triangle is picked with probability area / total.
  std::vector<double> cumulative(mesh.triangles.cols());
  double total = 0.0;
  for (int t = 0; t < mesh.triangles.cols(); ++t) {
    total += TriangleArea(mesh, t);
    cumulative[t] = total;
  }
  if (!(total > 0.0)) throw std::invalid_argument("SampleSurface: zero surface area");
  Rng rng(seed);
  SurfaceSample sample;
  sample.points.resize(3, count);
  sample.triangle.resize(count);
  for (int i = 0; i < count; ++i) {
    const double target = rng.Uniform() * total;
    int t = static_cast<int>(std::upper_bound(cumulative.begin(), cumulative.end(), target) -
                             cumulative.begin());
    t = std::min<int>(t, static_cast<int>(mesh.triangles.cols()) - 1);
    // Uniform point in a triangle: reflect (u, v) outside the lower half.
    double u = rng.Uniform(), v = rng.Uniform();
    if (u + v > 1.0) {
      u = 1.0 - u;
      v = 1.0 - v;
    }
    const Eigen::Vector3d a = Corner(mesh, t, 0), b = Corner(mesh, t, 1), c = Corner(mesh, t, 2);
    sample.points.col(i) = a + u * (b - a) + v * (c - a);
    sample.triangle(i) = t;
  }
  return sample;
}

PointSet SampleSurface(const Mesh& mesh, int count, std::uint64_t seed) {
  return SampleSurfaceWithTriangles(mesh, count, seed).points;
}

// Ericson, Real-Time Collision Detection, section 5.1.5 (Voronoi regions).
Eigen::Vector3d ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  // Ericson's divisions assume a proper triangle; zero-area ones would give 0/0.
  if (!(ab.cross(ac).squaredNorm() > 1e-30 * ab.squaredNorm() * ac.squaredNorm())) {
    return ClosestPointOnDegenerateTriangle(p, a, b, c);
  }
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  }
  // Inside: project onto the plane. Same point as Ericson's a + ab vb/(va+vb+vc)
  // + ac vc/(va+vb+vc), without the cancellation in va + vb + vc = |ab x ac|^2.
  const Eigen::Vector3d normal = ab.cross(ac);
  return p - normal * (normal.dot(ap) / normal.squaredNorm());
}

SurfacePoint ClosestSurfacePoint(const Mesh& mesh, const Eigen::Vector3d& p) {
  SurfacePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  for (int t = 0; t < mesh.triangles.cols(); ++t) {
    const Eigen::Vector3d q =
        ClosestPointOnTriangle(p, Corner(mesh, t, 0), Corner(mesh, t, 1), Corner(mesh, t, 2));
    const double d = (q - p).norm();
    if (d < best.distance) best = {q, t, d};
  }
  return best;
}

}  // namespace c3po
