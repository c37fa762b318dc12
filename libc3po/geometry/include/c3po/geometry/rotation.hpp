#pragma once
// Ground-truth rotations from other tools (datasets store them as float32 or
// as few-digit quaternions): accepted when orthonormal to within
// kRotationTolerance (max |R^T R - I|, a float32-level tolerance) and
// projected onto SO(3); anything farther is not a rotation.
#include <optional>
#include <string>

#include <Eigen/Core>

namespace c3po {

inline constexpr double kRotationTolerance = 1e-4;

// The nearest rotation to R (U V^T of its SVD; R itself, bit-exact, when it is
// orthonormal to 1e-12), or nullopt with *problem set: "not orthonormal (max
// |R^T R - I| = 0.0123)", "determinant is -1 (a reflection, not a rotation)",
// "non-finite entries".
std::optional<Eigen::Matrix3d> NearestRotation(const Eigen::Matrix3d& R, std::string* problem);

}  // namespace c3po
