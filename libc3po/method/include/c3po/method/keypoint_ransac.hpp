#pragma once
// The "KeyPo + RANSAC + ICP" baseline of the C-3PO evaluation (paper Section
// VIII, Tables II-IV): RANSAC (Fischler & Bolles 1981) over minimal sets of 3
// detected-vs-model keypoint correspondences (y_i, b_i), a hypothesis T from
// the closed form of eq. (8) on the 3 pairs, its inliers |y_i - T b_i| <=
// inlier_threshold, the best hypothesis (most inliers, then the smallest sum
// of inlier residuals) re-registered on its inliers (eq. 8). ICP follows in
// the evaluation (RefineIcp).
#include <cstdint>
#include <string>
#include <vector>

#include "c3po/base/types.hpp"

namespace c3po {

struct KeypointRansacOptions {
  double inlier_threshold = 0.0;  // object units, > 0
  // Every triple is tried when there are at most this many; otherwise this
  // many random triples (seeded).
  int max_iterations = 1000;
  std::uint64_t seed = 0;
  void Check() const;             // throws std::invalid_argument
};

struct KeypointRansacResult {
  Pose scene_from_model;
  std::vector<int> inliers;       // keypoint indices, sorted
  int hypotheses = 0;             // non-degenerate triples scored
  std::string failure;            // empty on success
  bool ok() const { return failure.empty(); }
};

// model_keypoints b (3 x N), detected y (3 x N), N >= 3. Non-finite detected
// keypoints are never inliers. Never throws on degenerate data (failure);
// throws std::invalid_argument on bad options or sizes.
KeypointRansacResult RegisterKeypointsRansac(const PointSet& model_keypoints,
                                             const PointSet& detected_keypoints,
                                             const KeypointRansacOptions& options);

}  // namespace c3po
