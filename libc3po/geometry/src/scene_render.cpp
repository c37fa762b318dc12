// Depth and label images of several meshes and a background plane
// (scene_render.hpp).
#include "c3po/geometry/scene_render.hpp"

#include <cmath>
#include <stdexcept>

namespace c3po {

std::vector<int> SceneImage::VisiblePixels(int instance) const {
  std::vector<int> pixels;
  for (std::size_t p = 0; p < label.size(); ++p) {
    if (label[p] == instance) pixels.push_back(static_cast<int>(p));
  }
  return pixels;
}

double PlaneDepth(const Plane& plane, const CameraIntrinsics& camera, int u, int v) {
  // The ray s * r, r = Ray(u, v) with r.z = 1, meets n . x = offset at
  // s = offset / (n . r); z = s.
  const double denominator = plane.normal.dot(camera.Ray(u, v));
  if (denominator == 0.0) return 0.0;
  const double z = plane.offset / denominator;
  return std::isfinite(z) && z > kNearPlane ? z : 0.0;
}

SceneImage RenderScene(DepthRenderer& renderer, const std::vector<SceneInstance>& instances,
                       const std::optional<Plane>& background) {
  const CameraIntrinsics& camera = renderer.camera();
  SceneImage image;
  image.width = camera.width;
  image.height = camera.height;
  const std::size_t pixels = static_cast<std::size_t>(camera.width) * camera.height;
  image.depth.assign(pixels, 0.0);
  image.label.assign(pixels, SceneImage::kBackground);
  if (background) {
    for (int v = 0; v < camera.height; ++v) {
      for (int u = 0; u < camera.width; ++u) {
        image.depth[static_cast<std::size_t>(v) * camera.width + u] =
            PlaneDepth(*background, camera, u, v);
      }
    }
  }
  image.silhouettes.resize(instances.size());
  for (std::size_t i = 0; i < instances.size(); ++i) {
    const SceneInstance& instance = instances[i];
    if (!instance.mesh) throw std::invalid_argument("RenderScene: instance without a mesh");
    renderer.Render(*instance.mesh, instance.camera_from_model, instance.closed_outward);
    image.silhouettes[i] = renderer.covered_pixels();   // row-major order: increasing
    for (const int pixel : image.silhouettes[i]) {
      // z of the exact back-projection onto the triangle seen at the pixel
      // (the same point DepthRenderer::SampleCloud returns).
      const double z = renderer.BackProject(pixel).z();
      double& nearest = image.depth[static_cast<std::size_t>(pixel)];
      if (nearest == 0.0 || z < nearest) {
        nearest = z;
        image.label[static_cast<std::size_t>(pixel)] = static_cast<int>(i);
      }
    }
  }
  return image;
}

}  // namespace c3po
