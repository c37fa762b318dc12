#pragma once
// Closed-form rigid registration (paper eq. 8; Arun et al. / Kabsch / Umeyama
// without scale): T = argmin_T sum_i w_i ||y_i - T b_i||^2.
#include <string>

#include "c3po/base/types.hpp"

namespace c3po {

enum class RegistrationStatus {
  kOk,
  kTooFewPoints,   // fewer than 3 points with positive weight, or < 3 distinct
  kCollinear,      // rotation about the line is unobservable
  kZeroWeights,    // all weights are zero
  kNonFinite,      // NaN / Inf in the input
};
const char* ToString(RegistrationStatus status);

struct RegistrationResult {
  Pose scene_from_model;             // identity unless ok()
  RegistrationStatus status = RegistrationStatus::kTooFewPoints;
  double rms_residual = 0.0;         // sqrt(sum w ||y - T b||^2 / sum w)
  Eigen::Vector3d singular_values = Eigen::Vector3d::Zero();  // of M = Y_c W B_c^T
  bool ok() const { return status == RegistrationStatus::kOk; }
};

// model (3xN) are b_i, scene (3xN) are y_i; weights empty or size N, >= 0.
// Throws std::invalid_argument if sizes disagree or a weight is negative.
RegistrationResult RegisterPoints(const PointSet& model, const PointSet& scene,
                                  const Eigen::VectorXd& weights = Eigen::VectorXd());

}  // namespace c3po
