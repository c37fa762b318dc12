#pragma once
// Camera intrinsics and depth images from files (issue 15; docs/camera_inputs.md).
//  - Camera JSON: {"cam_K": [9 numbers, row-major], "depth_scale": s} (a BOP
//    scene_camera.json entry), {"fx", "fy", "cx", "cy", "depth_scale", ...}
//    (a BOP camera.json), or a scene_camera.json: its entry `im_id` when
//    given, else it must hold exactly one image.
//  - Depth: a 16-bit PNG (value x depth_scale = millimetres, 0 = none) or a
//    .npy array of float32/float64 depths in metres (shape (H, W), 0 or NaN =
//    none).
#include <map>
#include <optional>
#include <string>

#include "c3po/geometry/camera.hpp"
#include "c3po/io/png_io.hpp"

namespace c3po {

struct CameraInfo {
  PinholeCamera K;
  double depth_scale = 1.0;   // millimetres per PNG depth unit (BOP), > 0
};

// One camera from JSON text (forms above). `depth_scale` overrides the file's
// (and is required when the file has none). `im_id` picks the entry of a
// scene_camera.json (ignored for a single camera). Throws InputError("name: ...")
// for a scene_camera.json of several images without `im_id`, an `im_id` it
// does not hold, missing cam_K, a cam_K that is not [fx 0 cx; 0 fy cy; 0 0 1],
// depth_scale <= 0, non-finite numbers.
CameraInfo ParseCameraJson(const std::string& text, const std::string& name,
                           std::optional<double> depth_scale = std::nullopt,
                           std::optional<int> im_id = std::nullopt);
CameraInfo ReadCameraJson(const std::string& path, std::optional<double> depth_scale = std::nullopt,
                          std::optional<int> im_id = std::nullopt);
// A BOP scene_camera.json: {"im_id": {"cam_K": [...], "depth_scale": s, ...}, ...}.
std::map<int, CameraInfo> ParseSceneCamera(const std::string& text, const std::string& name);
// --intrinsics fx,fy,cx,cy with --depth-scale S.
CameraInfo CameraFromIntrinsics(const std::string& fx_fy_cx_cy, double depth_scale);
// Checks depth_scale (finite, > 0) and K; throws InputError("where: ...").
void CheckCamera(const CameraInfo& camera, const std::string& where);

// Depth in metres from a 16-bit depth PNG: z = value x depth_scale x 1e-3.
DepthImage DepthFromPng(const Image& image, double depth_scale);
// A .npy depth array (metres). Strict: version 1-3 header, '<f4' or '<f8',
// shape (H, W), C or Fortran order, exact data size; negative or infinite
// depths are InputErrors, NaN = no measurement.
DepthImage ParseNpyDepth(const std::string& bytes, const std::string& name);
// By extension: .png (needs depth_scale) or .npy (metres; depth_scale unused).
DepthImage ReadDepth(const std::string& path, double depth_scale);
// Writes a .npy float32 depth array (tests, tools); atomic.
std::string EncodeNpyDepth(const DepthImage& depth);

}  // namespace c3po
