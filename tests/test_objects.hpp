#pragma once
// Small procedural meshes for unit tests (independent of the bundled objects).
#include <string>
#include <vector>

#include "c3po/geometry/mesh.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po::test {

// Axis-aligned closed box mesh (12 triangles, outward normals).
inline Mesh BoxMesh(const Eigen::Vector3d& centre, const Eigen::Vector3d& size) {
  Mesh mesh;
  mesh.vertices.resize(3, 8);
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d sign((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
    mesh.vertices.col(i) = centre + 0.5 * sign.cwiseProduct(size);
  }
  const int faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                            {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  mesh.triangles.resize(3, 12);
  for (int t = 0; t < 12; ++t) mesh.triangles.col(t) << faces[t][0], faces[t][1], faces[t][2];
  return mesh;
}

inline Mesh MergeMeshes(const std::vector<Mesh>& parts) {
  Mesh merged;
  Eigen::Index vertices = 0, triangles = 0;
  for (const auto& part : parts) {
    vertices += part.vertices.cols();
    triangles += part.triangles.cols();
  }
  merged.vertices.resize(3, vertices);
  merged.triangles.resize(3, triangles);
  Eigen::Index v = 0, t = 0;
  for (const auto& part : parts) {
    merged.vertices.middleCols(v, part.vertices.cols()) = part.vertices;
    merged.triangles.middleCols(t, part.triangles.cols()) =
        part.triangles.array() + static_cast<int>(v);
    v += part.vertices.cols();
    t += part.triangles.cols();
  }
  return merged;
}

// A box of `size` centred at the origin, its corners as keypoints, eps_oc 1 cm
// and delta_nd 8 mm (above the 20000-point sample's spacing, ~2 mm).
inline ObjectModel BoxObject(const Eigen::Vector3d& size, const std::string& name = "box") {
  ObjectSpec spec;
  spec.name = name;
  spec.keypoints = BoxMesh({0, 0, 0}, size).vertices;
  spec.eps_oc = 0.01;
  spec.delta_nd = 0.008;
  ObjectModelOptions options;
  options.sample_size = 20000;
  return ObjectModel(spec, BoxMesh({0, 0, 0}, size), options);
}

// An asymmetric object: a 0.20 x 0.10 x 0.06 block, a 0.06-high tower on one
// end and a side arm; 10 keypoints on corners of the parts.
inline ObjectModel AsymmetricObject(int sample_size = 4000) {
  Mesh mesh = MergeMeshes({BoxMesh({0, 0, 0}, {0.20, 0.10, 0.06}),
                           BoxMesh({0.07, 0.02, 0.06}, {0.06, 0.06, 0.06}),
                           BoxMesh({-0.05, 0.08, 0.0}, {0.04, 0.06, 0.03})});
  ObjectSpec spec;
  spec.name = "asym";
  spec.keypoints.resize(3, 10);
  spec.keypoints << -0.10, 0.10, 0.10, -0.10, 0.10, 0.04, 0.10, -0.07, -0.03, -0.03,  //
      -0.05, -0.05, 0.05, 0.05, -0.01, 0.05, 0.05, 0.11, 0.11, 0.05,                  //
      -0.03, -0.03, 0.03, 0.03, 0.09, 0.09, 0.09, 0.015, 0.015, -0.015;
  spec.eps_oc = 0.006;
  spec.delta_nd = 0.004;
  ObjectModelOptions options;
  options.sample_size = sample_size;
  return ObjectModel(spec, mesh, options);
}

// The paper's mug reduced to boxes: an 0.08 x 0.08 x 0.10 body and a small
// side "handle" block; keypoint 0 is on the handle and alone is the indicator
// set (eps_oc 1 cm, delta_nd 8 mm).
inline Mesh MugLikeMesh() {
  return MergeMeshes({BoxMesh({0, 0, 0}, {0.08, 0.08, 0.10}), BoxMesh({0.055, 0, 0}, {0.03, 0.02, 0.06})});
}

inline ObjectSpec MugLikeSpec() {
  ObjectSpec spec;
  spec.name = "mug-like";
  spec.keypoints.resize(3, 3);
  spec.keypoints << 0.07, -0.04, -0.04, 0.0, -0.04, 0.04, 0.0, 0.05, -0.05;
  spec.indicator_sets = {{0}};
  spec.eps_oc = 0.01;
  spec.delta_nd = 0.008;
  return spec;
}

}  // namespace c3po::test
