// Pinhole depth renderer: z-buffer rasterisation + exact back-projection
// (render.hpp).
#include "c3po/geometry/render.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <vector>

#include "c3po/base/error.hpp"

namespace c3po {
namespace {

// Twice the signed area of (a, b, p): > 0 when p is left of a->b.
inline double Edge(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double u, double v) {
  return (b.x() - a.x()) * (v - a.y()) - (b.y() - a.y()) * (u - a.x());
}

// Ray parameter s with s * ray on the plane of triangle (a, b, c); NaN when
// the ray is parallel to the plane.
inline double RayPlane(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c, const Eigen::Vector3d& ray) {
  const Eigen::Vector3d normal = (b - a).cross(c - a);
  const double denominator = normal.dot(ray);
  if (denominator == 0.0) return std::numeric_limits<double>::quiet_NaN();
  return normal.dot(a) / denominator;
}

}  // namespace

void CameraIntrinsics::Check() const {
  const bool finite = std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) &&
                      std::isfinite(cy);
  if (!finite || !(fx > 0.0) || !(fy > 0.0)) {
    throw InputError("intrinsics: focal lengths must be finite and positive");
  }
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    throw InputError("intrinsics: image size must be between 1 and 16384 pixels");
  }
  if (static_cast<long long>(width) * height > 50000000LL) {
    throw InputError("intrinsics: more than 50 megapixels");
  }
}

CameraIntrinsics ParseIntrinsics(const std::string& text) {
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw InputError("--intrinsics: '" + item + "' is not a number");
    }
  }
  if (values.size() != 6) throw InputError("--intrinsics: expected fx,fy,cx,cy,width,height");
  CameraIntrinsics camera;
  camera.fx = values[0];
  camera.fy = values[1];
  camera.cx = values[2];
  camera.cy = values[3];
  if (values[4] != std::floor(values[4]) || values[5] != std::floor(values[5]) ||
      !(std::abs(values[4]) < 1e6) || !(std::abs(values[5]) < 1e6)) {
    throw InputError("--intrinsics: width and height must be whole numbers of pixels");
  }
  camera.width = static_cast<int>(values[4]);
  camera.height = static_cast<int>(values[5]);
  camera.Check();
  return camera;
}

void DepthSampleOptions::Check() const {
  if (points < 1) throw InputError("--points: must be at least 1");
  if (!(noise_sigma >= 0.0) || !std::isfinite(noise_sigma)) {
    throw InputError("--noise: must be a finite distance >= 0");
  }
  if (!(dropout >= 0.0 && dropout < 1.0)) throw InputError("--dropout: must be in [0, 1)");
}

DepthRenderer::DepthRenderer(const CameraIntrinsics& camera) : camera_(camera) {
  camera_.Check();
  const std::size_t pixels = static_cast<std::size_t>(camera_.width) * camera_.height;
  inverse_depth_.assign(pixels, 0.0);
  triangle_.assign(pixels, -1);
}

void DepthRenderer::ClearRectangle() {
  for (int v = rect_v0_; v <= rect_v1_; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * camera_.width;
    std::fill(inverse_depth_.begin() + row + rect_u0_, inverse_depth_.begin() + row + rect_u1_ + 1,
              0.0);
    std::fill(triangle_.begin() + row + rect_u0_, triangle_.begin() + row + rect_u1_ + 1, -1);
  }
  rect_u0_ = rect_v0_ = 0;
  rect_u1_ = rect_v1_ = -1;
}

namespace {

// One id per vertex position (loaders split vertices at texture seams).
std::vector<std::uint32_t> PositionIds(const Mesh& mesh) {
  std::vector<int> order(static_cast<std::size_t>(mesh.vertices.cols()));
  std::iota(order.begin(), order.end(), 0);
  const auto less = [&](int i, int j) {
    const auto a = mesh.vertices.col(i), b = mesh.vertices.col(j);
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<std::uint32_t> ids(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const bool same = k > 0 && !less(order[k - 1], order[k]);
    ids[static_cast<std::size_t>(order[k])] =
        same ? ids[static_cast<std::size_t>(order[k - 1])] : static_cast<std::uint32_t>(k);
  }
  return ids;
}

// A triangle by its position ids and winding.
struct WoundFace {
  std::array<std::uint32_t, 3> sorted;
  bool even;   // winding parity relative to the sorted order
  std::array<std::uint32_t, 3> id;
  bool operator<(const WoundFace& o) const { return sorted != o.sorted ? sorted < o.sorted : even < o.even; }
};

// The triangles that are drawn (three distinct positions, non-zero area), sorted.
std::vector<WoundFace> DrawnFaces(const Mesh& mesh, const std::vector<std::uint32_t>& position_ids) {
  std::vector<WoundFace> faces;
  for (Eigen::Index t = 0; t < mesh.triangles.cols(); ++t) {
    WoundFace face;
    for (int e = 0; e < 3; ++e) {
      face.id[static_cast<std::size_t>(e)] = position_ids[static_cast<std::size_t>(mesh.triangles(e, t))];
    }
    const auto& id = face.id;
    if (id[0] == id[1] || id[1] == id[2] || id[0] == id[2]) continue;
    const Eigen::Vector3d a = mesh.vertices.col(mesh.triangles(0, t));
    if ((Eigen::Vector3d(mesh.vertices.col(mesh.triangles(1, t))) - a)
            .cross(Eigen::Vector3d(mesh.vertices.col(mesh.triangles(2, t))) - a)
            .squaredNorm() == 0.0) {
      continue;
    }
    face.sorted = id;
    std::sort(face.sorted.begin(), face.sorted.end());
    // A rotation of the sorted triple has even parity.
    face.even = (id[0] == face.sorted[0] && id[1] == face.sorted[1]) ||
                (id[1] == face.sorted[0] && id[2] == face.sorted[1]) ||
                (id[2] == face.sorted[0] && id[0] == face.sorted[1]);
    faces.push_back(face);
  }
  std::sort(faces.begin(), faces.end());
  return faces;
}

// The sorted faces' directed edges (from << 32 | to), sorted. A triangle
// coincident with a reversed copy of itself (a zero-thickness fin) is drawn
// either way and is left out, like zero-area triangles.
std::vector<std::uint64_t> DirectedEdgesWithoutFins(const std::vector<WoundFace>& faces) {
  std::vector<std::uint64_t> edges;
  edges.reserve(faces.size() * 3);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const bool next_same = f + 1 < faces.size() && faces[f + 1].sorted == faces[f].sorted;
    const bool previous_same = f > 0 && faces[f - 1].sorted == faces[f].sorted;
    if ((next_same && faces[f + 1].even != faces[f].even) ||
        (previous_same && faces[f - 1].even != faces[f].even)) {
      continue;
    }
    const auto& id = faces[f].id;
    for (std::size_t e = 0; e < 3; ++e) {
      edges.push_back((static_cast<std::uint64_t>(id[e]) << 32) | id[(e + 1) % 3]);
    }
  }
  std::sort(edges.begin(), edges.end());
  return edges;
}

// Closed and consistently wound iff every directed edge occurs once and its reverse occurs too.
bool EveryEdgeOnceEachWay(const std::vector<std::uint64_t>& sorted_edges) {
  if (std::adjacent_find(sorted_edges.begin(), sorted_edges.end()) != sorted_edges.end()) return false;
  for (const std::uint64_t edge : sorted_edges) {
    const std::uint64_t reverse = (edge << 32) | (edge >> 32);
    if (!std::binary_search(sorted_edges.begin(), sorted_edges.end(), reverse)) return false;
  }
  return true;
}

// Six times the signed volume enclosed by the triangles (> 0: normals outward).
double SixSignedVolume(const Mesh& mesh) {
  double six_volume = 0.0;
  for (Eigen::Index t = 0; t < mesh.triangles.cols(); ++t) {
    const Eigen::Vector3d a = mesh.vertices.col(mesh.triangles(0, t));
    six_volume += a.dot(Eigen::Vector3d(mesh.vertices.col(mesh.triangles(1, t)))
                            .cross(Eigen::Vector3d(mesh.vertices.col(mesh.triangles(2, t)))));
  }
  return six_volume;
}

}  // namespace

bool IsClosedOutward(const Mesh& mesh) {
  if (mesh.empty()) return false;
  const std::vector<WoundFace> faces = DrawnFaces(mesh, PositionIds(mesh));
  return EveryEdgeOnceEachWay(DirectedEdgesWithoutFins(faces)) && SixSignedVolume(mesh) > 0.0;
}

void DepthRenderer::Render(const Mesh& mesh, const Pose& camera_from_model,
                           bool cull_back_faces) {
  ClearRectangle();
  covered_.clear();
  triangles_ = &mesh.triangles;
  cull_back_faces_ = cull_back_faces;
  screen_area_.assign(static_cast<std::size_t>(mesh.triangles.cols()),
                      std::numeric_limits<double>::quiet_NaN());
  camera_vertices_ = camera_from_model * mesh.vertices;
  const Eigen::Index count = camera_vertices_.cols();
  projected_.resize(2, count);
  double u_min = HUGE_VAL, u_max = -HUGE_VAL, v_min = HUGE_VAL, v_max = -HUGE_VAL;
  for (Eigen::Index i = 0; i < count; ++i) {
    const Eigen::Vector3d p = camera_vertices_.col(i);
    if (!(p.z() > kNearPlane)) {
      projected_.col(i).setConstant(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    const double u = camera_.fx * p.x() / p.z() + camera_.cx;
    const double v = camera_.fy * p.y() / p.z() + camera_.cy;
    projected_.col(i) << u, v;
    u_min = std::min(u_min, u);
    u_max = std::max(u_max, u);
    v_min = std::min(v_min, v);
    v_max = std::max(v_max, v);
  }
  // Pixel centres are at integer coordinates; clip the rectangle to the image.
  // (An empty view leaves u_min = +inf, u_max = -inf: clamping keeps the casts defined.)
  const auto clamp = [](double x, double lo, double hi) { return std::min(hi, std::max(lo, x)); };
  rect_u0_ = static_cast<int>(clamp(std::ceil(u_min), 0.0, camera_.width));
  rect_v0_ = static_cast<int>(clamp(std::ceil(v_min), 0.0, camera_.height));
  rect_u1_ = static_cast<int>(clamp(std::floor(u_max), -1.0, camera_.width - 1.0));
  rect_v1_ = static_cast<int>(clamp(std::floor(v_max), -1.0, camera_.height - 1.0));
  if (rect_u0_ > rect_u1_ || rect_v0_ > rect_v1_) {
    rect_u0_ = rect_v0_ = 0;
    rect_u1_ = rect_v1_ = -1;
    return;
  }
  for (Eigen::Index t = 0; t < mesh.triangles.cols(); ++t) RasterizeTriangle(static_cast<int>(t));
  for (int v = rect_v0_; v <= rect_v1_; ++v) {
    const int row = v * camera_.width;
    for (int u = rect_u0_; u <= rect_u1_; ++u) {
      if (triangle_[static_cast<std::size_t>(row + u)] >= 0) covered_.push_back(row + u);
    }
  }
}

void DepthRenderer::RasterizeTriangle(int t) {
  const Eigen::Vector3i tri = triangles_->col(t);
  const Eigen::Vector2d a = projected_.col(tri[0]);
  const Eigen::Vector2d b = projected_.col(tri[1]);
  const Eigen::Vector2d c = projected_.col(tri[2]);
  double area = Edge(a, b, c.x(), c.y());
  screen_area_[static_cast<std::size_t>(t)] = area;
  // NaN (behind the near plane), edge-on, or culled back face.
  if (!(area < 0.0 || (area > 0.0 && !cull_back_faces_))) return;
  const double u_lo = std::max<double>(rect_u0_, std::ceil(std::min({a.x(), b.x(), c.x()})));
  const double u_hi = std::min<double>(rect_u1_, std::floor(std::max({a.x(), b.x(), c.x()})));
  const double v_lo = std::max<double>(rect_v0_, std::ceil(std::min({a.y(), b.y(), c.y()})));
  const double v_hi = std::min<double>(rect_v1_, std::floor(std::max({a.y(), b.y(), c.y()})));
  if (u_lo > u_hi || v_lo > v_hi) return;
  // Barycentric weights scaled by 1/area so that inside means all >= 0.
  const double sign = area > 0.0 ? 1.0 : -1.0;
  area = std::abs(area);
  const double inv_za = 1.0 / camera_vertices_(2, tri[0]);
  const double inv_zb = 1.0 / camera_vertices_(2, tri[1]);
  const double inv_zc = 1.0 / camera_vertices_(2, tri[2]);
  for (int v = static_cast<int>(v_lo); v <= static_cast<int>(v_hi); ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * camera_.width;
    for (int u = static_cast<int>(u_lo); u <= static_cast<int>(u_hi); ++u) {
      const double wa = sign * Edge(b, c, u, v);
      const double wb = sign * Edge(c, a, u, v);
      const double wc = sign * Edge(a, b, u, v);
      if (wa < 0.0 || wb < 0.0 || wc < 0.0) continue;
      // 1/z is affine in screen space (perspective-correct depth).
      const double inverse_depth = (wa * inv_za + wb * inv_zb + wc * inv_zc) / area;
      const std::size_t pixel = row + static_cast<std::size_t>(u);
      if (inverse_depth > inverse_depth_[pixel]) {
        inverse_depth_[pixel] = inverse_depth;
        triangle_[pixel] = t;
      }
    }
  }
}

int DepthRenderer::TriangleAt(int u, int v) const {
  if (u < 0 || v < 0 || u >= camera_.width || v >= camera_.height) return -1;
  return triangle_[static_cast<std::size_t>(v) * camera_.width + u];
}

double DepthRenderer::DepthAt(int u, int v) const {
  const int t = TriangleAt(u, v);
  if (t < 0) return std::numeric_limits<double>::infinity();
  return BackProject(v * camera_.width + u).z();
}

Eigen::Vector3d DepthRenderer::BackProject(int pixel) const {
  const int t = triangle_[static_cast<std::size_t>(pixel)];
  const Eigen::Vector3i tri = triangles_->col(t);
  const Eigen::Vector3d ray = camera_.Ray(pixel % camera_.width, pixel / camera_.width);
  const double s = RayPlane(camera_vertices_.col(tri[0]), camera_vertices_.col(tri[1]),
                            camera_vertices_.col(tri[2]), ray);
  return s * ray;
}

PointSet DepthRenderer::SampleCloud(const DepthSampleOptions& options, Rng& rng,
                                    Eigen::VectorXi* triangles) const {
  std::vector<int> pixels = covered_;
  const std::size_t keep = std::min(pixels.size(), static_cast<std::size_t>(options.points));
  // Partial Fisher-Yates: the first `keep` entries are a uniform subset.
  if (keep < pixels.size()) {
    for (std::size_t i = 0; i < keep; ++i) {
      const std::size_t j = i + static_cast<std::size_t>(
                                    rng.UniformInt(static_cast<int>(pixels.size() - i)));
      std::swap(pixels[i], pixels[j]);
    }
  }
  PointSet cloud(3, static_cast<Eigen::Index>(keep));
  std::vector<int> kept_triangles;
  Eigen::Index count = 0;
  for (std::size_t i = 0; i < keep; ++i) {
    if (options.dropout > 0.0 && rng.Uniform() < options.dropout) continue;
    Eigen::Vector3d point = BackProject(pixels[i]);
    if (options.noise_sigma > 0.0) {
      // Depth noise: z -> z + sigma * N(0, 1), along the pixel ray.
      point *= (point.z() + options.noise_sigma * rng.Normal()) / point.z();
    }
    cloud.col(count++) = point;
    kept_triangles.push_back(triangle_[static_cast<std::size_t>(pixels[i])]);
  }
  cloud.conservativeResize(3, count);
  if (triangles) {
    *triangles = Eigen::Map<const Eigen::VectorXi>(kept_triangles.data(),
                                                   static_cast<Eigen::Index>(kept_triangles.size()));
  }
  return cloud;
}

std::vector<bool> DepthRenderer::KeypointsVisible(const PointSet& camera_keypoints,
                                                  double tolerance) const {
  const std::size_t count = static_cast<std::size_t>(camera_keypoints.cols());
  std::vector<bool> visible(count, false);
  if (!triangles_) return visible;
  // Keypoints to test: in front of the camera and inside the image.
  struct Query {
    std::size_t index;
    double u, v;
    double s_limit;   // occluded by a hit at ray parameter s in (0, s_limit)
    bool occluded;
  };
  std::vector<Query> queries;
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3d p = camera_keypoints.col(static_cast<Eigen::Index>(k));
    if (!(p.z() > kNearPlane)) continue;
    const double u = camera_.fx * p.x() / p.z() + camera_.cx;
    const double v = camera_.fy * p.y() / p.z() + camera_.cy;
    if (!(u >= -0.5 && u < camera_.width - 0.5 && v >= -0.5 && v < camera_.height - 0.5)) continue;
    queries.push_back({k, u, v, 1.0 - tolerance / p.norm(), false});
  }
  if (queries.empty() || screen_area_.empty()) return visible;
  for (Eigen::Index t = 0; t < triangles_->cols(); ++t) {
    const double area = screen_area_[static_cast<std::size_t>(t)];
    if (!(area < 0.0 || (area > 0.0 && !cull_back_faces_))) continue;
    const Eigen::Vector3i tri = triangles_->col(t);
    const Eigen::Vector2d a = projected_.col(tri[0]);
    const Eigen::Vector2d b = projected_.col(tri[1]);
    const Eigen::Vector2d c = projected_.col(tri[2]);
    const double u_lo = std::min({a.x(), b.x(), c.x()}), u_hi = std::max({a.x(), b.x(), c.x()});
    const double v_lo = std::min({a.y(), b.y(), c.y()}), v_hi = std::max({a.y(), b.y(), c.y()});
    const double sign = area > 0.0 ? 1.0 : -1.0;
    for (Query& q : queries) {
      if (q.occluded || q.u < u_lo || q.u > u_hi || q.v < v_lo || q.v > v_hi) continue;
      if (sign * Edge(b, c, q.u, q.v) < 0.0 || sign * Edge(c, a, q.u, q.v) < 0.0 ||
          sign * Edge(a, b, q.u, q.v) < 0.0) {
        continue;
      }
      const double s = RayPlane(camera_vertices_.col(tri[0]), camera_vertices_.col(tri[1]),
                                camera_vertices_.col(tri[2]),
                                camera_keypoints.col(static_cast<Eigen::Index>(q.index)));
      q.occluded = s > 0.0 && s < q.s_limit;
    }
  }
  for (const Query& q : queries) visible[q.index] = !q.occluded;
  return visible;
}

}  // namespace c3po
