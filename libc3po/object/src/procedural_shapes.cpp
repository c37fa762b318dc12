// Closed primitive meshes and mesh utilities (procedural.hpp).
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

#include "c3po/object/procedural.hpp"

namespace c3po {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Builds a mesh from vertex and triangle lists.
Mesh FromLists(const std::vector<Eigen::Vector3d>& vertices,
               const std::vector<Eigen::Vector3i>& triangles) {
  Mesh mesh;
  mesh.vertices.resize(3, static_cast<Eigen::Index>(vertices.size()));
  for (std::size_t i = 0; i < vertices.size(); ++i) mesh.vertices.col(i) = vertices[i];
  mesh.triangles.resize(3, static_cast<Eigen::Index>(triangles.size()));
  for (std::size_t i = 0; i < triangles.size(); ++i) mesh.triangles.col(i) = triangles[i];
  return mesh;
}

// Makes a closed mesh face outwards (positive signed volume).
Mesh Outwards(Mesh mesh) {
  if (SignedVolume(mesh) < 0.0) FlipTriangles(&mesh);
  return mesh;
}

// Cells along an extent: at least one, even (so face centres are vertices).
int EvenCellCount(double extent, double max_edge) {
  int n = static_cast<int>(std::ceil(extent / max_edge - 1e-9));
  if (n < 1) n = 1;
  if (n % 2 == 1) ++n;
  return n;
}

// Rings of points around a closed polyline of cross-sections: ring k has
// `sides` vertices; the two ends are closed by fans to `cap_begin`/`cap_end`.
// `ring_offset(k)` is the index of the first vertex of ring k.
void AddRingStrip(int ring_a, int ring_b, int sides, std::vector<Eigen::Vector3i>* triangles) {
  for (int s = 0; s < sides; ++s) {
    const int s1 = (s + 1) % sides;
    triangles->emplace_back(ring_a + s, ring_a + s1, ring_b + s1);
    triangles->emplace_back(ring_a + s, ring_b + s1, ring_b + s);
  }
}

void AddFan(int apex, int ring, int sides, bool reverse,
            std::vector<Eigen::Vector3i>* triangles) {
  for (int s = 0; s < sides; ++s) {
    const int s1 = (s + 1) % sides;
    if (reverse) {
      triangles->emplace_back(apex, ring + s1, ring + s);
    } else {
      triangles->emplace_back(apex, ring + s, ring + s1);
    }
  }
}

// (cos, sin) of 2 pi k / n, exact at quarter turns (no 1e-17 residues).
Eigen::Vector2d UnitCircle(int k, int n) {
  if ((4 * k) % n == 0) {
    static const double kCos[4] = {1.0, 0.0, -1.0, 0.0};
    static const double kSin[4] = {0.0, 1.0, 0.0, -1.0};
    const int quarter = (4 * k / n) % 4;
    return {kCos[quarter], kSin[quarter]};
  }
  const double angle = 2.0 * kPi * k / n;
  return {std::cos(angle), std::sin(angle)};
}

}  // namespace

Mesh MakeCuboid(const Eigen::Vector3d& min_corner, const Eigen::Vector3d& max_corner,
                double max_edge) {
  if (!((max_corner - min_corner).array() > 0.0).all() || !(max_edge > 0.0)) {
    throw std::invalid_argument("MakeCuboid: empty box or non-positive edge length");
  }
  // Per-axis grid coordinates, shared by every face so that edges weld exactly.
  std::array<std::vector<double>, 3> grid;
  for (int a = 0; a < 3; ++a) {
    const int n = EvenCellCount(max_corner[a] - min_corner[a], max_edge);
    for (int i = 0; i <= n; ++i) {
      grid[a].push_back(i == n ? max_corner[a]
                               : min_corner[a] + (max_corner[a] - min_corner[a]) * i / n);
    }
  }
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;
  for (int a = 0; a < 3; ++a) {
    const int u = (a + 1) % 3;
    const int v = (a + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      const int base = static_cast<int>(vertices.size());
      const int nu = static_cast<int>(grid[u].size());
      const int nv = static_cast<int>(grid[v].size());
      for (int i = 0; i < nu; ++i) {
        for (int j = 0; j < nv; ++j) {
          Eigen::Vector3d p;
          p[a] = side == 0 ? min_corner[a] : max_corner[a];
          p[u] = grid[u][i];
          p[v] = grid[v][j];
          vertices.push_back(p);
        }
      }
      // e_u x e_v = e_a: counter-clockwise (u, v) order faces +a.
      for (int i = 0; i + 1 < nu; ++i) {
        for (int j = 0; j + 1 < nv; ++j) {
          const int p00 = base + i * nv + j;
          const int p10 = base + (i + 1) * nv + j;
          const int p11 = p10 + 1;
          const int p01 = p00 + 1;
          if (side == 1) {
            triangles.emplace_back(p00, p10, p11);
            triangles.emplace_back(p00, p11, p01);
          } else {
            triangles.emplace_back(p00, p11, p10);
            triangles.emplace_back(p00, p01, p11);
          }
        }
      }
    }
  }
  return WeldVertices(FromLists(vertices, triangles));
}

Mesh MakeRevolution(const std::vector<Eigen::Vector2d>& profile, int segments) {
  const int p = static_cast<int>(profile.size());
  if (p < 3 || segments < 3) throw std::invalid_argument("MakeRevolution: too few points");
  if (profile.front().x() != 0.0 || profile.back().x() != 0.0) {
    throw std::invalid_argument("MakeRevolution: the profile must start and end on the axis");
  }
  for (int i = 1; i + 1 < p; ++i) {
    if (!(profile[i].x() > 0.0)) {
      throw std::invalid_argument("MakeRevolution: inner profile points must be off the axis");
    }
  }
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;
  vertices.emplace_back(0.0, 0.0, profile.front().y());   // first pole: index 0
  for (int i = 1; i + 1 < p; ++i) {
    for (int s = 0; s < segments; ++s) {
      const Eigen::Vector2d direction = UnitCircle(s, segments);
      vertices.emplace_back(profile[i].x() * direction.x(), profile[i].x() * direction.y(),
                            profile[i].y());
    }
  }
  const int last_pole = static_cast<int>(vertices.size());
  vertices.emplace_back(0.0, 0.0, profile.back().y());
  const auto ring = [segments](int i) { return 1 + (i - 1) * segments; };
  AddFan(0, ring(1), segments, true, &triangles);
  for (int i = 1; i + 2 < p; ++i) AddRingStrip(ring(i), ring(i + 1), segments, &triangles);
  AddFan(last_pole, ring(p - 2), segments, false, &triangles);
  return Outwards(FromLists(vertices, triangles));
}

Mesh MakeCylinder(const Eigen::Vector3d& start, const Eigen::Vector3d& end, double radius,
                  int segments) {
  const Eigen::Vector3d axis = end - start;
  const double length = axis.norm();
  if (!(length > 0.0) || !(radius > 0.0)) {
    throw std::invalid_argument("MakeCylinder: zero length or radius");
  }
  const Mesh upright = MakeRevolution({{0.0, 0.0}, {radius, 0.0}, {radius, length}, {0.0, length}},
                                      segments);
  Pose pose;
  pose.R = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis / length)
               .toRotationMatrix();
  pose.t = start;
  return TransformMesh(upright, pose);
}

Mesh MakeArcTube(const Eigen::Vector3d& centre, double arc_radius, double angle_begin,
                 double angle_end, double tube_radius, int arc_segments, int sides) {
  if (arc_segments < 1 || sides < 3 || !(tube_radius > 0.0) || !(arc_radius > tube_radius)) {
    throw std::invalid_argument("MakeArcTube: bad parameters");
  }
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;
  const Eigen::Vector3d e_y = Eigen::Vector3d::UnitY();
  const auto arc_point = [&](double phi) {
    return Eigen::Vector3d(centre + arc_radius * Eigen::Vector3d(std::cos(phi), 0, std::sin(phi)));
  };
  for (int k = 0; k <= arc_segments; ++k) {
    const double phi = angle_begin + (angle_end - angle_begin) * k / arc_segments;
    const Eigen::Vector3d radial(std::cos(phi), 0.0, std::sin(phi));
    for (int s = 0; s < sides; ++s) {
      const Eigen::Vector2d psi = UnitCircle(s, sides);   // s = 0: away from the arc centre
      vertices.push_back(arc_point(phi) + tube_radius * (psi.x() * radial + psi.y() * e_y));
    }
  }
  const int cap_begin = static_cast<int>(vertices.size());
  vertices.push_back(arc_point(angle_begin));
  vertices.push_back(arc_point(angle_end));
  for (int k = 0; k < arc_segments; ++k) {
    AddRingStrip(k * sides, (k + 1) * sides, sides, &triangles);
  }
  AddFan(cap_begin, 0, sides, true, &triangles);
  AddFan(cap_begin + 1, arc_segments * sides, sides, false, &triangles);
  return Outwards(FromLists(vertices, triangles));
}

Mesh TransformMesh(const Mesh& mesh, const Pose& pose) {
  Mesh out = mesh;
  out.vertices = pose * mesh.vertices;
  return out;
}

void AppendMesh(Mesh* into, const Mesh& part) {
  const Eigen::Index v0 = into->vertices.cols();
  const Eigen::Index t0 = into->triangles.cols();
  into->vertices.conservativeResize(3, v0 + part.vertices.cols());
  into->vertices.rightCols(part.vertices.cols()) = part.vertices;
  into->triangles.conservativeResize(3, t0 + part.triangles.cols());
  into->triangles.rightCols(part.triangles.cols()) =
      part.triangles.array() + static_cast<int>(v0);
}

Mesh WeldVertices(const Mesh& mesh) {
  std::map<std::array<double, 3>, int> index_of;
  std::vector<int> remap(static_cast<std::size_t>(mesh.vertices.cols()));
  std::vector<Eigen::Vector3d> vertices;
  for (Eigen::Index i = 0; i < mesh.vertices.cols(); ++i) {
    const Eigen::Vector3d p = mesh.vertices.col(i);
    const std::array<double, 3> key{p.x(), p.y(), p.z()};
    const auto found = index_of.emplace(key, static_cast<int>(vertices.size()));
    if (found.second) vertices.push_back(p);
    remap[static_cast<std::size_t>(i)] = found.first->second;
  }
  std::vector<Eigen::Vector3i> triangles;
  for (Eigen::Index t = 0; t < mesh.triangles.cols(); ++t) {
    triangles.emplace_back(remap[static_cast<std::size_t>(mesh.triangles(0, t))],
                           remap[static_cast<std::size_t>(mesh.triangles(1, t))],
                           remap[static_cast<std::size_t>(mesh.triangles(2, t))]);
  }
  return FromLists(vertices, triangles);
}

Mesh RoundToFloat(const Mesh& mesh) {
  Mesh out = mesh;
  out.vertices = mesh.vertices.cast<float>().cast<double>();
  return WeldVertices(out);
}

double SignedVolume(const Mesh& mesh) {
  double six_volume = 0.0;
  for (Eigen::Index t = 0; t < mesh.triangles.cols(); ++t) {
    const Eigen::Vector3d a = mesh.vertices.col(mesh.triangles(0, t));
    const Eigen::Vector3d b = mesh.vertices.col(mesh.triangles(1, t));
    const Eigen::Vector3d c = mesh.vertices.col(mesh.triangles(2, t));
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

void FlipTriangles(Mesh* mesh) { mesh->triangles.row(1).swap(mesh->triangles.row(2)); }

ClosednessReport CheckClosed(const Mesh& mesh) {
  // (low, high) -> (uses low->high, uses high->low)
  std::map<std::pair<int, int>, std::pair<int, int>> uses;
  ClosednessReport report;
  for (Eigen::Index t = 0; t < mesh.triangles.cols(); ++t) {
    const Eigen::Vector3i tri = mesh.triangles.col(t);
    const Eigen::Vector3d a = mesh.vertices.col(tri[0]);
    const Eigen::Vector3d b = mesh.vertices.col(tri[1]);
    const Eigen::Vector3d c = mesh.vertices.col(tri[2]);
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] ||
        (b - a).cross(c - a).norm() == 0.0) {
      ++report.degenerate_triangles;
    }
    for (int e = 0; e < 3; ++e) {
      const int from = tri[e];
      const int to = tri[(e + 1) % 3];
      auto& count = uses[{std::min(from, to), std::max(from, to)}];
      (from < to ? count.first : count.second) += 1;
    }
  }
  report.edges = static_cast<long>(uses.size());
  for (const auto& [edge, count] : uses) {
    const int total = count.first + count.second;
    if (total == 1) ++report.boundary_edges;
    if (total > 2) ++report.non_manifold_edges;
    if (total == 2 && count.first != 1) ++report.inconsistent_edges;
  }
  return report;
}

}  // namespace c3po
