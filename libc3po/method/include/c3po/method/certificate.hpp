#pragma once
// Certificates (paper Section V; docs/method.md "Certificates"). Each certificate is
// a value that carries its evidence, not a bare bool.
#include <string>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct CertificateOptions {
  double eps_oc = 0.0;     // absolute, object units
  double delta_nd = 0.0;   // absolute, object units
  // The reference also requires max_i ||y_i - ŷ_i|| < eps_oc.
  bool check_keypoint_agreement = true;
  void Check() const;      // both thresholds positive and finite
  static CertificateOptions FromObject(const ObjectSpec& spec);
};

// oc = 1 iff max_{x in X} min_{p in T̂·B̂} ||x - p|| < eps_oc (paper eq. 19) and,
// with check_keypoint_agreement, max_i ||y_i - T̂ b_i|| < eps_oc.
struct ObservableCorrectness {
  bool passed = false;
  double eps_oc = 0.0;
  double max_point_distance = 0.0;     // "oc_distance"
  int worst_point = -1;
  double max_keypoint_distance = 0.0;  // max_i ||y_i - ŷ_i||
  Eigen::VectorXd point_distances;     // per input point
};

// nd = 1 iff some indicator set G_l has every posed keypoint ŷ_i, i in G_l,
// within delta_nd of an input point (paper eq. 21 and Section VII); no sets => 1.
struct NonDegeneracy {
  bool passed = false;
  double delta_nd = 0.0;
  int passing_set = -1;                   // first set that passed, -1 if none / no sets
  std::vector<double> set_worst_distance; // per set: max_{i in G_l} dist(ŷ_i, X)
  Eigen::VectorXd keypoint_distances;     // per keypoint: min_x ||ŷ_i - x||
};

struct Certificate {
  ObservableCorrectness oc;
  NonDegeneracy nd;
  bool certified() const { return oc.passed && nd.passed; }
};

ObservableCorrectness CheckObservableCorrectness(const ObjectModel& object, const PointSet& cloud,
                                                 const Pose& scene_from_model,
                                                 const PointSet& corrected_keypoints,
                                                 const CertificateOptions& options);
NonDegeneracy CheckNonDegeneracy(const ObjectModel& object, const PointSet& cloud,
                                 const Pose& scene_from_model, const CertificateOptions& options);
Certificate Certify(const ObjectModel& object, const PointSet& cloud, const Pose& scene_from_model,
                    const PointSet& corrected_keypoints, const CertificateOptions& options);

// min over input points of ||q - x|| for every column q (brute force: N is small).
Eigen::VectorXd DistancesToCloud(const PointSet& queries, const PointSet& cloud);

}  // namespace c3po
