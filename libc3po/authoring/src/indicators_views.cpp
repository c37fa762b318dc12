// Automatic indicator sets, step 1: render views evenly over the sphere of
// viewing directions and decide for each whether it pins the pose down (the
// cover-set condition, paper eq. 20).
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "c3po/authoring/indicators.hpp"
#include "c3po/base/error.hpp"
#include "c3po/method/certificate.hpp"

namespace c3po {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Fibonacci sphere: direction i of n, evenly spread (golden-angle spiral).
Eigen::Vector3d FibonacciDirection(int i, int n) {
  const double z = 1.0 - (2.0 * i + 1.0) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = i * kPi * (3.0 - std::sqrt(5.0));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// camera_from_model rotation of a camera looking along -direction (model
// frame), rolled by `roll` about its optical axis.
Eigen::Matrix3d LookAtRotation(const Eigen::Vector3d& direction, double roll) {
  const Eigen::Vector3d forward = -direction.normalized();
  const Eigen::Vector3d helper = std::abs(forward.z()) < 0.9 ? Eigen::Vector3d::UnitZ()
                                                             : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x0 = helper.cross(forward).normalized();
  const Eigen::Vector3d y0 = forward.cross(x0);   // x0 × y0 = forward
  Eigen::Matrix3d model_from_camera;
  model_from_camera.col(0) = std::cos(roll) * x0 + std::sin(roll) * y0;
  model_from_camera.col(1) = -std::sin(roll) * x0 + std::cos(roll) * y0;
  model_from_camera.col(2) = forward;
  return model_from_camera.transpose();
}

double MaxDistance(const ObjectModel& object, const PointSet& cloud, const Pose& pose) {
  return object.DistancesToPosedModel(cloud, pose).maxCoeff();
}

// Model-frame rotation about `centre`: p -> R (p - c) + c.
Pose AboutCentre(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& centre) {
  return {rotation, centre - rotation * centre};
}

// The 24 rotations of the cube: signed permutation matrices with det +1.
std::vector<Eigen::Matrix3d> CubeGroup() {
  std::vector<Eigen::Matrix3d> group;
  const int permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& perm : permutations) {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) m(r, perm[r]) = (signs >> r) & 1 ? -1.0 : 1.0;
      if (m.determinant() > 0) group.push_back(m);
    }
  }
  return group;
}

// Centroid and principal axes (columns by increasing extent, right-handed) of
// the object's surface sample. (With decreasing extent, or with other training
// seeds, the rendered views differ; before DegeneracyOptions::near_factor some
// of those runs learned a set that accepted an independent face-on box view:
// docs/method.md "Deliberate degenerate views".)
std::pair<Eigen::Vector3d, Eigen::Matrix3d> SurfacePrincipalAxes(const ObjectModel& object) {
  const PointSet& sample = object.sample();
  const Eigen::Vector3d centroid = sample.rowwise().mean();
  const PointSet centred = sample.colwise() - centroid;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca(centred * centred.transpose());
  Eigen::Matrix3d axes = pca.eigenvectors();
  if (axes.determinant() < 0) axes.col(0) = -axes.col(0);
  return {centroid, axes};
}

constexpr std::uint64_t kDeliberateSeedSalt = 0x9e3779b97f4a7c15ULL;
constexpr int kDeliberatePoints = 2000;

// Outward normals of the large planar patches of the mesh: triangles binned
// by quantised normal (cells of about `angle` radians on a latitude/longitude
// grid) and plane offset (cells of 2 % of d); bins holding at least
// `min_fraction` of the area, largest first.
std::vector<Eigen::Vector3d> PlanarPatchNormals(const ObjectModel& object, double angle, double min_fraction,
                                                int max_patches) {
  const Mesh& mesh = object.mesh();
  const Eigen::Vector3d centre = object.sample().rowwise().mean();
  const double offset_cell = 0.02 * object.diameter();
  struct Bin {
    Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();   // area-weighted
    Eigen::Vector3d centroid_sum = Eigen::Vector3d::Zero();
    double area = 0.0;
  };
  std::map<std::tuple<long, long, long>, Bin> bins;
  double total = 0.0;
  for (Eigen::Index t = 0; t < mesh.triangles.cols(); ++t) {
    const Eigen::Vector3d a = mesh.vertices.col(mesh.triangles(0, t));
    const Eigen::Vector3d b = mesh.vertices.col(mesh.triangles(1, t));
    const Eigen::Vector3d c = mesh.vertices.col(mesh.triangles(2, t));
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double area = 0.5 * cross.norm();
    if (!(area > 0) || !std::isfinite(area)) continue;
    total += area;
    const Eigen::Vector3d n = cross.normalized();
    const Eigen::Vector3d mid = (a + b + c) / 3.0;
    const double polar = std::acos(std::clamp(n.z(), -1.0, 1.0));
    const long polar_bin = std::lround(polar / angle);
    // Longitude cells shrink towards the poles: as many as fit at this latitude.
    const long ring = std::max(1L, std::lround(2.0 * kPi * std::sin(polar_bin * angle) / angle));
    const long azimuth_bin =
        (polar_bin == 0 || polar_bin * angle >= kPi - 1e-9) ? 0 : std::lround((std::atan2(n.y(), n.x()) + kPi) / (2 * kPi) * ring) % ring;
    const long offset_bin = std::lround(n.dot(mid) / offset_cell);
    Bin& bin = bins[{polar_bin, azimuth_bin, offset_bin}];
    bin.normal_sum += area * n;
    bin.centroid_sum += area * mid;
    bin.area += area;
  }
  std::vector<std::pair<double, Eigen::Vector3d>> patches;
  for (const auto& [key, bin] : bins) {
    if (bin.area < min_fraction * total || bin.normal_sum.norm() < 1e-12) continue;
    Eigen::Vector3d n = bin.normal_sum.normalized();
    // Outward: the patch lies on the normal's side of the object's centre
    // (meshes are not always wound consistently).
    if (n.dot(bin.centroid_sum / bin.area - centre) < 0) n = -n;
    patches.emplace_back(bin.area, n);
  }
  std::stable_sort(patches.begin(), patches.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  std::vector<Eigen::Vector3d> normals;
  for (const auto& patch : patches) {
    if (static_cast<int>(normals.size()) >= max_patches) break;
    normals.push_back(patch.second);
  }
  return normals;
}

}  // namespace

const char* ToString(ViewKind kind) {
  switch (kind) {
    case ViewKind::kRandom: return "random";
    case ViewKind::kFaceOn: return "face-on";
    case ViewKind::kEdgeOn: return "edge-on";
    case ViewKind::kCorner: return "corner";
    case ViewKind::kPartial: return "partial";
  }
  return "?";
}

void DeliberateViewOptions::Check() const {
  if (!(min_patch_fraction > 0 && min_patch_fraction < 1)) throw InputError("min_patch_fraction", "must be in (0, 1)");
  if (!(patch_angle_deg > 0 && patch_angle_deg <= 45)) throw InputError("patch_angle_deg", "must be in (0, 45]");
  if (!(min_separation_deg >= 0 && min_separation_deg < 60)) throw InputError("min_separation_deg", "must be in [0, 60)");
  if (max_patches < 0) throw InputError("max_patches", "must be >= 0");
}

std::vector<DeliberateView> DeliberateViews(const ObjectModel& object, const DeliberateViewOptions& options) {
  options.Check();
  const double separation = std::cos(options.min_separation_deg * kPi / 180.0);
  std::vector<DeliberateView> views;
  // Adds a view unless one of the same kind looks (almost) the same way.
  const auto add = [&](ViewKind kind, const Eigen::Vector3d& direction, std::vector<Eigen::Vector3d>* kept) {
    if (!(direction.norm() > 1e-9)) return;
    const Eigen::Vector3d d = direction.normalized();
    for (const Eigen::Vector3d& other : *kept) {
      if (other.dot(d) > separation) return;
    }
    kept->push_back(d);
    views.push_back({kind, d, -1});
  };
  const Eigen::Matrix3d axes = SurfacePrincipalAxes(object).second;
  std::vector<Eigen::Vector3d> faces;
  for (int k = 0; k < 3; ++k) {
    for (double sign : {1.0, -1.0}) add(ViewKind::kFaceOn, sign * axes.col(k), &faces);
  }
  for (const Eigen::Vector3d& n : PlanarPatchNormals(object, options.patch_angle_deg * kPi / 180.0,
                                                     options.min_patch_fraction, options.max_patches)) {
    add(ViewKind::kFaceOn, n, &faces);
  }
  std::vector<Eigen::Vector3d> edges;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    for (std::size_t j = i + 1; j < faces.size(); ++j) {
      const double cosine = faces[i].dot(faces[j]);
      if (cosine > -0.5 && cosine < 0.5) add(ViewKind::kEdgeOn, faces[i] + faces[j], &edges);
    }
  }
  std::vector<Eigen::Vector3d> corners;
  for (int signs = 0; signs < 8; ++signs) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) d += ((signs >> k) & 1 ? -1.0 : 1.0) * axes.col(k);
    add(ViewKind::kCorner, d, &corners);
  }
  if (options.partial) {
    std::vector<Eigen::Vector3d> occluded = faces;
    occluded.insert(occluded.end(), corners.begin(), corners.end());
    for (const Eigen::Vector3d& d : occluded) {
      for (int axis : {0, 1}) views.push_back({ViewKind::kPartial, d, axis});
    }
  }
  return views;
}

RenderedView RenderDeliberateView(const ObjectModel& object, const ViewSamplingOptions& options,
                                  double noise_sigma, const DeliberateView& deliberate, int index,
                                  DepthRenderer* renderer) {
  const Eigen::Vector3d centre = object.mesh().BoundingBox().center();
  double distance = 0.5 * (options.distance_min + options.distance_max);
  if (options.distance_min <= 0 && options.distance_max <= 0) {
    distance = options.camera.fy * object.diameter() / (0.4 * options.camera.height);   // as RenderView's D0
  }
  Rng rng = Rng::ForItem(options.seed ^ kDeliberateSeedSalt, static_cast<std::uint64_t>(index));
  RenderedView view;
  view.direction = deliberate.direction.normalized();
  DepthSampleOptions sampling;
  // Densely sampled (at least kDeliberatePoints): a degenerate view blocks
  // exactly the indicator sets it sees, so a keypoint that a sparse sample
  // happens to miss (a face's corner) would leave its sets unblocked while a
  // dense real cloud of the same view sees it. A partial view keeps about
  // half of the points: twice as many are drawn.
  sampling.points = std::max(options.points, kDeliberatePoints) * (deliberate.kind == ViewKind::kPartial ? 2 : 1);
  sampling.noise_sigma = std::max(0.0, noise_sigma);
  for (int attempt = 0; attempt < 20; ++attempt) {
    const double roll = rng.Uniform(0.0, 2.0 * kPi);
    Pose camera_from_model;
    camera_from_model.R = LookAtRotation(view.direction, roll);
    camera_from_model.t = -(camera_from_model.R * (centre + distance * view.direction));
    renderer->Render(object.mesh(), camera_from_model);
    view.camera_from_model = camera_from_model;
    PointSet cloud = renderer->SampleCloud(sampling, rng);
    if (deliberate.kind == ViewKind::kPartial) {
      // The occluder: a plane through the centre (on the optical axis) and the
      // axis; the points on its negative side are hidden.
      const int axis = deliberate.cut_axis == 1 ? 1 : 0;
      std::vector<Eigen::Index> kept;
      for (Eigen::Index i = 0; i < cloud.cols(); ++i) {
        if (cloud(axis, i) >= 0.0) kept.push_back(i);
      }
      PointSet cut(3, static_cast<Eigen::Index>(kept.size()));
      for (std::size_t i = 0; i < kept.size(); ++i) cut.col(static_cast<Eigen::Index>(i)) = cloud.col(kept[i]);
      cloud = std::move(cut);
    }
    view.cloud = std::move(cloud);
    if (view.cloud.cols() >= options.min_points) break;
  }
  return view;
}

void ViewSamplingOptions::Check() const {
  if (views < 1 || views > 1000000) throw InputError("--views", "must be in [1, 1000000]");
  if (points < 10) throw InputError("--points", "must be at least 10");
  if (!std::isfinite(noise_sigma)) throw InputError("--noise", "must be finite");
  if (!(std::isfinite(distance_min) && std::isfinite(distance_max) && distance_min >= 0 &&
        distance_max >= distance_min)) {
    throw InputError("--distance", "need 0 <= min <= max");
  }
  if (min_points < 3) throw InputError("min_points", "must be at least 3");
  camera.Check();
}

RenderedView RenderView(const ObjectModel& object, const ViewSamplingOptions& options,
                        double noise_sigma, int index, DepthRenderer* renderer) {
  const Eigen::AlignedBox3d box = object.mesh().BoundingBox();
  const Eigen::Vector3d centre = box.center();
  const double d = object.diameter();
  double near = options.distance_min, far = options.distance_max;
  if (near <= 0 && far <= 0) {
    // As c3po synth: the diameter spans 40 % of the image height at D0.
    const double d0 = options.camera.fy * d / (0.4 * options.camera.height);
    near = 0.5 * d0;
    far = 1.5 * d0;
  }
  Rng rng = Rng::ForItem(options.seed, static_cast<std::uint64_t>(index));
  RenderedView view;
  view.direction = FibonacciDirection(index % options.views, options.views);
  DepthSampleOptions sampling;
  sampling.points = options.points;
  sampling.noise_sigma = std::max(0.0, noise_sigma);
  for (int attempt = 0; attempt < 20; ++attempt) {
    const double roll = rng.Uniform(0.0, 2.0 * kPi);
    const double distance = rng.Uniform(near, far);
    Pose camera_from_model;
    camera_from_model.R = LookAtRotation(view.direction, roll);
    camera_from_model.t = -(camera_from_model.R * (centre + distance * view.direction));
    renderer->Render(object.mesh(), camera_from_model);
    view.camera_from_model = camera_from_model;
    view.cloud = renderer->SampleCloud(sampling, rng);
    if (view.cloud.cols() >= options.min_points) break;
  }
  return view;
}

void DegeneracyOptions::Check() const {
  if (!(std::isfinite(eps_oc) && std::isfinite(delta_nd))) throw InputError("thresholds", "must be finite");
  if (!(tolerance_factor >= 1.0 && std::isfinite(tolerance_factor))) {
    throw InputError("--tolerance", "must be at least 1 (times eps_oc)");
  }
  if (!(near_factor >= 1.0 && std::isfinite(near_factor))) throw InputError("--near-factor", "must be at least 1");
  if (screening_iterations < 1) throw InputError("screening_iterations", "must be positive");
  if (!(screening_factor > 0 && std::isfinite(screening_factor))) throw InputError("screening_factor", "must be positive");
  if (search_points < 10) throw InputError("search_points", "must be at least 10");
  if (hausdorff_points < 10) throw InputError("hausdorff_points", "must be at least 10");
  icp.Check();
}

std::vector<Pose> DegeneracySearchMotions(const ObjectModel& object) {
  const auto [centroid, axes] = SurfacePrincipalAxes(object);   // principal frame, columns

  std::vector<Pose> motions;
  for (const Eigen::Matrix3d& m : CubeGroup()) {   // the identity comes first
    motions.push_back(AboutCentre(axes * m * axes.transpose(), centroid));
  }
  for (int k = 0; k < 3; ++k) {
    for (int step : {1, 3, 5, 7}) {
      const Eigen::AngleAxisd turn(step * kPi / 4.0, axes.col(k));
      motions.push_back(AboutCentre(turn.toRotationMatrix(), centroid));
    }
  }
  const double shift = 0.25 * object.diameter();
  for (int k = 0; k < 3; ++k) {
    for (double sign : {-1.0, 1.0}) motions.push_back({Eigen::Matrix3d::Identity(), sign * shift * axes.col(k)});
  }
  return motions;
}

ViewDegeneracy AnalyzeViewDegeneracy(const ObjectModel& object, const PointSet& cloud,
                                     const Pose& scene_from_model,
                                     const std::vector<Pose>& motions,
                                     const DegeneracyOptions& options) {
  options.Check();
  if (!(options.eps_oc > 0 && options.delta_nd > 0)) {
    throw std::invalid_argument("AnalyzeViewDegeneracy: resolve eps_oc and delta_nd first");
  }
  if (object.num_keypoints() > 64) throw InputError(object.name(), "automatic indicator sets support at most 64 keypoints");
  ViewDegeneracy result;
  if (cloud.cols() < 3 || !cloud.allFinite()) return result;   // not usable
  const Eigen::VectorXd keypoint_distances = DistancesToCloud(scene_from_model * object.keypoints(), cloud);
  for (Eigen::Index i = 0; i < keypoint_distances.size(); ++i) {
    if (keypoint_distances(i) < options.delta_nd) result.seen_mask |= std::uint64_t{1} << i;
    if (keypoint_distances(i) < options.near_factor * options.delta_nd) result.near_mask |= std::uint64_t{1} << i;
  }
  result.true_fit = MaxDistance(object, cloud, scene_from_model);
  result.usable = result.true_fit < options.eps_oc;
  if (!result.usable) return result;

  // Starts: model-frame motions composed with the truth, and shifts of the
  // truth along the viewing ray by fractions of the object's depth extent there.
  std::vector<Pose> starts;
  for (const Pose& motion : motions) starts.push_back(scene_from_model * motion);
  const Eigen::Vector3d ray = cloud.rowwise().mean().normalized();
  const Eigen::VectorXd depth = ray.transpose() * (scene_from_model * StridedColumns(object.sample(), 2000));
  const double extent = depth.maxCoeff() - depth.minCoeff();
  for (double fraction : {-1.0, -0.5, 0.5, 1.0}) {
    starts.push_back(Pose{Eigen::Matrix3d::Identity(), fraction * extent * ray} * scene_from_model);
  }

  const PointSet search_cloud = StridedColumns(cloud, options.search_points);
  const PointSet queries = StridedColumns(object.sample(), options.hausdorff_points);
  const double tolerance = options.tolerance_factor * options.eps_oc;
  IcpOptions screening = options.icp;
  screening.max_iterations = std::min(options.icp.max_iterations, options.screening_iterations);
  for (const Pose& start : starts) {
    ++result.starts;
    // A short first run drops starts that are still far from any fit (an RMS
    // above the screening factor times eps_oc), then the rest refines.
    IcpResult icp = RefineIcp(object, search_cloud, start, screening);
    if (!icp.ok() || !icp.scene_from_model.IsFinite()) continue;
    if (!icp.converged) {
      if (icp.rms_after > options.screening_factor * options.eps_oc) continue;
      icp = RefineIcp(object, search_cloud, icp.scene_from_model, options.icp);
      if (!icp.ok() || !icp.scene_from_model.IsFinite()) continue;
    }
    if (MaxDistance(object, cloud, icp.scene_from_model) >= options.eps_oc) continue;
    ++result.fitting_starts;
    const double hausdorff = PosedModelHausdorff(object, queries, scene_from_model, icp.scene_from_model);
    if (hausdorff > result.worst_hausdorff) {
      result.worst_hausdorff = hausdorff;
      result.worst_pose = icp.scene_from_model;
    }
    // One far fitting pose settles it; the remaining starts cannot undo it.
    if (result.worst_hausdorff > tolerance) break;
  }
  result.degenerate = result.worst_hausdorff > tolerance;
  return result;
}

}  // namespace c3po
