#pragma once
// Certificates (paper Section V; docs/method.md "Certificates" and
// "Outlier-robust certificates"). Each certificate is a value that carries its
// evidence, not a bare bool. With an outlier budget m (OutlierBudget):
//   oc_m: at most m input points lie at >= eps_oc from the posed model (and
//         the corrected keypoints agree, as today); the others are "accepted";
//   nd_m: the local non-degeneracy test passes on the accepted points and, if
//         the object has indicator sets, some set has every posed keypoint
//         supported by more than m accepted points within delta_nd, and no
//         rival pose far from T̂ passes oc_m (the global search,
//         global_uniqueness.hpp; run by the pipeline, EstimateAndCertify);
//   free space (depth-image inputs only, free_space.hpp): the camera did not
//         see through where the posed model would be.
// m = 0 is the paper (eq. 19, eq. 21) plus the local and global tests.
#include <string>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/method/free_space.hpp"
#include "c3po/method/global_uniqueness.hpp"
#include "c3po/method/local_nondegeneracy.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

// How many input points may be outliers: a count, or a fraction of the
// points (`--max-outliers 10` or `--max-outliers 2%`).
struct OutlierBudget {
  int count = 0;            // used when fraction == 0
  double fraction = 0.0;    // in [0, 1); > 0: floor(fraction * n)
  int Resolve(Eigen::Index points) const;
  bool IsZero() const { return count == 0 && fraction == 0.0; }
  std::string ToString() const;   // "10" or "2%"
  void Check() const;             // throws std::invalid_argument
};
// "10" | "2%" | "0"; throws InputError("--max-outliers", ...) otherwise.
OutlierBudget ParseOutlierBudget(const std::string& text);

// Default budget for depth-image / BOP input of `c3po certify` (segments with
// stray pixels; wired after 0 false certificates at it with the global rival
// search and the free-space test on: docs/method.md "Measured on real
// frames"). Ready-made clouds default to 0.
constexpr double kDepthImageOutlierFraction = 0.02;

struct CertificateOptions {
  double eps_oc = 0.0;     // absolute, object units
  double delta_nd = 0.0;   // absolute, object units
  // The reference also requires max_i ||y_i - ŷ_i|| < eps_oc.
  bool check_keypoint_agreement = true;
  OutlierBudget max_outliers;                  // m
  bool local_nondegeneracy = true;             // the local test is part of nd
  // false: nd ignores the object's indicator sets (as for an object without
  // any); the camera-frame default (docs/method.md "Indicator sets on camera
  // frames"): their corner keypoints lose their support to the mask erosion,
  // and with a percentage budget no delta_nd ball holds m + 1 points.
  bool use_indicator_sets = true;
  LocalNonDegeneracyOptions local;
  GlobalUniquenessOptions global;              // the rival search (pipeline.hpp runs it)
  FreeSpaceOptions free_space;                 // depth-image inputs (pipeline.hpp runs it)
  void Check() const;      // both thresholds positive and finite
  static CertificateOptions FromObject(const ObjectSpec& spec);
};

// oc_m = 1 iff #{x : min_{p in T̂·B̂} ||x - p|| >= eps_oc} <= m (paper eq. 19
// for m = 0) and, with check_keypoint_agreement, max_i ||y_i - T̂ b_i|| < eps_oc.
struct ObservableCorrectness {
  bool passed = false;                 // points_passed && keypoints_passed
  bool points_passed = false;          // at most m points at >= eps_oc (and at least one point)
  bool keypoints_passed = true;        // keypoint agreement (true when not checked)
  double eps_oc = 0.0;
  int max_outliers = 0;                // m resolved for this cloud
  double max_point_distance = 0.0;     // "oc_distance" (100 % quantile)
  int worst_point = -1;
  // (m+1)-th largest point distance: oc_m's point test is budget_distance < eps_oc.
  double budget_distance = 0.0;
  double max_keypoint_distance = 0.0;  // max_i ||y_i - ŷ_i||
  int outlier_count = 0;               // points at >= eps_oc
  std::vector<int> outlier_indices;    // ascending
  double max_inlier_distance = 0.0;    // largest distance below eps_oc
  double quantile50 = 0.0, quantile90 = 0.0, quantile99 = 0.0;
  Eigen::VectorXd point_distances;     // per input point
  Eigen::VectorXi nearest_model_point; // per input point: index into B̂
};

// nd_m (see the top of this file). For m = 0 the set test counts supports
// among all input points (the paper's eq. 21: identical to counting accepted
// points whenever oc passes); for m > 0 among the accepted points only
// (docs/method.md: the proof needs a support that oc_m controls).
struct NonDegeneracy {
  bool passed = false;
  double delta_nd = 0.0;
  int max_outliers = 0;
  int passing_set = -1;                   // first set that passed, -1 if none / no sets
  bool sets_passed = false;               // some set passed, or the object has none (or they are not used)
  bool sets_used = false;                 // the object has sets and CertificateOptions::use_indicator_sets
  std::vector<double> set_worst_distance; // per set: max_{i in G_l} dist(ŷ_i, X)
  std::vector<int> set_min_support;       // per set: min_{i in G_l} support count
  Eigen::VectorXd keypoint_distances;     // per keypoint: min_x ||ŷ_i - x||
  std::vector<int> keypoint_support;      // per keypoint: supporting points within delta_nd
  bool local_checked = false;
  LocalNonDegeneracy local;               // evidence of the local test
  // The finite check of a single weak motion (global_uniqueness.hpp, run by
  // EstimateAndCertify when the local test failed on exactly one motion and
  // everything else passed): when it passes, nd's local part passes.
  bool weak_motion_checked = false;
  WeakMotionCheck weak_motion;
  // The global rival search (global_uniqueness.hpp): run by EstimateAndCertify
  // when everything else passed (it cannot change any other decision).
  bool global_checked = false;
  GlobalUniqueness global;
};

// Identity among known objects (identity_check.hpp; docs/method.md
// "Identity among known objects"): every other object the user named was
// estimated and certified on the same cloud by its own certifier; the check
// fails when one of them is certified too (the cloud does not say which
// object it shows). Not checked: passes (the paper's single-object setting).
struct IdentityCheck {
  bool checked = false;
  bool passed = true;
  int objects_tried = 0;
  std::string rival;                   // the first other object certified on the cloud ("" = none)
  double rival_oc_distance = 0.0;      // its budget distance (the (m+1)-th largest point distance)
  Pose rival_scene_from_model;         // its certified pose
};

struct Certificate {
  ObservableCorrectness oc;
  NonDegeneracy nd;
  FreeSpace free_space;    // checked only for depth-image inputs (free_space.checked)
  IdentityCheck identity;  // checked only when other objects are named (certify --other-objects)
  // The pose explains what was seen: oc and, for depth-image inputs, free
  // space (nd aside). Failing it refutes an estimate; a pseudo-label needs it.
  bool fits_observation() const { return oc.passed && !free_space.refutes(); }
  bool certified() const { return fits_observation() && nd.passed && identity.passed; }
};

ObservableCorrectness CheckObservableCorrectness(const ObjectModel& object, const PointSet& cloud,
                                                 const Pose& scene_from_model,
                                                 const PointSet& corrected_keypoints,
                                                 const CertificateOptions& options);
// The oc_m decision and its outlier evidence from the per-point distances
// with another threshold (the distances do not depend on eps_oc), under the
// same budget (oc->max_outliers). The nd evidence depends on the accepted
// points: callers that change eps_oc decide nd again (CheckNonDegeneracy).
void RethresholdObservableCorrectness(ObservableCorrectness* oc, double eps_oc,
                                      bool check_keypoint_agreement = true);

// nd_m given the oc evidence of the same cloud and pose (accepted points).
NonDegeneracy CheckNonDegeneracy(const ObjectModel& object, const PointSet& cloud,
                                 const Pose& scene_from_model, const ObservableCorrectness& oc,
                                 const CertificateOptions& options);
// Convenience: computes the oc evidence first (keypoint agreement not needed).
NonDegeneracy CheckNonDegeneracy(const ObjectModel& object, const PointSet& cloud,
                                 const Pose& scene_from_model, const CertificateOptions& options);
Certificate Certify(const ObjectModel& object, const PointSet& cloud, const Pose& scene_from_model,
                    const PointSet& corrected_keypoints, const CertificateOptions& options);

// min over input points of ||q - x|| for every column q (brute force: N is small).
Eigen::VectorXd DistancesToCloud(const PointSet& queries, const PointSet& cloud);

}  // namespace c3po
