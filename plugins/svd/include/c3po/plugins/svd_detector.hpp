#pragma once
// The "svd" detector: training-free keypoints by principal-axes alignment.
//
// Rotation hypotheses: the object's model sample B̂ and the input cloud X are
// each reduced to their centroid and principal axes (eigenvectors of the
// centred covariance); every proper rotation mapping the model axes onto the
// cloud axes up to sign (4 sign patterns) and, optionally, order (x 6
// permutations, since a partial cloud's axes need not come in the model's
// order) is a hypothesis, and a fixed set of rotations uniform on SO(3) adds
// more for partial clouds.
// Translation hypotheses: per rotation, the centroids coincide, or (partial
// clouds, whose centroid is not the model's) along each model axis the
// cloud's extent is aligned with the low or the high end of the model's box.
// Three stages, each scored by the one-sided Chamfer distance from X to the
// posed model (mean of squared nearest-neighbour distances, paper eq. 9),
// with nearest neighbours from the model-frame k-d trees:
//   1. screen every (rotation, translation) on a few points with a sampled
//      distance field of B̂ (no refinement);
//   2. brief ICP of the best screened ones on a small subsample;
//   3. longer ICP of the best few on B̂ and a larger subsample.
// The posed keypoints T·b of the best final pose are the detection.
#include <cstdint>
#include <memory>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/method/detector.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

class DistanceGrid;

struct SvdDetectorOptions {
  // Clouds with more finite points are first reduced to this many by an even
  // stride over the finite points (0 = never): the detector's cost is then
  // bounded for huge clouds (10^7 points); smaller clouds are used whole.
  int max_input_points = 5000;
  bool try_permutations = true;   // 24 axis rotations; false: the 4 sign flips only
  int uniform_rotations = 120;    // extra rotations, uniform on SO(3) (fixed by seed)
  bool box_translations = true;   // 27 translations per rotation; false: centroids only
  int coarse_model_points = 1000; // model sample of stage 2
  int grid_cells = 40;            // distance field of B̂ used in stage 1 (cells on the longest side)
  int screening_points = 64;      // cloud subsample of stage 1
  int screened_hypotheses = 24;   // kept for stage 2
  int max_hypothesis_points = 100;   // cloud subsample of stage 2
  int hypothesis_icp_iterations = 8;
  int refined_hypotheses = 3;     // kept for stage 3
  int max_final_points = 500;     // cloud subsample of stage 3
  int final_icp_iterations = 30;
  double trim_fraction = 0.0;     // trimmed ICP (see IcpOptions)
  std::uint64_t seed = 0;         // of the subsamples and the uniform rotations
  // Throws std::invalid_argument on a value out of range.
  void Check() const;
};

// One scored pose hypothesis (evidence of a detection).
struct SvdHypothesis {
  Pose scene_from_model;
  double chamfer = 0.0;   // stage-2 score: mean squared NN distance to the coarse model
  int icp_iterations = 0;
};

struct SvdEstimate {
  Pose scene_from_model;
  double chamfer = 0.0;      // eq. (9), every used finite cloud point -> posed B̂, final pose
  int screened = 0;          // (rotation, translation) pairs screened in stage 1
  int best_hypothesis = -1;  // index into hypotheses of the winner
  std::vector<SvdHypothesis> hypotheses;   // stage-2 results
};

class SvdDetector : public Detector {
 public:
  // Keeps its own copy of the object (the copy shares the k-d tree).
  explicit SvdDetector(const ObjectModel& object, const SvdDetectorOptions& options = {});

  std::string name() const override { return "svd"; }
  int num_keypoints() const override { return object_.num_keypoints(); }
  // Posed keypoints (3 x N). Non-finite points are ignored; more than
  // max_input_points finite ones are strided down to that many. With 1 or 2 finite
  // points (no axes) the model is only translated onto the cloud centroid.
  // Throws InputError("cloud: ...") when the cloud has no finite point.
  // Safe to call concurrently; the same cloud always gives the same output.
  PointSet Detect(const PointSet& cloud) const override;
  // The pose behind Detect, with the evidence of every stage.
  SvdEstimate Estimate(const PointSet& cloud) const;

  const SvdDetectorOptions& options() const { return options_; }

 private:
  struct Candidate;
  std::vector<Candidate> Screen(const PointSet& points, const Eigen::Vector3d& centroid) const;

  ObjectModel object_;
  ObjectModel coarse_;   // same mesh, coarse_model_points samples
  std::shared_ptr<const DistanceGrid> grid_;   // distance field of B̂
  SvdDetectorOptions options_;
  Eigen::Vector3d model_centroid_;
  Eigen::Matrix3d model_axes_;   // columns: principal axes of B̂, decreasing variance
  Eigen::AlignedBox3d model_box_;
  std::vector<Eigen::Matrix3d> uniform_rotations_;
};

// The proper rotations R = A_cloud · S · P · A_model^T for the sign patterns S
// and (optionally) the axis permutations P with det(R) = +1: 4 or 24 of them.
std::vector<Eigen::Matrix3d> PrincipalAxisRotations(const Eigen::Matrix3d& model_axes,
                                                    const Eigen::Matrix3d& cloud_axes,
                                                    bool permutations);

// Principal axes (columns, decreasing variance, right-handed) of a point set
// about its centroid.
Eigen::Matrix3d PrincipalAxes(const PointSet& points, const Eigen::Vector3d& centroid);

}  // namespace c3po
