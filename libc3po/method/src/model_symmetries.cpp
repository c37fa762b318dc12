// Rotational symmetries of the model surface (model_symmetries.hpp).
#include "c3po/method/model_symmetries.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "c3po/geometry/registration.hpp"
#include "c3po/method/global_uniqueness.hpp"
#include "c3po/method/icp.hpp"

namespace c3po {

void SymmetrySearchOptions::Check() const {
  if (!(tolerance >= 0.0 && std::isfinite(tolerance))) throw std::invalid_argument("symmetry tolerance must be >= 0");
  if (max_order < 2 || max_order > 24) throw std::invalid_argument("symmetry max order must be in [2, 24]");
  if (queries < 1) throw std::invalid_argument("symmetry queries must be >= 1");
}

namespace {

double RotationAngle(const Eigen::Matrix3d& R) {
  return std::acos(std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0));
}

// Principal frame of the mesh surface from exact area integrals: centroid
// c = (1/A) Σ A_T (a+b+c)/3 and second moment Σ (A_T/12)[s sᵀ + a aᵀ + b bᵀ + c cᵀ]
// (s = a+b+c) per triangle. Exact where the sample's frame is off by sampling
// noise (the box's by 1.4°). Falls back to the sample's frame on a
// zero-area mesh.
PrincipalFrame SurfacePrincipalFrame(const ObjectModel& object) {
  const Mesh& mesh = object.mesh();
  double area = 0.0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (Eigen::Index f = 0; f < mesh.triangles.cols(); ++f) {
    const Eigen::Vector3d a = mesh.vertices.col(mesh.triangles(0, f));
    const Eigen::Vector3d b = mesh.vertices.col(mesh.triangles(1, f));
    const Eigen::Vector3d c = mesh.vertices.col(mesh.triangles(2, f));
    const double triangle_area = 0.5 * (b - a).cross(c - a).norm();
    const Eigen::Vector3d sum = a + b + c;
    area += triangle_area;
    first += triangle_area * sum / 3.0;
    second += triangle_area / 12.0 * (sum * sum.transpose() + a * a.transpose() + b * b.transpose() + c * c.transpose());
  }
  if (!(area > 0.0)) return ModelPrincipalFrame(object);
  PrincipalFrame frame;
  frame.centroid = first / area;
  const Eigen::Matrix3d covariance = second / area - frame.centroid * frame.centroid.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  for (int a = 0; a < 3; ++a) frame.axes.col(a) = solver.eigenvectors().col(2 - a);
  if (frame.axes.determinant() < 0) frame.axes.col(2) = -frame.axes.col(2);
  return frame;
}

// Dominant planar directions of the mesh: triangle normals (n ~ -n) grouped
// within 2°, weighted by area; the directions holding >= 5 % of the area,
// largest first, at most `count`. A cube's or a square prism's faces give
// the axes its principal frame cannot (equal extents leave the principal
// axes arbitrary in their eigenspace).
std::vector<Eigen::Vector3d> DominantNormalAxes(const Mesh& mesh, int count) {
  constexpr int kMaxClusters = 256;
  const double cos_limit = std::cos(2.0 * M_PI / 180.0);
  std::vector<Eigen::Vector3d> sums;   // area-weighted, sign-aligned normal sums
  std::vector<double> weights;
  double total = 0.0;
  for (Eigen::Index f = 0; f < mesh.triangles.cols(); ++f) {
    const Eigen::Vector3d a = mesh.vertices.col(mesh.triangles(0, f));
    const Eigen::Vector3d cross = (mesh.vertices.col(mesh.triangles(1, f)) - a)
                                      .cross(mesh.vertices.col(mesh.triangles(2, f)) - a);
    const double norm = cross.norm();
    if (!(norm > 0.0)) continue;
    const double area = 0.5 * norm;
    const Eigen::Vector3d n = cross / norm;
    total += area;
    std::size_t c = 0;
    for (; c < sums.size(); ++c) {
      const double dot = n.dot(sums[c].normalized());
      if (std::abs(dot) >= cos_limit) {
        sums[c] += (dot >= 0 ? area : -area) * n;
        weights[c] += area;
        break;
      }
    }
    if (c == sums.size() && static_cast<int>(sums.size()) < kMaxClusters) {
      sums.push_back(area * n);
      weights.push_back(area);
    }
  }
  std::vector<std::size_t> order(sums.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return weights[x] > weights[y]; });
  std::vector<Eigen::Vector3d> axes;
  for (std::size_t i : order) {
    if (static_cast<int>(axes.size()) >= count || weights[i] < 0.05 * total) break;
    axes.push_back(sums[i].normalized());
  }
  return axes;
}

// Candidate rotations (model frame, about the origin; the caller centres
// them): by 2πk/n about every axis, and the rotations mapping every frame
// onto itself (signed permutations of its axes with determinant +1).
std::vector<Eigen::Matrix3d> CandidateRotations(const std::vector<Eigen::Vector3d>& axes,
                                                const std::vector<Eigen::Matrix3d>& frames, int max_order) {
  std::vector<Eigen::Matrix3d> candidates;
  for (const Eigen::Vector3d& u : axes) {
    for (int n = 2; n <= max_order; ++n) {
      for (int k = 1; k < n; ++k) {
        candidates.push_back(Eigen::AngleAxisd(2.0 * M_PI * k / n, u.normalized()).toRotationMatrix());
      }
    }
  }
  const int permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const Eigen::Matrix3d& frame : frames) {
    for (const auto& p : permutations) {
      for (int signs = 0; signs < 8; ++signs) {
        Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
        for (int r = 0; r < 3; ++r) A(r, p[r]) = (signs >> r) & 1 ? -1.0 : 1.0;
        if (A.determinant() < 0) continue;
        candidates.push_back(frame * A * frame.transpose());
      }
    }
  }
  return candidates;
}

// The principal axes and frame, plus the dominant normal axes and the
// frames of their near-orthogonal pairs (within 2°).
std::vector<Eigen::Matrix3d> CandidateRotations(const ObjectModel& object, const PrincipalFrame& frame,
                                                int max_order) {
  std::vector<Eigen::Vector3d> axes = {frame.axes.col(0), frame.axes.col(1), frame.axes.col(2)};
  std::vector<Eigen::Matrix3d> frames = {frame.axes};
  const std::vector<Eigen::Vector3d> normals = DominantNormalAxes(object.mesh(), 3);
  axes.insert(axes.end(), normals.begin(), normals.end());
  for (std::size_t i = 0; i < normals.size(); ++i) {
    for (std::size_t j = i + 1; j < normals.size(); ++j) {
      if (std::abs(normals[i].dot(normals[j])) > std::sin(2.0 * M_PI / 180.0)) continue;
      Eigen::Matrix3d normal_frame;
      normal_frame.col(0) = normals[i];
      normal_frame.col(1) = (normals[j] - normals[j].dot(normals[i]) * normals[i]).normalized();
      normal_frame.col(2) = normal_frame.col(0).cross(normal_frame.col(1));
      frames.push_back(normal_frame);
    }
  }
  return CandidateRotations(axes, frames, max_order);
}

// Two rotations closer than this are one: polishing can leave the same
// symmetry a fraction of a degree apart from two candidates, and distinct
// candidates differ by at least 2π(1/7 - 1/8) = 6.4°.
constexpr double kSameRotation = 3.0 * M_PI / 180.0;

bool SameRotation(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return RotationAngle(a.transpose() * b) < kSameRotation;
}

// Candidates whose posed surface is within this fraction of d are polished.
constexpr double kPolishDistance = 0.1;
// Sample points of the screening pass and of the ICP polish.
constexpr int kScreenQueries = 400;

// The principal axes of a finite sample are off by up to a degree or two
// (the box's: 1.4°), which turns an exact half-turn into a 5 mm misfit. ICP
// of B̂ (400 points) onto S·B̂ from S finds the exact symmetry nearby; the polished
// rotation is kept when its surface distance is smaller.
void Polish(const ObjectModel& object, const PointSet& icp_points, const PointSet& queries, ModelSymmetry* symmetry) {
  IcpOptions options;
  options.max_iterations = 20;
  const IcpResult icp = RefineIcp(object, icp_points, symmetry->model_from_model, options);
  if (!icp.ok()) return;
  const double hausdorff = PosedSurfaceHausdorff(object, queries, Pose::Identity(), icp.scene_from_model);
  if (hausdorff < symmetry->hausdorff) {
    symmetry->model_from_model = icp.scene_from_model;
    symmetry->hausdorff = hausdorff;
  }
}

}  // namespace

std::vector<ModelSymmetry> FindModelSymmetries(const ObjectModel& object, const SymmetrySearchOptions& options) {
  options.Check();
  const PrincipalFrame frame = SurfacePrincipalFrame(object);
  const PointSet queries = StridedColumns(object.sample(), options.queries);
  // Screening: a subset's Hausdorff distance never exceeds the full set's,
  // so a candidate the subset already puts beyond every threshold is out.
  const PointSet screen = StridedColumns(object.sample(), kScreenQueries);
  const double screen_threshold = std::max(options.tolerance, kPolishDistance * object.diameter());
  std::vector<Eigen::Matrix3d> tried;
  std::vector<ModelSymmetry> accepted;
  for (const Eigen::Matrix3d& R : CandidateRotations(object, frame, options.max_order)) {
    if (SameRotation(R, Eigen::Matrix3d::Identity())) continue;
    if (std::any_of(tried.begin(), tried.end(), [&](const Eigen::Matrix3d& s) { return SameRotation(R, s); })) continue;
    tried.push_back(R);
    ModelSymmetry symmetry;
    symmetry.model_from_model.R = R;
    symmetry.model_from_model.t = frame.centroid - R * frame.centroid;
    if (PosedSurfaceHausdorff(object, screen, Pose::Identity(), symmetry.model_from_model) > screen_threshold) continue;
    symmetry.hausdorff = PosedSurfaceHausdorff(object, queries, Pose::Identity(), symmetry.model_from_model);
    if (symmetry.hausdorff <= kPolishDistance * object.diameter()) Polish(object, screen, queries, &symmetry);
    const Eigen::AngleAxisd angle_axis(symmetry.model_from_model.R);
    symmetry.angle = angle_axis.angle();
    symmetry.axis = angle_axis.axis();
    if (!(symmetry.hausdorff <= options.tolerance)) continue;
    if (SameRotation(symmetry.model_from_model.R, Eigen::Matrix3d::Identity())) continue;   // polished to identity
    accepted.push_back(symmetry);
  }
  // Polishing may land several candidates on (nearly) the same symmetry:
  // keep the best fitting of every group within kSameRotation.
  std::stable_sort(accepted.begin(), accepted.end(),
                   [](const ModelSymmetry& a, const ModelSymmetry& b) { return a.hausdorff < b.hausdorff; });
  std::vector<ModelSymmetry> symmetries;
  for (const ModelSymmetry& symmetry : accepted) {
    if (std::none_of(symmetries.begin(), symmetries.end(), [&](const ModelSymmetry& kept) {
          return SameRotation(symmetry.model_from_model.R, kept.model_from_model.R);
        })) {
      symmetries.push_back(symmetry);
    }
  }
  std::stable_sort(symmetries.begin(), symmetries.end(), [](const ModelSymmetry& a, const ModelSymmetry& b) {
    return a.angle < b.angle - 1e-9;
  });
  return symmetries;
}

std::vector<PointSet> SymmetricLabellings(const ObjectModel& object, const std::vector<ModelSymmetry>& symmetries,
                                          const PointSet& posed_keypoints) {
  if (symmetries.empty() || posed_keypoints.cols() != object.num_keypoints()) return {};
  const RegistrationResult registration = RegisterPoints(object.keypoints(), posed_keypoints);
  if (!registration.ok() || !(registration.rms_residual <= 1e-3 * object.diameter())) return {};
  std::vector<PointSet> labellings;
  labellings.reserve(symmetries.size());
  for (const ModelSymmetry& symmetry : symmetries) {
    labellings.push_back((registration.scene_from_model * symmetry.model_from_model) * object.keypoints());
  }
  return labellings;
}

Pose NearestSymmetricTruth(const Pose& truth, const Pose& estimate, const std::vector<Pose>& symmetries) {
  Pose nearest = truth;
  double best = (estimate.R.transpose() * truth.R).trace();
  for (const Pose& symmetry : symmetries) {
    const Pose candidate = truth * symmetry;
    const double trace = (estimate.R.transpose() * candidate.R).trace();
    if (trace > best) best = trace, nearest = candidate;
  }
  return nearest;
}

}  // namespace c3po
