#include "c3po/geometry/rotation.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cstdio>

namespace c3po {

std::optional<Eigen::Matrix3d> NearestRotation(const Eigen::Matrix3d& R, std::string* problem, double tolerance) {
  constexpr double kProjectAbove = 1e-12;   // below this R is kept bit-exact
  if (!R.allFinite()) {
    *problem = "non-finite entries";
    return std::nullopt;
  }
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(error <= tolerance)) {
    char text[128];
    std::snprintf(text, sizeof text, "not orthonormal (max |R^T R - I| = %.3g, tolerance %g)", error,
                  tolerance);
    *problem = text;
    return std::nullopt;
  }
  if (R.determinant() < 0) {
    *problem = "determinant is -1 (a reflection, not a rotation)";
    return std::nullopt;
  }
  if (error <= kProjectAbove) return R;
  // Nearest rotation in the Frobenius norm; det stays +1 since R is within
  // the tolerance (<= 0.1) of a rotation.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return Eigen::Matrix3d(svd.matrixU() * svd.matrixV().transpose());
}

}  // namespace c3po
