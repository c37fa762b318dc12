// Corrector solvers (see corrector.hpp for the objective and the reduction
// that the fast solver relies on).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "c3po/base/error.hpp"
#include "c3po/method/corrector.hpp"

namespace c3po {

const char* ToString(PointCloudLoss loss) {
  return loss == PointCloudLoss::kMeanSquared ? "mean" : "max";
}
const char* ToString(CorrectorSolver solver) {
  return solver == CorrectorSolver::kFast ? "fast" : "gd";
}
const char* ToString(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::kTruncated: return "tls";
    case RobustLoss::kGemanMcClure: return "gm";
    default: return "none";
  }
}
RobustLoss ParseRobustLoss(const std::string& text) {
  if (text == "none") return RobustLoss::kNone;
  if (text == "tls") return RobustLoss::kTruncated;
  if (text == "gm") return RobustLoss::kGemanMcClure;
  throw InputError("--robust-loss", "'" + text + "' must be none, tls or gm");
}
double RobustRho(RobustLoss loss, double squared, double scale) {
  const double c2 = scale * scale;
  switch (loss) {
    case RobustLoss::kTruncated: return std::min(squared, c2);
    case RobustLoss::kGemanMcClure: return c2 * squared / (c2 + squared);
    default: return squared;
  }
}
double RobustWeight(RobustLoss loss, double squared, double scale) {
  const double c2 = scale * scale;
  switch (loss) {
    case RobustLoss::kTruncated: return squared < c2 ? 1.0 : 0.0;
    case RobustLoss::kGemanMcClure: return (c2 * c2) / ((c2 + squared) * (c2 + squared));
    default: return 1.0;
  }
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
  require(fast_coarse_subsample >= 0, "fast_coarse_subsample must be >= 0");
  require(fast_basin_iterations >= 0, "fast_basin_iterations must be >= 0");
  require(fast_polish_iterations >= 0, "fast_polish_iterations must be >= 0");
  require(std::isfinite(fast_restart_distance), "fast_restart_distance must be finite");
  require(fast_restart_angle >= 0 && fast_restart_angle <= M_PI, "fast_restart_angle must be in [0, pi]");
  require(std::isfinite(robust_scale) && (robust_scale > 0 || robust_scale == -1.0),
          "robust_scale must be > 0 or -1 (= eps_oc)");
  require(robust_loss == RobustLoss::kNone || loss == PointCloudLoss::kMeanSquared,
          "a robust kernel needs the mean loss");
}

namespace {

// The robust kernel of the mean loss at one scale (kNone: plain squares).
struct Kernel {
  RobustLoss type = RobustLoss::kNone;
  double scale = 0.0;
  bool active() const { return type != RobustLoss::kNone; }
  Kernel Scaled(double factor) const { return {type, scale * factor}; }
};

// L_pc of `points` at `pose`, with the nearest B̂ point of every input point.
// `hints`: the nearest points of `points` at a nearby pose (the previous
// iterate's), which make the search faster and change nothing.
struct PoseFit {
  Pose pose;
  Eigen::VectorXi nearest;
  Eigen::VectorXd squared;
  double loss = std::numeric_limits<double>::infinity();
};

PoseFit FitAtPose(const ObjectModel& object, const PointSet& points, const Pose& pose,
                  PointCloudLoss loss, const Kernel& kernel = {}, const Eigen::VectorXi* hints = nullptr) {
  PoseFit fit;
  fit.pose = pose;
  object.NearestInPosedModel(points, pose, &fit.nearest, &fit.squared, hints);
  if (points.cols() > 0) {
    if (loss == PointCloudLoss::kMeanSquared && kernel.active()) {
      double sum = 0.0;
      for (Eigen::Index j = 0; j < fit.squared.size(); ++j) sum += RobustRho(kernel.type, fit.squared(j), kernel.scale);
      fit.loss = sum / static_cast<double>(points.cols());
    } else {
      fit.loss = loss == PointCloudLoss::kMeanSquared ? fit.squared.mean() : fit.squared.maxCoeff();
    }
  }
  return fit;
}

// IRLS weights rho'(d_j^2) of the kernel (empty = unit weights).
Eigen::VectorXd KernelWeights(const Kernel& kernel, const Eigen::VectorXd& squared) {
  Eigen::VectorXd weights;
  if (!kernel.active()) return weights;
  weights.resize(squared.size());
  for (Eigen::Index j = 0; j < squared.size(); ++j) weights(j) = RobustWeight(kernel.type, squared(j), kernel.scale);
  return weights;
}

struct StageResult {
  PoseFit best;          // lowest loss seen in the stage
  int iterations = 0;    // candidate poses evaluated
  bool converged = false;
};

bool SmallDecrease(double previous, double current, double tolerance) {
  return std::abs(previous - current) <= tolerance * std::max(previous, 1e-300);
}

// Majorise-minimise (ICP) steps on a fixed point set: re-associate, then the
// weighted closed-form registration of eq. (8). With unit weights no step can
// increase the mean loss, and each step only moves as far as the current
// matches pull, so the iterates stay in the basin of the start (this is what
// the reference's small gradient steps achieve, in far fewer iterations).
// With IRLS weights w_j = d_j^(p-2) it minimises sum d_j^p, which tends to
// the max loss.
// With a robust kernel the weights are w_j = rho'(d_j^2) (IRLS; for TLS an
// MM step on the points within the truncation).
StageResult RunPointToPointStage(const ObjectModel& object, const PointSet& points, PoseFit fit,
                                 PointCloudLoss loss, double irls_power, int max_iterations,
                                 double tolerance, const Kernel& kernel = {}) {
  StageResult stage{fit};
  PointSet matched(3, points.cols());
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    Eigen::VectorXd weights;
    if (irls_power > 2.0) {
      const double scale = std::max(fit.squared.maxCoeff(), 1e-300);
      weights = (fit.squared / scale).array().pow(0.5 * (irls_power - 2.0)).matrix();
      weights = weights.cwiseMax(1e-12);
    } else if (kernel.active()) {
      weights = KernelWeights(kernel, fit.squared);
    }
    for (Eigen::Index j = 0; j < points.cols(); ++j) matched.col(j) = object.sample().col(fit.nearest(j));
    const RegistrationResult step = RegisterPoints(matched, points, weights);
    if (!step.ok()) break;
    const double previous = fit.loss;
    fit = FitAtPose(object, points, step.scene_from_model, loss, kernel, &fit.nearest);
    ++stage.iterations;
    if (fit.loss < stage.best.loss) stage.best = fit;
    if (SmallDecrease(previous, fit.loss, tolerance)) {
      stage.converged = true;
      break;
    }
  }
  return stage;
}

// R <- Exp(ω) R, t <- Exp(ω) t + v for delta = (ω, v).
Pose ApplyIncrement(const Pose& pose, const Eigen::Matrix<double, 6, 1>& delta) {
  const double angle = delta.head<3>().norm();
  const Eigen::Matrix3d step_rotation =
      angle > 0 ? Eigen::AngleAxisd(angle, delta.head<3>() / angle).toRotationMatrix()
                : Eigen::Matrix3d::Identity();
  Pose out;
  out.R = step_rotation * pose.R;
  out.t = step_rotation * pose.t + delta.tail<3>();
  return out;
}

// Levenberg-Marquardt on the point-to-plane residuals r_j = m_j·(x_j - s_j),
// with s_j = R p_j + t the nearest posed sample point and m_j = R n_j its
// normal; for the increment of ApplyIncrement the Jacobian of r_j is
// [ (m_j × x_j)^T, -m_j^T ] (the normal moves with the model). A step is
// accepted only if the true mean loss L_pc (re-associated) decreases;
// otherwise the damping grows tenfold, at most `max_tries` times. Undamped
// Gauss-Newton converges in a few steps near the optimum but from afar can
// jump out of the start's basin; the acceptance test forbids that.
StageResult RunPointToPlaneStage(const ObjectModel& object, const PointSet& points, PoseFit fit,
                                 int max_iterations, double tolerance, int max_tries,
                                 const Kernel& kernel = {}) {
  StageResult stage;
  double damping = 1e-4;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    Eigen::Matrix<double, 6, 6> JtJ = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> Jtr = Eigen::Matrix<double, 6, 1>::Zero();
    const Eigen::VectorXd weights = KernelWeights(kernel, fit.squared);   // IRLS (empty: unit)
    for (Eigen::Index j = 0; j < points.cols(); ++j) {
      const double w = weights.size() ? weights(j) : 1.0;
      if (w == 0.0) continue;
      const Eigen::Vector3d x = points.col(j);
      const Eigen::Vector3d m = fit.pose.R * object.sample_normals().col(fit.nearest(j));
      const Eigen::Vector3d s = fit.pose.R * object.sample().col(fit.nearest(j)) + fit.pose.t;
      Eigen::Matrix<double, 6, 1> J;
      J << m.cross(x), -m;
      JtJ.noalias() += w * J * J.transpose();
      Jtr.noalias() += w * J * m.dot(x - s);
    }
    const double floor = 1e-12 * (JtJ.trace() + 1e-300);
    bool accepted = false;
    const double previous = fit.loss;
    for (int attempt = 0; attempt < max_tries && !accepted; ++attempt) {
      Eigen::Matrix<double, 6, 6> damped = JtJ;
      damped.diagonal() += damping * JtJ.diagonal().cwiseMax(floor);
      const Eigen::Matrix<double, 6, 1> delta = damped.ldlt().solve(-Jtr);
      if (!delta.allFinite()) break;
      PoseFit candidate = FitAtPose(object, points, ApplyIncrement(fit.pose, delta),
                                    PointCloudLoss::kMeanSquared, kernel, &fit.nearest);
      ++stage.iterations;
      if (candidate.loss < fit.loss) {
        fit = std::move(candidate);
        damping = std::max(damping / 3.0, 1e-7);
        accepted = true;
      } else {
        damping *= 10.0;
      }
    }
    // No descent step at this resolution: a (numerical) local minimum.
    if (!accepted || SmallDecrease(previous, fit.loss, tolerance)) {
      stage.converged = true;
      break;
    }
  }
  stage.best = std::move(fit);
  return stage;
}

// Fills the result for y* = T·b: then L_kp = 0, T(y*) = T and f = kappa L_pc(T)
// (corrector.hpp); `fit` is L_pc of the whole cloud at T.
CorrectorResult FinishAtPose(const ObjectModel& object, const PoseFit& fit,
                             const CorrectorOptions& options, CorrectorResult result) {
  const PointSet posed = fit.pose * object.keypoints();
  const RegistrationResult registration = RegisterPoints(object.keypoints(), posed);
  result.keypoints = posed;
  result.scene_from_model = registration.ok() ? registration.scene_from_model : fit.pose;
  result.posed_keypoints = result.scene_from_model * object.keypoints();
  result.point_cloud_loss = fit.loss;
  result.keypoint_loss = (posed - result.posed_keypoints).squaredNorm() / posed.cols();
  result.cost_after = options.kappa * result.point_cloud_loss + options.theta * result.keypoint_loss;
  return result;
}

// Mean loss, coarse to fine, from `start`: (1) ICP steps on a small subset
// find the basin of the start, (2) damped point-to-plane steps on a larger
// subset converge in it, (3) the same on every point, accepted only if L_pc
// decreases, (4) a couple of ICP steps on every point, the objective itself.
struct Refined {
  PoseFit fit;  // on every point
  int iterations = 0;
  bool converged = false;
};

// With a robust kernel the basin stage is graduated (GNC): the kernel's scale
// starts at 8c (nearly quadratic over the basin, so a far start still sees
// every point) and halves to c; later stages use scale c.
Refined RefineMean(const ObjectModel& object, const PointSet& cloud, const PointSet& coarse,
                   const PointSet& subset, const Pose& start, const CorrectorOptions& options,
                   const Kernel& kernel = {}) {
  const PointCloudLoss mean = PointCloudLoss::kMeanSquared;
  int budget = options.fast_max_iterations;
  auto spend = [&budget](const StageResult& stage) { budget = std::max(0, budget - stage.iterations); };
  StageResult basin;
  if (!kernel.active()) {
    basin = RunPointToPointStage(object, coarse, FitAtPose(object, coarse, start, mean),
                                 mean, 2.0, std::min(budget, options.fast_basin_iterations), 1e-3);
    spend(basin);
  } else {
    Pose pose = start;
    int iterations = 0;
    for (double factor : {8.0, 4.0, 2.0, 1.0}) {
      const Kernel graduated = kernel.Scaled(factor);
      const int stage_budget = std::min(budget, std::max(2, options.fast_basin_iterations / 2));
      const StageResult step = RunPointToPointStage(object, coarse, FitAtPose(object, coarse, pose, mean, graduated),
                                                    mean, 2.0, stage_budget, 1e-3, graduated);
      spend(step);
      iterations += step.iterations;
      pose = step.best.pose;
    }
    basin.best = FitAtPose(object, coarse, pose, mean, kernel);
    basin.iterations = iterations;
  }
  const StageResult local = RunPointToPlaneStage(object, subset, FitAtPose(object, subset, basin.best.pose, mean, kernel),
                                                 std::min(budget, 25), 1e-3, 4, kernel);
  spend(local);
  const StageResult fine = RunPointToPlaneStage(object, cloud, FitAtPose(object, cloud, local.best.pose, mean, kernel),
                                                std::min(budget, 5), 1e-4, 1, kernel);
  spend(fine);
  const StageResult polish = RunPointToPointStage(object, cloud, fine.best, mean, 2.0,
                                                  std::min(budget, options.fast_polish_iterations),
                                                  options.fast_tolerance, kernel);
  return {polish.best, basin.iterations + local.iterations + fine.iterations + polish.iterations,
          fine.converged};
}

// Further starts when the fit leaves an input point farther than the restart
// distance from the posed model (a wrong basin, typically a turned pose): the
// found pose turned by ±fast_restart_angle about the three axes through the
// cloud's centroid. Each is screened by the basin stage on the coarse subset;
// the best one, if it fits the coarse subset better, is refined, and kept if
// its L_pc is lower. The same objective, minimised better.
Refined TryRestarts(const ObjectModel& object, const PointSet& cloud, const PointSet& coarse,
                    const PointSet& subset, Refined found, const CorrectorOptions& options,
                    const Kernel& kernel = {}) {
  const PointCloudLoss mean = PointCloudLoss::kMeanSquared;
  const Eigen::Vector3d centre = cloud.rowwise().mean();
  PoseFit best_screen = FitAtPose(object, coarse, found.fit.pose, mean, kernel);
  const double found_screen = best_screen.loss;
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {-1.0, 1.0}) {
      const Eigen::Matrix3d turn(Eigen::AngleAxisd(sign * options.fast_restart_angle, Eigen::Vector3d::Unit(axis)));
      Pose hypothesis;
      hypothesis.R = turn * found.fit.pose.R;
      hypothesis.t = turn * (found.fit.pose.t - centre) + centre;
      const StageResult screen =
          RunPointToPointStage(object, coarse, FitAtPose(object, coarse, hypothesis, mean, kernel), mean, 2.0,
                               options.fast_basin_iterations, 1e-3, kernel);
      found.iterations += screen.iterations + 1;
      if (screen.best.loss < best_screen.loss) best_screen = screen.best;
    }
  }
  if (!(best_screen.loss < found_screen)) return found;
  const Refined other = RefineMean(object, cloud, coarse, subset, best_screen.pose, options, kernel);
  found.iterations += other.iterations;
  if (other.fit.loss < found.fit.loss) {
    found.fit = other.fit;
    found.converged = other.converged;
  }
  return found;
}

CorrectorResult SolveFastMean(const ObjectModel& object, const PointSet& cloud, const Pose& start,
                              double start_loss, const CorrectorOptions& options, CorrectorResult result) {
  const PointSet coarse = StridedColumns(cloud, options.fast_coarse_subsample);
  const PointSet subset = StridedColumns(cloud, options.fast_subsample);
  const Kernel kernel{options.robust_loss, options.robust_scale};
  Refined refined = RefineMean(object, cloud, coarse, subset, start, options, kernel);
  const double restart_distance =
      options.fast_restart_distance < 0 ? object.spec().eps_oc : options.fast_restart_distance;
  // Without a kernel one far point triggers restarts; with one, stray points
  // are expected, so more than 1 % of the points (at least one) must be far.
  const double restart_squared = restart_distance * restart_distance;
  const Eigen::Index far = (refined.fit.squared.array() >= restart_squared).count();
  const Eigen::Index allowed = kernel.active() ? cloud.cols() / 100 : 0;
  if (restart_distance > 0 && options.fast_restart_angle > 0 && far > allowed) {
    refined = TryRestarts(object, cloud, coarse, subset, refined, options, kernel);
  }
  result.iterations = refined.iterations;
  result.converged = refined.converged;
  if (refined.fit.loss > start_loss) {
    // The subsets misled the stages: keep T(ỹ), whose y = T·b costs
    // kappa L_pc(T(ỹ)) <= f(ỹ).
    PoseFit start_fit;
    start_fit.pose = start;
    start_fit.loss = start_loss;
    return FinishAtPose(object, start_fit, options, result);
  }
  return FinishAtPose(object, refined.fit, options, result);
}

// Max loss: ICP on a subset (mean loss) finds the basin, then an IRLS
// continuation towards the max, p = 4, 8, 16, 32; keep the pose with the
// lowest true max loss (the start included).
CorrectorResult SolveFastMax(const ObjectModel& object, const PointSet& cloud, const Pose& start,
                             double start_loss, const CorrectorOptions& options, CorrectorResult result) {
  const PointSet subset = StridedColumns(cloud, options.fast_subsample);
  const int budget = options.fast_max_iterations;
  const StageResult mean_stage =
      RunPointToPointStage(object, subset, FitAtPose(object, subset, start, PointCloudLoss::kMeanSquared),
                           PointCloudLoss::kMeanSquared, 2.0, budget / 4, 1e-4);
  int iterations = mean_stage.iterations;
  PoseFit best;  // only pose and loss are used
  best.pose = start;
  best.loss = start_loss;
  PoseFit current = FitAtPose(object, cloud, mean_stage.best.pose, options.loss);
  if (current.loss < best.loss) best = current;
  for (double power : {4.0, 8.0, 16.0, 32.0}) {
    const int stage_budget = std::max(1, (budget - iterations) / 4);
    const StageResult stage = RunPointToPointStage(object, cloud, current, options.loss, power,
                                                   stage_budget, options.fast_tolerance);
    iterations += stage.iterations;
    result.converged = stage.converged;
    current = stage.best;
    if (current.loss < best.loss) best = current;
  }
  result.iterations = iterations;
  return FinishAtPose(object, best, options, result);
}

CorrectorResult SolveFast(const ObjectModel& object, const PointSet& cloud, const Pose& start,
                          double start_loss, const CorrectorOptions& options, CorrectorResult result) {
  if (options.loss == PointCloudLoss::kMeanSquared) {
    return SolveFastMean(object, cloud, start, start_loss, options, result);
  }
  return SolveFastMax(object, cloud, start, start_loss, options, result);
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
  if (options.robust_loss != RobustLoss::kNone && options.robust_scale < 0) {
    // Truncation tied to eps_oc: the object's, unless the caller set it.
    CorrectorOptions resolved = options;
    resolved.robust_scale = object.spec().eps_oc;
    if (!(resolved.robust_scale > 0)) throw std::invalid_argument("CorrectKeypoints: robust kernel needs eps_oc > 0");
    return CorrectKeypoints(object, cloud, detected_keypoints, resolved);
  }
  result.robust_loss = options.robust_loss;
  if (options.robust_loss != RobustLoss::kNone) result.robust_scale = options.robust_scale;
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
  return SolveFast(object, cloud, start.scene_from_model, start.point_cloud_loss, options, result);
}

}  // namespace c3po
