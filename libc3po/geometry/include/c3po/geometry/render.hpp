#pragma once
// A pinhole depth camera: z-buffer rasterisation of a posed triangle mesh and
// back-projection of the covered pixels (the paper's "real" depth clouds).
//
// Camera frame: x right, y down, z forward (optical axis); pixel (u, v) has
// its centre at column u, row v and sees the ray ((u - cx)/fx, (v - cy)/fy, 1).
// A back-projected point is the intersection of the pixel-centre ray with the
// triangle recorded in the z-buffer at that pixel, so noise-free points lie
// exactly (to rounding) on the posed mesh.
#include <cstdint>
#include <string>
#include <vector>

#include "c3po/base/random.hpp"
#include "c3po/base/types.hpp"
#include "c3po/geometry/camera.hpp"
#include "c3po/geometry/mesh.hpp"

namespace c3po {

// A rendering camera: the pinhole model (camera.hpp's PinholeCamera, the one
// home of K, back-projection and projection) plus an image size. Default: a
// 640 x 480 Kinect-like camera (fx = fy = 525).
struct CameraIntrinsics : PinholeCamera {
  CameraIntrinsics() : PinholeCamera{525.0, 525.0, 319.5, 239.5} {}
  int width = 640;
  int height = 480;
  // Throws InputError("intrinsics: ...") on non-positive focal lengths or
  // sizes, sizes above 16384 or 50 megapixels, or non-finite values.
  void Check() const;
  // Direction (z = 1) of the ray through image point (u, v).
  Eigen::Vector3d Ray(double u, double v) const { return BackProject(u, v, 1.0); }
};

// Parses "fx,fy,cx,cy,w,h"; throws InputError("--intrinsics: ...").
CameraIntrinsics ParseIntrinsics(const std::string& text);

struct DepthSampleOptions {
  int points = 1000;          // subsample to this many points (all if fewer pixels)
  double noise_sigma = 0.0;   // Gaussian depth noise along the pixel ray (object units)
  double dropout = 0.0;       // each kept point is dropped with this probability
  void Check() const;         // throws InputError
};

// True when every edge of the mesh is shared by exactly two triangles in
// opposite directions and the signed volume is positive (closed parts with
// outward normals): then back-face culling is exact.
bool IsClosedOutward(const Mesh& mesh);

// Triangles with a vertex closer than this to the camera plane are skipped
// (objects are placed well in front of the camera).
constexpr double kNearPlane = 1e-3;

// Owns the image buffers; reuse one renderer per thread (not thread-safe).
// Only the bounding rectangle of the projected mesh is cleared per view.
class DepthRenderer {
 public:
  explicit DepthRenderer(const CameraIntrinsics& camera);

  const CameraIntrinsics& camera() const { return camera_; }

  // Rasterises `mesh` posed by camera_from_model into the z-buffer. With
  // `cull_back_faces`, triangles facing away from the camera are skipped: exact
  // (and twice as fast) for meshes whose parts are closed and outward
  // (IsClosedOutward), wrong for open or inconsistently wound meshes. The mesh
  // must outlive the queries below.
  void Render(const Mesh& mesh, const Pose& camera_from_model, bool cull_back_faces = false);

  // After Render(): pixels covered by the mesh (row-major index v * width + u).
  const std::vector<int>& covered_pixels() const { return covered_; }
  // Triangle seen at a pixel (-1: background) and its depth (z, camera frame).
  int TriangleAt(int u, int v) const;
  double DepthAt(int u, int v) const;
  // Back-projection of a covered pixel onto its triangle (camera frame).
  Eigen::Vector3d BackProject(int pixel) const;

  // A partial cloud: covered pixels subsampled to options.points (uniformly,
  // without replacement), back-projected, each dropped with probability
  // options.dropout, Gaussian noise added along the ray. `triangles` receives
  // the triangle of every output point when not null.
  PointSet SampleCloud(const DepthSampleOptions& options, Rng& rng,
                       Eigen::VectorXi* triangles = nullptr) const;

  // visible[i]: keypoint i (camera frame) projects inside the image and no
  // triangle of the posed mesh crosses the ray from the camera to it closer
  // than `tolerance` (object units) before it. Exact ray test against the
  // projected triangles (culled as in Render), independent of the pixel grid.
  std::vector<bool> KeypointsVisible(const PointSet& camera_keypoints, double tolerance) const;

 private:
  void ClearRectangle();
  void RasterizeTriangle(int t);

  CameraIntrinsics camera_;
  std::vector<double> inverse_depth_;   // 1/z per pixel, 0 = background
  std::vector<int> triangle_;           // triangle id per pixel, -1 = background
  int rect_u0_ = 0, rect_v0_ = 0, rect_u1_ = -1, rect_v1_ = -1;   // last cleared rectangle
  // Per view: posed vertices, their projections, the triangles.
  PointSet camera_vertices_;
  Eigen::Matrix2Xd projected_;
  const Eigen::Matrix3Xi* triangles_ = nullptr;
  bool cull_back_faces_ = false;
  std::vector<int> covered_;
  // Twice the signed screen area per triangle (NaN behind the near plane);
  // negative = front-facing, since it has the sign of det[a b c] = n . a.
  std::vector<double> screen_area_;
};

}  // namespace c3po
