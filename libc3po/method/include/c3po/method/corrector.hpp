#pragma once
// The keypoint corrector (paper Section VI-B, eq. 17; docs/method.md step 3):
//   f(y) = kappa * L_pc(T(y)) + theta * L_kp(y),   y = ỹ + Δy,
//   L_kp(y) = (1/N) sum_i ||y_i - T(y) b_i||^2   (the registration residual),
//   L_pc(T) = one-sided Chamfer from the input X to the posed sample T·B̂,
// with T(y) the closed-form registration of eq. (8).
//
// A fact the fast solver uses: for every pose T, y = T·b gives L_kp = 0 and
// T(y) = T, and f(y) >= kappa * L_pc(T(y)) always; hence
//   min_y f(y) = kappa * min_T L_pc(T), attained at y = T·b,
// and every local minimum of f has y = T(y)·b. The fast solver therefore
// minimises L_pc over the 6-DoF pose from T(ỹ) and returns y = T·b; the `gd`
// solver reproduces the reference's gradient descent in keypoint space.
#include <string>

#include "c3po/base/types.hpp"
#include "c3po/geometry/registration.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

enum class PointCloudLoss {
  kMeanSquared,  // the paper: (1/n) sum_x min_p ||x - T p||^2
  kMaxSquared,   // the reference code: max_x min_p ||x - T p||^2
};
enum class CorrectorSolver {
  kFast,             // pose-space ICP + damped point-to-plane steps (mean), IRLS (max); see above
  kGradientDescent,  // the reference: fixed step in keypoint space
};
// Robust kernel rho on the squared distance s = d^2 of each input point in the
// mean loss, L_pc = (1/n) sum_j rho(d_j^2) (issue 16; method.md "Robust
// corrector"), with scale c tied to eps_oc:
//   none: rho(s) = s
//   tls:  rho(s) = min(s, c^2)              (truncated least squares, TEASER++)
//   gm:   rho(s) = c^2 s / (c^2 + s)        (Geman-McClure)
// The fast solver minimises it by IRLS with weights w = rho'(s) and graduated
// non-convexity (the scale starts at 8c and halves to c in the basin stage).
enum class RobustLoss { kNone, kTruncated, kGemanMcClure };
const char* ToString(PointCloudLoss loss);
const char* ToString(CorrectorSolver solver);
const char* ToString(RobustLoss loss);
PointCloudLoss ParsePointCloudLoss(const std::string& text);    // "mean" | "max"
CorrectorSolver ParseCorrectorSolver(const std::string& text);  // "fast" | "gd"
RobustLoss ParseRobustLoss(const std::string& text);            // "none" | "tls" | "gm"
// Default kernel for depth-image / BOP input (certificate.hpp has the
// budget): measured on the real YCB-Video frames, TLS certifies 98 of 200
// instances against 89 without a kernel, 0 false certificates either way
// (docs/method.md "Options and defaults"). Ready-made clouds default to none.
constexpr RobustLoss kDepthImageRobustLoss = RobustLoss::kTruncated;
// rho(s) and rho'(s) of the kernel at scale c (s = squared distance).
double RobustRho(RobustLoss loss, double squared, double scale);
double RobustWeight(RobustLoss loss, double squared, double scale);

struct CorrectorOptions {
  double kappa = 10.0;
  double theta = 50.0;
  PointCloudLoss loss = PointCloudLoss::kMeanSquared;
  CorrectorSolver solver = CorrectorSolver::kFast;
  // gd: Δy <- Δy - step * ∇f, stop when |Δf| < tolerance.
  double gd_step = 0.1;
  int gd_max_iterations = 1000;
  double gd_tolerance = 1e-12;
  // fast (mean loss), coarse to fine: (1) at most fast_basin_iterations ICP
  // steps on fast_coarse_subsample points keep the start's basin, (2) damped
  // point-to-plane steps on fast_subsample points, each accepted only if L_pc
  // decreases, (3) the same on every point, (4) at most fast_polish_iterations
  // ICP steps on every point.
  // fast_max_iterations bounds the candidate poses evaluated in all stages;
  // the last stage stops when the relative decrease of L_pc < fast_tolerance.
  // 0 subsample = every point.
  int fast_max_iterations = 100;
  double fast_tolerance = 1e-5;
  int fast_subsample = 256;
  int fast_coarse_subsample = 128;
  int fast_basin_iterations = 15;
  int fast_polish_iterations = 2;
  // fast (mean loss): when the result leaves an input point at least
  // fast_restart_distance from the posed model (-1 = the object's eps_oc,
  // 0 = never), also try the result turned by ±fast_restart_angle (radians)
  // about three axes, and keep the lowest L_pc.
  double fast_restart_distance = -1.0;
  double fast_restart_angle = 0.8;
  // Robust kernel of the mean loss (needs loss = mean); robust_scale is c in
  // object units, -1 = the certified eps_oc (the object's unless overridden).
  RobustLoss robust_loss = RobustLoss::kNone;
  double robust_scale = -1.0;
  void Check() const;   // throws std::invalid_argument
};

struct CorrectorResult {
  PointSet keypoints;                 // corrected keypoints y*
  Pose scene_from_model;              // T(y*)
  PointSet posed_keypoints;           // T(y*)·b
  double cost_before = 0.0;           // f(ỹ)
  double cost_after = 0.0;            // f(y*)
  double point_cloud_loss = 0.0;      // L_pc(T(y*)) (robust kernel applied)
  RobustLoss robust_loss = RobustLoss::kNone;   // the kernel of L_pc
  double robust_scale = 0.0;          // c used (0 without a robust kernel)
  double keypoint_loss = 0.0;         // L_kp(y*)
  int iterations = 0;
  bool converged = false;
  RegistrationStatus registration = RegistrationStatus::kOk;  // of T(ỹ)
  bool ok() const { return registration == RegistrationStatus::kOk; }
};

// Corrects detected keypoints (3 x N, scene frame) against the input cloud.
// Degenerate input (empty cloud, collinear keypoints) is an outcome: ok() is
// false and the detected keypoints are returned unchanged.
CorrectorResult CorrectKeypoints(const ObjectModel& object, const PointSet& cloud,
                                 const PointSet& detected_keypoints,
                                 const CorrectorOptions& options = {});

// The objective and its analytic gradient with respect to y (3 x N), with the
// nearest neighbours of the current pose held fixed (they are piecewise
// constant in y). Envelope theorem: ∂L_kp/∂y_i = (2/N)(y_i - T b_i);
// ∂T/∂y by implicit differentiation of the optimality condition of eq. (8)
// (R^T M symmetric). Returns f; fills `gradient` when non-null.
struct CorrectorObjectiveTerms {
  double value = 0.0;
  double point_cloud_loss = 0.0;
  double keypoint_loss = 0.0;
  Pose scene_from_model;
  RegistrationStatus registration = RegistrationStatus::kOk;
  bool registration_ok() const { return registration == RegistrationStatus::kOk; }
};
CorrectorObjectiveTerms EvaluateCorrectorObjective(const ObjectModel& object, const PointSet& cloud,
                                                   const PointSet& keypoints,
                                                   const CorrectorOptions& options,
                                                   PointSet* gradient = nullptr);

// Gradient of a scalar L(R, t) with respect to the scene points y of
// T = RegisterPoints(b, y) (unit weights), given the Euclidean gradients dL/dR
// (3x3) and dL/dt (3). With S = R^T M symmetric at the optimum,
// dR = R [ω]x, ω = (tr(S) I - S)^{-1} vee(R^T dM - dM^T R), dt = dȳ - dR b̄:
//   ∂L/∂y_i = R (z × (b_i - b̄)) + (1/N) dL/dt,
//   z = (tr(S) I - S)^{-1} (vee(R^T dL/dR) - b̄ × R^T dL/dt).
PointSet RegistrationBackward(const PointSet& model_points, const PointSet& scene_points,
                              const Pose& scene_from_model, const Eigen::Matrix3d& dL_dR,
                              const Eigen::Vector3d& dL_dt);

}  // namespace c3po
