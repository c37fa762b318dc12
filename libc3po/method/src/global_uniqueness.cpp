// Global uniqueness: the rival search of nd (global_uniqueness.hpp).
#include "c3po/method/global_uniqueness.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

#include "c3po/base/parallel.hpp"
#include "c3po/geometry/registration.hpp"
#include "c3po/method/pipeline.hpp"

namespace c3po {

void GlobalUniquenessOptions::Check() const {
  if (steps < 2 || steps > 36 || steps % 2 != 0) {
    throw std::invalid_argument("global uniqueness steps must be even and in [2, 36]");
  }
  if (!(rival_distance >= 0.0 && std::isfinite(rival_distance))) {
    throw std::invalid_argument("global uniqueness rival distance must be >= 0");
  }
  if (!(tolerance >= 0.0 && std::isfinite(tolerance))) throw std::invalid_argument("tolerance must be >= 0");
  if (!(rival_extra_fraction >= 0.0 && rival_extra_fraction < 1.0)) {
    throw std::invalid_argument("global uniqueness rival slack must be in [0, 1)");
  }
  if (rival_extra_min < 0) throw std::invalid_argument("global uniqueness rival slack floor must be >= 0");
  if (reestimate_steps < 2 || reestimate_steps > 36 || reestimate_steps % 2 != 0) {
    throw std::invalid_argument("re-estimation steps must be even and in [2, 36]");
  }
}

double GlobalUniquenessOptions::Tolerance(double eps_oc, double diameter) const {
  if (tolerance > 0.0) return tolerance;
  return std::max(kDefaultToleranceFraction * diameter, 3.0 * eps_oc);
}

double GlobalUniquenessOptions::RivalDistance(double eps_oc, double diameter) const {
  if (rival_distance > 0.0) return rival_distance;
  return std::max(Tolerance(eps_oc, diameter) - eps_oc, 0.0);
}

int GlobalUniquenessOptions::RivalSlack(Eigen::Index n) const {
  return std::max(static_cast<int>(std::floor(rival_extra_fraction * static_cast<double>(n))), rival_extra_min);
}

PrincipalFrame ModelPrincipalFrame(const ObjectModel& object) {
  const PointSet& sample = object.sample();
  PrincipalFrame frame;
  frame.centroid = sample.rowwise().mean();
  const PointSet centred = sample.colwise() - frame.centroid;
  const Eigen::Matrix3d covariance = centred * centred.transpose() / std::max<double>(1.0, sample.cols());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  // Eigen sorts eigenvalues increasingly; axis 0 = largest extent.
  for (int a = 0; a < 3; ++a) frame.axes.col(a) = solver.eigenvectors().col(2 - a);
  if (frame.axes.determinant() < 0) frame.axes.col(2) = -frame.axes.col(2);   // right-handed
  return frame;
}

namespace {

// Axis `axis` of the rival search: a principal axis (0-2) or a diagonal of
// the principal frame (3-12, ReestimateAxes), unit.
Eigen::Vector3d SearchAxis(const PrincipalFrame& frame, int axis) {
  if (axis < 0 || axis > 12) throw std::invalid_argument("rival search axis must be in [0, 12]");
  if (axis < 3) return frame.axes.col(axis).normalized();
  return ReestimateAxes(frame).col(axis);
}

}  // namespace

Pose AxisRotation(const PrincipalFrame& frame, int axis, double angle) {
  const Eigen::Vector3d u = SearchAxis(frame, axis);
  Pose turn;
  turn.R = Eigen::AngleAxisd(angle, u).toRotationMatrix();
  turn.t = frame.centroid - turn.R * frame.centroid;
  return turn;
}

Pose HalfTurn(const PrincipalFrame& frame, int axis) {
  const Eigen::Vector3d u = SearchAxis(frame, axis);
  // Rotation by pi about u: 2 u u^T - I (exact).
  Pose flip;
  flip.R = 2.0 * u * u.transpose() - Eigen::Matrix3d::Identity();
  flip.t = frame.centroid - flip.R * frame.centroid;
  return flip;
}

std::vector<std::pair<int, double>> RivalHypotheses(const GlobalUniquenessOptions& options) {
  options.Check();
  std::vector<std::pair<int, double>> hypotheses;
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = 1; k < options.steps; ++k) hypotheses.emplace_back(axis, 2.0 * M_PI * k / options.steps);
  }
  for (int axis = 3; axis < 13; ++axis) hypotheses.emplace_back(axis, M_PI);
  hypotheses.emplace_back(0, 0.0);   // T̂ itself: its refit must not settle beyond rival_distance
  return hypotheses;
}

Eigen::Matrix<double, 3, 13> ReestimateAxes(const PrincipalFrame& frame) {
  const Eigen::Matrix3d& a = frame.axes;
  Eigen::Matrix<double, 3, 13> axes;
  int k = 0;
  for (int i = 0; i < 3; ++i) axes.col(k++) = a.col(i).normalized();
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) {
      axes.col(k++) = (a.col(i) + a.col(j)).normalized();
      axes.col(k++) = (a.col(i) - a.col(j)).normalized();
    }
  }
  for (int s1 : {1, -1}) {
    for (int s2 : {1, -1}) axes.col(k++) = (a.col(0) + s1 * a.col(1) + s2 * a.col(2)).normalized();
  }
  return axes;
}

Pose CentreOfFits(const ObjectModel& object, const std::vector<Pose>& poses) {
  if (poses.empty()) throw std::invalid_argument("CentreOfFits needs at least one pose");
  const Eigen::Vector3d centroid = object.sample().rowwise().mean();
  Eigen::Matrix3d rotation_sum = Eigen::Matrix3d::Zero();
  Eigen::Vector3d posed_centroid = Eigen::Vector3d::Zero();
  for (const Pose& pose : poses) {
    rotation_sum += pose.R;
    posed_centroid += pose.R * centroid + pose.t;
  }
  posed_centroid /= static_cast<double>(poses.size());
  // argmax_R tr(R^T sum): R = U diag(1, 1, det(U V^T)) V^T (the chordal mean).
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotation_sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d sign = Eigen::Matrix3d::Identity();
  sign(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  Pose centre;
  centre.R = svd.matrixU() * sign * svd.matrixV().transpose();
  centre.t = posed_centroid - centre.R * centroid;
  return centre;
}

std::vector<RivalFit> FitRivals(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                const PipelineOptions& pipeline, const std::vector<RivalStart>& starts, bool refine,
                                const PointSet* evidence) {
  const PointSet& judged = evidence ? *evidence : cloud;
  PipelineOptions rival_options = pipeline;
  rival_options.correct = refine;   // a refined rival is where the corrector settles from the start
  rival_options.certificate.global.enabled = false;
  rival_options.certificate.global.reestimate = false;
  rival_options.certificate.global.centre = false;
  rival_options.certificate.local_nondegeneracy = false;   // only the rival's oc is needed
  // The rivals' budget: m + the slack (global_uniqueness.hpp).
  const int m = pipeline.certificate.max_outliers.Resolve(judged.cols());
  rival_options.certificate.max_outliers = OutlierBudget{};
  rival_options.certificate.max_outliers.count = m + pipeline.certificate.global.RivalSlack(judged.cols());
  const PointSet queries = StridedColumns(object.sample(), 1000);
  // The starts are independent: both cores for one pose (inline inside a
  // batch's worker, parallel.hpp); each fit goes to its own slot.
  std::vector<RivalFit> fits(starts.size());
  ParallelFor(0, static_cast<int>(starts.size()), [&](int i) {
    const RivalStart& start = starts[static_cast<std::size_t>(i)];
    RivalFit& fit = fits[static_cast<std::size_t>(i)];
    fit.axis = start.axis;
    fit.angle = start.angle;
    fit.start = start.scene_from_model;
    const PoseEstimate rival = EstimateAndCertify(object, cloud, start.scene_from_model * object.keypoints(),
                                                  rival_options, nullptr, evidence);
    fit.ok = rival.ok();
    if (fit.ok) {
      fit.scene_from_model = rival.scene_from_model;
      fit.keypoints = rival.keypoints;
      fit.passes_oc = rival.certificate.oc.passed;
      fit.outliers = rival.certificate.oc.outlier_count;
      fit.budget_distance = rival.certificate.oc.budget_distance;
      fit.keypoint_distance = (rival.keypoints - estimate.keypoints).colwise().norm().maxCoeff();
      fit.hausdorff = PosedModelHausdorff(object, queries, estimate.scene_from_model, rival.scene_from_model);
    }
  });
  return fits;
}

std::vector<RivalFit> RefineRivals(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                   const PipelineOptions& pipeline, const PrincipalFrame& frame,
                                   const std::vector<std::pair<int, double>>& hypotheses) {
  std::vector<RivalStart> starts;
  starts.reserve(hypotheses.size());
  for (const auto& [axis, angle] : hypotheses) {
    const Pose turn = std::abs(angle - M_PI) < 1e-12 ? HalfTurn(frame, axis) : AxisRotation(frame, axis, angle);
    starts.push_back({axis, angle, estimate.scene_from_model * turn});
  }
  return FitRivals(object, cloud, estimate, pipeline, starts, true);
}

namespace {

// A rival counts when it was fitted, lies beyond the distance, passes the
// rivals' oc and (depth-image inputs) the free-space test.
bool RivalCounts(const RivalFit& fit, double rival_distance, const RivalFilter* filter, int* violations) {
  *violations = -1;
  if (!fit.ok || !(fit.hausdorff > rival_distance) || !fit.passes_oc) return false;
  return !filter || filter->Passes(fit.scene_from_model, violations);
}

}  // namespace

Pose WeakMotionDisplacement(const ObjectModel& object, const Eigen::Matrix<double, 6, 1>& motion, double step) {
  // The twist's frame (local_nondegeneracy.cpp): about the sample centroid c,
  // rotation part scaled by r = d/2.
  const Eigen::Vector3d centre = object.sample().rowwise().mean();
  const double radius = std::max(0.5 * object.diameter(), 1e-12);
  const Eigen::Vector3d rotation = step * motion.head<3>() / radius;
  Pose displacement;
  const double angle = rotation.norm();
  displacement.R = angle > 0 ? Eigen::AngleAxisd(angle, rotation / angle).toRotationMatrix()
                             : Eigen::Matrix3d::Identity();
  displacement.t = centre + step * motion.tail<3>() - displacement.R * centre;
  return displacement;
}

WeakMotionCheck CheckWeakMotion(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                const PipelineOptions& pipeline, const RivalFilter* filter) {
  WeakMotionCheck check;
  if (!estimate.ok()) return check;
  const GlobalUniquenessOptions& global = pipeline.certificate.global;
  const double rival_distance = global.RivalDistance(pipeline.certificate.eps_oc, object.diameter());
  const Eigen::Matrix<double, 6, 1> motion = estimate.certificate.nd.local.motion;
  std::vector<RivalStart> starts;
  for (double step = 1.5 * rival_distance; step <= object.diameter() && step > 0; step *= 2.0) {
    for (double sign : {1.0, -1.0}) {
      starts.push_back({-1, sign * step, estimate.scene_from_model * WeakMotionDisplacement(object, motion, sign * step)});
    }
  }
  for (bool refine : {false, true}) {
    for (const RivalFit& fit : FitRivals(object, cloud, estimate, pipeline, starts, refine)) {
      ++check.starts;
      int violations = -1;
      if (RivalCounts(fit, rival_distance, filter, &violations)) {
        ++check.rivals_found;
        check.rival_poses.push_back(fit.scene_from_model);
        if (fit.hausdorff > check.rival_hausdorff) {
          check.rival_hausdorff = fit.hausdorff;
          check.rival_step = fit.angle;
          check.rival_outliers = fit.outliers;
        }
      } else if (fit.ok && fit.hausdorff > rival_distance &&
                 (check.fewest_outliers < 0 || fit.outliers < check.fewest_outliers)) {
        check.fewest_outliers = fit.outliers;
        check.fewest_outliers_step = fit.angle;
      }
    }
  }
  check.passed = !starts.empty() && check.rivals_found == 0;
  return check;
}

GlobalUniqueness CheckGlobalUniqueness(const ObjectModel& object, const PointSet& cloud, const PoseEstimate& estimate,
                                       const PipelineOptions& pipeline, const RivalFilter* filter) {
  const GlobalUniquenessOptions& options = pipeline.certificate.global;
  GlobalUniqueness global;
  global.rival_distance = options.RivalDistance(pipeline.certificate.eps_oc, object.diameter());
  if (!estimate.ok()) {
    global.passed = false;
    return global;
  }
  const std::vector<RivalFit> fits =
      RefineRivals(object, cloud, estimate, pipeline, ModelPrincipalFrame(object), RivalHypotheses(options));
  global.rivals_tried = static_cast<int>(fits.size());
  // The reported rival: counting ones first (the farthest), then the
  // distinct one with the fewest outliers, then the smallest budget distance.
  auto key = [](bool counts, const RivalFit& f) {
    return counts ? std::make_tuple(false, -f.hausdorff, 0.0) : std::make_tuple(true, double(f.outliers), f.budget_distance);
  };
  bool have_best = false;
  std::tuple<bool, double, double> best_key;
  for (const RivalFit& fit : fits) {
    if (!fit.ok || !(fit.hausdorff > global.rival_distance)) continue;   // failed, or T̂'s own basin
    int violations = -1;
    const bool counts = RivalCounts(fit, global.rival_distance, filter, &violations);
    if (counts) {
      ++global.rivals_found;
      global.rival_poses.push_back(fit.scene_from_model);
    }
    const auto fit_key = key(counts, fit);
    if (!have_best || fit_key < best_key) {
      have_best = true;
      best_key = fit_key;
      global.rival_axis = fit.axis;
      global.rival_angle_deg = fit.angle * 180.0 / M_PI;
      global.rival_hausdorff = fit.hausdorff;
      global.rival_outliers = fit.outliers;
      global.rival_budget_distance = fit.budget_distance;
      global.rival_passes_oc = fit.passes_oc;
      global.rival_free_space_violations = violations;
      global.rival_counts = counts;
      global.rival_scene_from_model = fit.scene_from_model;
    }
  }
  global.passed = global.rivals_found == 0;
  return global;
}

void AddRestartRivals(const ObjectModel& object, const std::vector<RivalFit>& fits, const Pose& scene_from_model,
                      const RivalFilter* filter, GlobalUniqueness* global) {
  const PointSet queries = StridedColumns(object.sample(), 1000);
  global->rivals_tried += static_cast<int>(fits.size());
  for (const RivalFit& fit : fits) {
    if (!fit.ok || !fit.passes_oc) continue;
    const double hausdorff = PosedModelHausdorff(object, queries, scene_from_model, fit.scene_from_model);
    if (!(hausdorff > global->rival_distance)) continue;   // the chosen pose's own basin
    int violations = -1;
    if (filter && !filter->Passes(fit.scene_from_model, &violations)) continue;
    ++global->rivals_found;
    global->rival_poses.push_back(fit.scene_from_model);
    // The report shows a rival that counts: this one, unless a farther one
    // that counts is there already (a non-counting report is replaced).
    if (global->rival_counts && !(hausdorff > global->rival_hausdorff)) continue;
    global->rival_axis = fit.axis;
    global->rival_angle_deg = fit.angle * 180.0 / M_PI;
    global->rival_hausdorff = hausdorff;
    global->rival_outliers = fit.outliers;
    global->rival_budget_distance = fit.budget_distance;
    global->rival_passes_oc = true;
    global->rival_free_space_violations = violations;
    global->rival_counts = true;
    global->rival_scene_from_model = fit.scene_from_model;
  }
  global->passed = global->rivals_found == 0;
}

}  // namespace c3po
