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

// Candidate rotations (model frame, about the origin; the caller centres them).
std::vector<Eigen::Matrix3d> CandidateRotations(const PrincipalFrame& frame, int max_order) {
  std::vector<Eigen::Matrix3d> candidates;
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d u = frame.axes.col(axis).normalized();
    for (int n = 2; n <= max_order; ++n) {
      for (int k = 1; k < n; ++k) {
        candidates.push_back(Eigen::AngleAxisd(2.0 * M_PI * k / n, u).toRotationMatrix());
      }
    }
  }
  // Signed permutations of the principal axes with determinant +1.
  const int permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : permutations) {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) A(r, p[r]) = (signs >> r) & 1 ? -1.0 : 1.0;
      if (A.determinant() < 0) continue;
      candidates.push_back(frame.axes * A * frame.axes.transpose());
    }
  }
  return candidates;
}

bool SameRotation(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return RotationAngle(a.transpose() * b) < 0.5 * M_PI / 180.0;
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
  std::vector<ModelSymmetry> symmetries;
  for (const Eigen::Matrix3d& R : CandidateRotations(frame, options.max_order)) {
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
    // Polishing may land two candidates on the same symmetry: keep it once.
    const Eigen::Matrix3d& polished = symmetry.model_from_model.R;
    if (SameRotation(polished, Eigen::Matrix3d::Identity())) continue;
    const auto same = std::find_if(symmetries.begin(), symmetries.end(), [&](const ModelSymmetry& s) {
      return SameRotation(polished, s.model_from_model.R);
    });
    if (same != symmetries.end()) {
      if (symmetry.hausdorff < same->hausdorff) *same = symmetry;
      continue;
    }
    symmetries.push_back(symmetry);
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
