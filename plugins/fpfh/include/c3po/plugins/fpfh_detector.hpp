#pragma once
// The "fpfh" detector: the training-free FPFH + TEASER baseline of the C-3PO
// paper (Section VIII) as a keypoint detector. The object's model sample B̂
// and the input cloud X are voxel-downsampled, FPFH descriptors (Rusu et al.
// 2009, geometry/fpfh.hpp) are matched (mutual nearest neighbours in
// descriptor space, best matches first), and the correspondences are
// registered robustly in the TEASER++ manner (max-clique pruning, GNC-TLS
// rotation, adaptive-voting translation: method/robust_registration.hpp).
// The posed keypoints T·b are the detection, so the corrector and the
// certificates run on them as on any detector's output; "KeyPo (fpfh)" in
// c3po eval is FPFH + TEASER, "KeyPo (fpfh) + ICP" adds ICP.
//
// Normals: input clouds are depth clouds in the camera frame, so their
// normals are oriented towards the camera at the origin; the model's agree
// with the mesh's outward normals (the visible surface faces the camera).
#include <cstdint>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/geometry/fpfh.hpp"
#include "c3po/method/detector.hpp"
#include "c3po/method/robust_registration.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct FpfhDetectorOptions {
  // Defaults chosen on 30 rendered drill depth clouds (1 mm noise): 50 % with
  // ADD-S < 5 % d before ICP, 77 % after (docs/method.md "Baselines").
  double voxel_fraction = 0.02;       // voxel side = this x object diameter
  double normal_radius_voxels = 3.0;  // PCA normal radius, in voxels
  double feature_radius_voxels = 6.0; // FPFH radius, in voxels
  double noise_bound_voxels = 1.5;    // TEASER noise bound, in voxels
  int max_neighbors = 64;
  int max_input_points = 3000;        // after voxelisation (strided down beyond)
  int max_correspondences = 300;      // best descriptor matches kept
  int min_mutual_matches = 12;        // fewer mutual matches: one-way matches
  std::int64_t max_clique_branches = 200000;
  void Check() const;                 // throws std::invalid_argument
};

struct FpfhEstimate {
  Pose scene_from_model;
  int scene_points = 0;               // after voxelisation
  int model_points = 0;
  bool mutual = true;                 // false: fell back to one-way matches
  RobustRegistrationResult registration;
};

class FpfhDetector : public Detector {
 public:
  explicit FpfhDetector(const ObjectModel& object, const FpfhDetectorOptions& options = {});

  std::string name() const override { return "fpfh"; }
  int num_keypoints() const override { return object_.num_keypoints(); }
  // Posed keypoints T·b. Throws InputError("cloud: ...") when the cloud has
  // no finite point or the registration fails (too few consistent matches).
  // Safe to call concurrently; deterministic.
  PointSet Detect(const PointSet& cloud) const override;
  // The pose and the evidence; registration.failure non-empty on failure.
  FpfhEstimate Estimate(const PointSet& cloud) const;

  const FpfhDetectorOptions& options() const { return options_; }

 private:
  ObjectModel object_;
  FpfhDetectorOptions options_;
  double voxel_ = 0.0;
  PointSet model_points_;       // voxelised B̂
  FpfhFeatures model_features_;
};

}  // namespace c3po
