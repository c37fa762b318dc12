#include "c3po/geometry/registration.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace c3po {

const char* ToString(RegistrationStatus status) {
  switch (status) {
    case RegistrationStatus::kOk: return "ok";
    case RegistrationStatus::kTooFewPoints: return "fewer than 3 distinct points";
    case RegistrationStatus::kCollinear: return "collinear points";
    case RegistrationStatus::kZeroWeights: return "all weights are zero";
    case RegistrationStatus::kNonFinite: return "non-finite input";
  }
  return "unknown";
}

namespace {

// Relative tolerances for "distinct" points and for rank deficiency.
constexpr double kDistinctTolerance = 1e-12;
constexpr double kCollinearTolerance = 1e-9;

int CountPositive(const Eigen::VectorXd& w) { return static_cast<int>((w.array() > 0).count()); }

}  // namespace

// Eq. (8): centre both sets with weights, M = Y_c W B_c^T = U S V^T,
// R = U diag(1, 1, det(U) det(V)) V^T (reflection correction), t = ȳ - R b̄.
RegistrationResult RegisterPoints(const PointSet& model, const PointSet& scene,
                                  const Eigen::VectorXd& weights) {
  if (model.cols() != scene.cols()) {
    throw std::invalid_argument("RegisterPoints: model and scene sizes differ");
  }
  const Eigen::Index n = model.cols();
  Eigen::VectorXd w = weights.size() == 0 ? Eigen::VectorXd::Ones(n) : weights;
  if (w.size() != n) throw std::invalid_argument("RegisterPoints: weight count differs");
  if ((w.array() < 0).any()) throw std::invalid_argument("RegisterPoints: negative weight");

  RegistrationResult result;
  if (!model.allFinite() || !scene.allFinite() || !w.allFinite()) {
    result.status = RegistrationStatus::kNonFinite;
    return result;
  }
  if (n > 0 && w.sum() <= 0) {
    result.status = RegistrationStatus::kZeroWeights;
    return result;
  }
  if (CountPositive(w) < 3) {
    result.status = RegistrationStatus::kTooFewPoints;
    return result;
  }
  const double total = w.sum();
  const Eigen::Vector3d model_mean = model * w / total;
  const Eigen::Vector3d scene_mean = scene * w / total;
  const PointSet model_centred = model.colwise() - model_mean;
  const PointSet scene_centred = scene.colwise() - scene_mean;

  const double spread = std::max(model_centred.cwiseAbs().maxCoeff(),
                                 scene_centred.cwiseAbs().maxCoeff());
  // Max-norms, not Euclidean norms: squaring huge coordinates must not overflow.
  const double magnitude = model_mean.cwiseAbs().maxCoeff() + scene_mean.cwiseAbs().maxCoeff();
  if (spread <= kDistinctTolerance * (1.0 + magnitude)) {
    result.status = RegistrationStatus::kTooFewPoints;
    return result;
  }

  const Eigen::Matrix3d M = scene_centred * w.asDiagonal() * model_centred.transpose();
  if (!M.allFinite()) {  // coordinates too large to square
    result.status = RegistrationStatus::kNonFinite;
    return result;
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  result.singular_values = svd.singularValues();
  if (result.singular_values(1) <= kCollinearTolerance * result.singular_values(0)) {
    result.status = RegistrationStatus::kCollinear;
    return result;
  }
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU().determinant() * svd.matrixV().determinant()) < 0 ? -1.0 : 1.0;
  result.scene_from_model.R = svd.matrixU() * D * svd.matrixV().transpose();
  result.scene_from_model.t = scene_mean - result.scene_from_model.R * model_mean;
  result.status = RegistrationStatus::kOk;

  const PointSet residual = scene - result.scene_from_model * model;
  result.rms_residual = std::sqrt((residual.colwise().squaredNorm().transpose().array() *
                                   w.array()).sum() / total);
  return result;
}

}  // namespace c3po
