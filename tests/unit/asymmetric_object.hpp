#pragma once
// A small asymmetric test object (no proper rotational symmetry): the union of
// three boxes of different sizes forming an L with a post, d ~ 0.25 m.
// Used by the ICP and svd-detector tests.
#include "c3po/geometry/mesh.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po::test {

// Closed box [lo, hi]: 8 vertices from column 8*k, 12 outward triangles from
// column 12*k of `mesh`, which must already have room for them.
inline void SetBox(Mesh* mesh, int k, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const int base = 8 * k;
  for (int corner = 0; corner < 8; ++corner) {
    mesh->vertices.col(base + corner) << ((corner & 1) ? hi.x() : lo.x()),
        ((corner & 2) ? hi.y() : lo.y()), ((corner & 4) ? hi.z() : lo.z());
  }
  // Faces as corner quads (counter-clockwise seen from outside).
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (int f = 0; f < 6; ++f) {
    const int* q = quads[f];
    mesh->triangles.col(12 * k + 2 * f) << base + q[0], base + q[1], base + q[2];
    mesh->triangles.col(12 * k + 2 * f + 1) << base + q[0], base + q[2], base + q[3];
  }
}

inline Mesh AsymmetricMesh() {
  Mesh mesh;
  mesh.vertices.resize(3, 24);
  mesh.triangles.resize(3, 36);
  SetBox(&mesh, 0, {0.0, 0.0, 0.0}, {0.20, 0.05, 0.04});     // long bar along x
  SetBox(&mesh, 1, {0.0, 0.05, 0.0}, {0.05, 0.13, 0.04});    // short arm along y
  SetBox(&mesh, 2, {0.15, 0.0, 0.04}, {0.19, 0.03, 0.09});   // post on the bar's end
  return mesh;
}

inline ObjectModel AsymmetricObject(int sample_size = 5000) {
  ObjectSpec spec;
  spec.name = "asymmetric_l";
  spec.keypoints.resize(3, 5);
  spec.keypoints << 0.0, 0.20, 0.05, 0.19, 0.0,   //
      0.0, 0.0, 0.13, 0.03, 0.13,                  //
      0.0, 0.0, 0.0, 0.09, 0.04;
  spec.eps_oc = 0.005;
  spec.delta_nd = 0.005;
  ObjectModelOptions options;
  options.sample_size = sample_size;
  options.seed = 7;
  return ObjectModel(spec, AsymmetricMesh(), options);
}

}  // namespace c3po::test
