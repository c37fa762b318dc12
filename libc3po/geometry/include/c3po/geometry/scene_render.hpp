#pragma once
// Depth images of scenes: several posed meshes in front of an optional
// background plane (a table), seen by one pinhole camera (render.hpp's
// conventions). Each instance is rasterised alone with DepthRenderer, which
// gives its full silhouette (BOP's `mask`); the depth image keeps, per pixel,
// the nearest surface over the instances and the plane, and the label image
// says which instance that is (BOP's `mask_visib`). Instances must not
// interpenetrate (the nearest surface along a pixel ray is then exactly what a
// z-buffer over all meshes at once would keep).
#include <cstdint>
#include <optional>
#include <vector>

#include "c3po/geometry/mesh.hpp"
#include "c3po/geometry/plane.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/base/types.hpp"

namespace c3po {

struct SceneInstance {
  const Mesh* mesh = nullptr;
  Pose camera_from_model;
  bool closed_outward = false;   // IsClosedOutward(*mesh): back faces may be culled
};

// Pixel index = v * width + u.
struct SceneImage {
  static constexpr int kBackground = -1;   // label of the plane and of empty pixels
  int width = 0;
  int height = 0;
  std::vector<double> depth;   // camera z of the nearest surface (object units); 0 = nothing
  std::vector<int> label;      // instance seen at the pixel, or kBackground
  // Per instance: the pixels it covers when rendered alone (full silhouette,
  // occlusion ignored), in increasing order.
  std::vector<std::vector<int>> silhouettes;

  // Pixels where `instance` is the nearest surface, in increasing order.
  std::vector<int> VisiblePixels(int instance) const;
};

// Depth of the plane along the ray of pixel (u, v): the z of the intersection,
// or 0 when the ray misses the plane (parallel, or behind the camera).
double PlaneDepth(const Plane& plane, const CameraIntrinsics& camera, int u, int v);

// Renders the instances (and the plane) with `renderer` (its camera is the
// scene's camera). Throws std::invalid_argument for a null mesh.
SceneImage RenderScene(DepthRenderer& renderer, const std::vector<SceneInstance>& instances,
                       const std::optional<Plane>& background);

}  // namespace c3po
