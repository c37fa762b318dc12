// The corrector objective f(y) = kappa L_pc(T(y)) + theta L_kp(y) and its
// analytic gradient (see corrector.hpp).
#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "c3po/method/corrector.hpp"

namespace c3po {
namespace {

// vee of the skew part: tr(X^T [w]x) = w · SkewVee(X).
Eigen::Vector3d SkewVee(const Eigen::Matrix3d& X) {
  return {X(2, 1) - X(1, 2), X(0, 2) - X(2, 0), X(1, 0) - X(0, 1)};
}

}  // namespace

PointSet RegistrationBackward(const PointSet& model_points, const PointSet& scene_points,
                              const Pose& scene_from_model, const Eigen::Matrix3d& dL_dR,
                              const Eigen::Vector3d& dL_dt) {
  const Eigen::Index n = model_points.cols();
  const Eigen::Matrix3d& R = scene_from_model.R;
  const Eigen::Vector3d model_mean = model_points.rowwise().mean();
  const Eigen::Vector3d scene_mean = scene_points.rowwise().mean();
  const PointSet model_centred = model_points.colwise() - model_mean;
  const Eigen::Matrix3d M = (scene_points.colwise() - scene_mean) * model_centred.transpose();
  Eigen::Matrix3d S = R.transpose() * M;
  S = 0.5 * (S + S.transpose());   // symmetric at the optimum; remove round-off
  const Eigen::Matrix3d H = S.trace() * Eigen::Matrix3d::Identity() - S;
  const Eigen::Vector3d Rt_gt = R.transpose() * dL_dt;
  const Eigen::Vector3d c = SkewVee(R.transpose() * dL_dR) - model_mean.cross(Rt_gt);
  const Eigen::Vector3d z = H.ldlt().solve(c);
  PointSet gradient(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    gradient.col(i) = R * z.cross(model_centred.col(i)) + dL_dt / static_cast<double>(n);
  }
  return gradient;
}

CorrectorObjectiveTerms EvaluateCorrectorObjective(const ObjectModel& object, const PointSet& cloud,
                                                   const PointSet& keypoints,
                                                   const CorrectorOptions& options,
                                                   PointSet* gradient) {
  CorrectorObjectiveTerms terms;
  const PointSet& model_keypoints = object.keypoints();
  const RegistrationResult registration = RegisterPoints(model_keypoints, keypoints);
  terms.registration = registration.status;
  if (!registration.ok() || cloud.cols() == 0) {
    terms.value = std::numeric_limits<double>::infinity();
    if (gradient) gradient->setZero(3, keypoints.cols());
    return terms;
  }
  const Pose& T = registration.scene_from_model;
  terms.scene_from_model = T;
  const double N = static_cast<double>(keypoints.cols());

  // L_kp(y) = (1/N) sum ||y_i - T b_i||^2; envelope theorem: ∂/∂y_i = (2/N) r_i.
  const PointSet keypoint_residual = keypoints - T * model_keypoints;
  terms.keypoint_loss = keypoint_residual.squaredNorm() / N;

  // L_pc with nearest neighbours p_j of T^{-1} x_j in B̂ (fixed), r_j = x_j - R p_j - t.
  Eigen::VectorXi nearest;
  Eigen::VectorXd squared;
  object.NearestInPosedModel(cloud, T, &nearest, &squared);
  const double n = static_cast<double>(cloud.cols());
  Eigen::Matrix3d dL_dR = Eigen::Matrix3d::Zero();
  Eigen::Vector3d dL_dt = Eigen::Vector3d::Zero();
  auto accumulate = [&](Eigen::Index j, double scale) {
    const Eigen::Vector3d p = object.sample().col(nearest(j));
    const Eigen::Vector3d r = cloud.col(j) - T.R * p - T.t;
    dL_dR -= scale * 2.0 * r * p.transpose();
    dL_dt -= scale * 2.0 * r;
  };
  if (options.loss == PointCloudLoss::kMeanSquared && options.robust_loss != RobustLoss::kNone) {
    // L_pc = (1/n) sum rho(d_j^2): chain rule, dL/dd_j^2 = rho'(d_j^2) / n.
    const double scale = options.robust_scale > 0 ? options.robust_scale : object.spec().eps_oc;
    double sum = 0.0;
    for (Eigen::Index j = 0; j < cloud.cols(); ++j) {
      sum += RobustRho(options.robust_loss, squared(j), scale);
      if (gradient) accumulate(j, RobustWeight(options.robust_loss, squared(j), scale) / n);
    }
    terms.point_cloud_loss = sum / n;
  } else if (options.loss == PointCloudLoss::kMeanSquared) {
    terms.point_cloud_loss = squared.mean();
    if (gradient) {
      for (Eigen::Index j = 0; j < cloud.cols(); ++j) accumulate(j, 1.0 / n);
    }
  } else {
    Eigen::Index worst = 0;
    terms.point_cloud_loss = squared.maxCoeff(&worst);
    if (gradient) accumulate(worst, 1.0);
  }
  terms.value = options.kappa * terms.point_cloud_loss + options.theta * terms.keypoint_loss;
  if (gradient) {
    *gradient = options.kappa * RegistrationBackward(model_keypoints, keypoints, T, dL_dR, dL_dt) +
                options.theta * (2.0 / N) * keypoint_residual;
  }
  return terms;
}

}  // namespace c3po
