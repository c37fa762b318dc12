#pragma once
// Rotations from other tools (datasets store them as float32 or as few-digit
// text): accepted when orthonormal to within a tolerance on max |R^T R - I|
// and projected onto SO(3); anything farther is not a rotation.
//  - kRotationTolerance (1e-4, float32 level): rotations c3po acts on (manifest
//    ground truth used for training, poses to certify);
//  - kDatasetRotationTolerance (1e-3): BOP ground truth, used for reporting
//    only. Datasets ship rotations stored as rounded text from older
//    annotation tools: Linemod-Occluded's scene_gt.json reaches 2.9e-4. At
//    1e-3 the projection moves a point at distance r from the origin by at
//    most ~1e-3 r (0.1 mm at 10 cm), far below any pose accuracy scored.
#include <optional>
#include <string>

#include <Eigen/Core>

namespace c3po {

inline constexpr double kRotationTolerance = 1e-4;
inline constexpr double kDatasetRotationTolerance = 1e-3;

// The nearest rotation to R (U V^T of its SVD; R itself, bit-exact, when it is
// orthonormal to 1e-12), or nullopt with *problem set: "not orthonormal (max
// |R^T R - I| = 0.0123, tolerance 0.0001)", "determinant is -1 (a reflection,
// not a rotation)", "non-finite entries". tolerance <= 0.1.
std::optional<Eigen::Matrix3d> NearestRotation(const Eigen::Matrix3d& R, std::string* problem,
                                               double tolerance = kRotationTolerance);

}  // namespace c3po
