#pragma once
// Procedural closed triangle meshes and the bundled objects (annotations/).
//
// Every primitive is a closed, consistently oriented 2-manifold (each
// undirected edge is shared by exactly two triangles, in opposite directions,
// normals pointing outwards). A bundled object is the union of a few such
// closed parts that may overlap slightly (a mug handle enters the wall, chair
// legs enter the seat): every part is watertight, the parts are not
// boolean-merged. Coordinates are rounded to float precision so that the OBJ
// files round-trip exactly through 32-bit mesh loaders; keypoints are mesh
// vertices, hence exactly on the surface.
#include <string>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

// ---- primitives (model frame, metres) --------------------------------------

// Axis-aligned cuboid [min_corner, max_corner], each face split into a grid of
// cells no longer than `max_edge`.
Mesh MakeCuboid(const Eigen::Vector3d& min_corner, const Eigen::Vector3d& max_corner,
                double max_edge);

// Surface of revolution about the +z axis of the polyline `profile` of
// (radius, z) points; the first and last points must lie on the axis
// (radius 0), every other point strictly off it. `segments` >= 3 around.
Mesh MakeRevolution(const std::vector<Eigen::Vector2d>& profile, int segments);

// Closed cylinder from `start` to `end` (a revolution with flat caps).
Mesh MakeCylinder(const Eigen::Vector3d& start, const Eigen::Vector3d& end, double radius,
                  int segments);

// Tube of circular cross-section (radius `tube_radius`, `sides` >= 3) along a
// circular arc in the x-z plane: centre `centre`, radius `arc_radius`, from
// angle `angle_begin` to `angle_end` (radians, measured from +x towards +z),
// `arc_segments` >= 1, with flat end caps.
Mesh MakeArcTube(const Eigen::Vector3d& centre, double arc_radius, double angle_begin,
                 double angle_end, double tube_radius, int arc_segments, int sides);

// ---- mesh utilities ----------------------------------------------------------

// x -> pose * x for every vertex.
Mesh TransformMesh(const Mesh& mesh, const Pose& pose);
// Appends `part` (vertices and triangles) to `into`.
void AppendMesh(Mesh* into, const Mesh& part);
// Merges vertices with bit-identical coordinates.
Mesh WeldVertices(const Mesh& mesh);
// Rounds every coordinate to the nearest float, then welds.
Mesh RoundToFloat(const Mesh& mesh);
// Signed volume (divergence theorem); positive for a closed outward mesh.
double SignedVolume(const Mesh& mesh);
// Reverses the winding of every triangle.
void FlipTriangles(Mesh* mesh);

// Edge-based closedness check.
struct ClosednessReport {
  long edges = 0;                 // undirected edges
  long boundary_edges = 0;        // used by one triangle
  long non_manifold_edges = 0;    // used by more than two triangles
  long inconsistent_edges = 0;    // used twice in the same direction
  long degenerate_triangles = 0;  // repeated vertex index or zero area
  bool closed() const {
    return boundary_edges == 0 && non_manifold_edges == 0 && inconsistent_edges == 0 &&
           degenerate_triangles == 0;
  }
};
ClosednessReport CheckClosed(const Mesh& mesh);

// ---- bundled objects ----------------------------------------------------------

struct BundledObject {
  ObjectSpec spec;   // mesh_path empty until written
  Mesh mesh;
  // Closed parts of the mesh: triangles [part_begin[k], part_begin[k+1]).
  std::vector<int> part_begin;
};

// "mug", "box", "drill", "chair".
std::vector<std::string> BundledObjectNames();
// Builds one bundled object; throws std::invalid_argument for an unknown name.
BundledObject MakeBundledObject(const std::string& name);
// Writes DIR/<name>.obj (WriteObj) and DIR/<name>.json (WriteObjectSpec).
void WriteBundledObject(const BundledObject& object, const std::string& dir);

}  // namespace c3po
