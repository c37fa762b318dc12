// Corrector solvers (see corrector.hpp for the objective and the reduction
// that the fast solver relies on).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "c3po/corrector.hpp"
#include "c3po/error.hpp"

namespace c3po {

const char* ToString(PointCloudLoss loss) {
  return loss == PointCloudLoss::kMeanSquared ? "mean" : "max";
}
const char* ToString(CorrectorSolver solver) {
  return solver == CorrectorSolver::kFast ? "fast" : "gd";
}
PointCloudLoss ParsePointCloudLoss(const std::string& text) {
  if (text == "mean") return PointCloudLoss::kMeanSquared;
  if (text == "max") return PointCloudLoss::kMaxSquared;
  throw InputError("--loss", "'" + text + "' must be mean or max");
}
CorrectorSolver ParseCorrectorSolver(const std::string& text) {
  if (text == "fast") return CorrectorSolver::kFast;
  if (text == "gd") return CorrectorSolver::kGradientDescent;
  throw InputError("--solver", "'" + text + "' must be fast or gd");
}

void CorrectorOptions::Check() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("CorrectorOptions: ") + what);
  };
  require(kappa >= 0 && std::isfinite(kappa), "kappa must be >= 0");
  require(theta >= 0 && std::isfinite(theta), "theta must be >= 0");
  require(gd_step > 0 && std::isfinite(gd_step), "gd_step must be > 0");
  require(gd_max_iterations >= 0, "gd_max_iterations must be >= 0");
  require(gd_tolerance >= 0, "gd_tolerance must be >= 0");
  require(fast_max_iterations >= 0, "fast_max_iterations must be >= 0");
  require(fast_tolerance >= 0, "fast_tolerance must be >= 0");
  require(fast_subsample >= 0, "fast_subsample must be >= 0");
}

namespace {

// Every k-th column, so the subset is deterministic and spread over the cloud.
PointSet StridedSubset(const PointSet& cloud, int max_points) {
  if (max_points <= 0 || cloud.cols() <= max_points) return cloud;
  PointSet subset(3, max_points);
  const double stride = static_cast<double>(cloud.cols()) / max_points;
  for (int i = 0; i < max_points; ++i) subset.col(i) = cloud.col(static_cast<Eigen::Index>(i * stride));
  return subset;
}

struct PoseFit {
  double loss = std::numeric_limits<double>::infinity();
  Eigen::VectorXd squared;       // per point
  PointSet matched_model_points; // nearest B̂ point of each input point (model frame)
};

PoseFit FitAtPose(const ObjectModel& object, const PointSet& cloud, const Pose& pose,
                  PointCloudLoss loss) {
  PoseFit fit;
  Eigen::VectorXi nearest;
  object.NearestInPosedModel(cloud, pose, &nearest, &fit.squared);
  fit.matched_model_points.resize(3, cloud.cols());
  for (Eigen::Index j = 0; j < cloud.cols(); ++j) {
    fit.matched_model_points.col(j) = object.sample().col(nearest(j));
  }
  fit.loss = loss == PointCloudLoss::kMeanSquared ? fit.squared.mean() : fit.squared.maxCoeff();
  return fit;
}

// One stage of majorise-minimise steps on a fixed point set: re-associate,
// then the weighted closed-form registration of eq. (8). With unit weights
// each step cannot increase the mean loss (ICP); with IRLS weights
// w_j = d_j^(p-2) it minimises sum d_j^p, which tends to the max loss.
struct StageResult {
  Pose pose;
  double loss;
  int iterations = 0;
  bool converged = false;
};

StageResult RunStage(const ObjectModel& object, const PointSet& points, Pose pose,
                     PointCloudLoss loss, double irls_power, int max_iterations,
                     double tolerance) {
  PoseFit fit = FitAtPose(object, points, pose, loss);
  StageResult best{pose, fit.loss};
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    Eigen::VectorXd weights;
    if (irls_power > 2.0) {
      const double scale = std::max(fit.squared.maxCoeff(), 1e-300);
      weights = (fit.squared / scale).array().pow(0.5 * (irls_power - 2.0)).matrix();
      weights = weights.cwiseMax(1e-12);
    }
    const RegistrationResult step = RegisterPoints(fit.matched_model_points, points, weights);
    ++best.iterations;
    if (!step.ok()) break;
    pose = step.scene_from_model;
    const double previous = fit.loss;
    fit = FitAtPose(object, points, pose, loss);
    if (fit.loss < best.loss) {
      best.pose = pose;
      best.loss = fit.loss;
    }
    if (std::abs(previous - fit.loss) <= tolerance * std::max(previous, 1e-300)) {
      best.converged = true;
      break;
    }
  }
  return best;
}

// Gauss-Newton on the point-to-plane residuals r_j = m_j·(x_j - s_j), with
// s_j = R p_j + t the nearest posed sample point and m_j = R n_j its normal.
// For the update R <- Exp(ω) R, t <- Exp(ω) t + v the Jacobian of r_j is
// [ (m_j × x_j)^T, -m_j^T ] (the normal moves with the model). Converges in a
// few steps near the optimum; the point-to-point stage then polishes.
StageResult RunPointToPlaneStage(const ObjectModel& object, const PointSet& points, Pose pose,
                                 int max_iterations, double tolerance) {
  StageResult best{pose, std::numeric_limits<double>::infinity()};
  double previous = std::numeric_limits<double>::infinity();
  Eigen::VectorXi nearest;
  Eigen::VectorXd squared;
  // One nearest-neighbour query per step: it gives both the loss at the
  // current pose and the linearisation for the next step.
  for (int iteration = 0; iteration <= max_iterations; ++iteration) {
    object.NearestInPosedModel(points, pose, &nearest, &squared);
    const double loss = squared.mean();
    if (loss < best.loss) {
      best.loss = loss;
      best.pose = pose;
    }
    if (std::isfinite(previous) && std::abs(previous - loss) <= tolerance * std::max(previous, 1e-300)) {
      best.converged = true;
      break;
    }
    if (iteration == max_iterations) break;
    previous = loss;
    Eigen::Matrix<double, 6, 6> JtJ = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> Jtr = Eigen::Matrix<double, 6, 1>::Zero();
    for (Eigen::Index j = 0; j < points.cols(); ++j) {
      const Eigen::Vector3d x = points.col(j);
      const Eigen::Vector3d m = pose.R * object.sample_normals().col(nearest(j));
      const Eigen::Vector3d s = pose.R * object.sample().col(nearest(j)) + pose.t;
      Eigen::Matrix<double, 6, 1> J;
      J << m.cross(x), -m;
      const double r = m.dot(x - s);
      JtJ.noalias() += J * J.transpose();
      Jtr.noalias() += J * r;
    }
    // Levenberg damping keeps the step bounded on near-degenerate views.
    JtJ.diagonal().array() += 1e-6 * (JtJ.trace() / 6.0 + 1e-12);
    const Eigen::Matrix<double, 6, 1> delta = JtJ.ldlt().solve(-Jtr);
    if (!delta.allFinite()) break;
    const double angle = delta.head<3>().norm();
    const Eigen::Matrix3d step_rotation =
        angle > 0 ? Eigen::AngleAxisd(angle, delta.head<3>() / angle).toRotationMatrix()
                  : Eigen::Matrix3d::Identity();
    pose.R = step_rotation * pose.R;
    pose.t = step_rotation * pose.t + delta.tail<3>();
    ++best.iterations;
  }
  return best;
}

CorrectorResult SolveFast(const ObjectModel& object, const PointSet& cloud, const Pose& start,
                          const CorrectorOptions& options, CorrectorResult result) {
  Pose pose = start;
  int iterations = 0;
  bool converged = false;
  const PointSet subset = StridedSubset(cloud, options.fast_subsample);
  const int budget = options.fast_max_iterations;
  if (options.loss == PointCloudLoss::kMeanSquared) {
    // Coarse: point-to-plane Gauss-Newton on a subset; fine: point-to-point
    // majorise-minimise steps on every point (the objective itself).
    const StageResult coarse = RunPointToPlaneStage(object, subset, pose, budget / 4, 1e-3);
    pose = coarse.pose;
    iterations += coarse.iterations;
    const StageResult fine = RunPointToPlaneStage(object, cloud, pose, budget / 4, 1e-4);
    pose = fine.pose;
    iterations += fine.iterations;
    const StageResult polish = RunStage(object, cloud, pose, options.loss, 2.0,
                                        std::min(10, budget - iterations), options.fast_tolerance);
    pose = polish.pose;
    iterations += polish.iterations;
    converged = fine.converged;
  } else {
    // IRLS continuation towards the max: p = 2, 4, 8, 16, 32, then keep the
    // pose with the lowest true max loss.
    const StageResult mean_stage = RunStage(object, subset, pose, PointCloudLoss::kMeanSquared,
                                            2.0, budget / 4, 1e-4);
    pose = mean_stage.pose;
    iterations += mean_stage.iterations;
    Pose best_pose = start;
    double best_loss = FitAtPose(object, cloud, start, options.loss).loss;
    for (double power : {4.0, 8.0, 16.0, 32.0}) {
      const int stage_budget = std::max(1, (budget - iterations) / 4);
      const StageResult stage = RunStage(object, cloud, pose, options.loss, power, stage_budget,
                                         options.fast_tolerance);
      pose = stage.pose;
      iterations += stage.iterations;
      converged = stage.converged;
      if (stage.loss < best_loss) {
        best_loss = stage.loss;
        best_pose = stage.pose;
      }
    }
    pose = best_pose;
  }
  // Return y* = T·b: L_kp = 0 and f = kappa L_pc(T) (corrector.hpp).
  const PointSet posed = pose * object.keypoints();
  const CorrectorObjectiveTerms final_terms =
      EvaluateCorrectorObjective(object, cloud, posed, options);
  result.keypoints = posed;
  result.scene_from_model = final_terms.scene_from_model;
  result.posed_keypoints = posed;
  result.cost_after = final_terms.value;
  result.point_cloud_loss = final_terms.point_cloud_loss;
  result.keypoint_loss = final_terms.keypoint_loss;
  result.iterations = iterations;
  result.converged = converged;
  return result;
}

// The reference solver: Δy <- Δy - step ∇f(ỹ + Δy) from Δy = 0.
CorrectorResult SolveGradientDescent(const ObjectModel& object, const PointSet& cloud,
                                     const PointSet& detected, const CorrectorOptions& options,
                                     CorrectorResult result) {
  PointSet y = detected;
  PointSet gradient;
  CorrectorObjectiveTerms terms = EvaluateCorrectorObjective(object, cloud, y, options, &gradient);
  int iterations = 0;
  bool converged = false;
  while (iterations < options.gd_max_iterations) {
    const PointSet candidate = y - options.gd_step * gradient;
    PointSet next_gradient;
    const CorrectorObjectiveTerms next =
        EvaluateCorrectorObjective(object, cloud, candidate, options, &next_gradient);
    ++iterations;
    if (!next.registration_ok()) break;
    const double change = std::abs(terms.value - next.value);
    y = candidate;
    gradient = next_gradient;
    terms = next;
    if (change < options.gd_tolerance) {
      converged = true;
      break;
    }
  }
  result.keypoints = y;
  result.scene_from_model = terms.scene_from_model;
  result.posed_keypoints = terms.scene_from_model * object.keypoints();
  result.cost_after = terms.value;
  result.point_cloud_loss = terms.point_cloud_loss;
  result.keypoint_loss = terms.keypoint_loss;
  result.iterations = iterations;
  result.converged = converged;
  return result;
}

}  // namespace

CorrectorResult CorrectKeypoints(const ObjectModel& object, const PointSet& cloud,
                                 const PointSet& detected_keypoints,
                                 const CorrectorOptions& options) {
  options.Check();
  if (detected_keypoints.cols() != object.num_keypoints()) {
    throw std::invalid_argument("CorrectKeypoints: detected keypoint count differs from the object's");
  }
  CorrectorResult result;
  result.keypoints = detected_keypoints;
  result.posed_keypoints = detected_keypoints;
  const CorrectorObjectiveTerms start =
      EvaluateCorrectorObjective(object, cloud, detected_keypoints, options);
  result.registration = start.registration;
  result.cost_before = start.value;
  result.cost_after = start.value;
  if (!start.registration_ok() || cloud.cols() == 0 || !cloud.allFinite()) {
    if (result.registration == RegistrationStatus::kOk) result.registration = RegistrationStatus::kNonFinite;
    return result;
  }
  result.scene_from_model = start.scene_from_model;
  if (options.solver == CorrectorSolver::kGradientDescent) {
    return SolveGradientDescent(object, cloud, detected_keypoints, options, result);
  }
  return SolveFast(object, cloud, start.scene_from_model, options, result);
}

}  // namespace c3po
