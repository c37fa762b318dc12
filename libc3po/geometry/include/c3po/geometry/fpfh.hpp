#pragma once
// Fast Point Feature Histograms (Rusu, Blodow, Beetz, ICRA 2009): the local
// descriptors of the training-free "FPFH + TEASER" baseline (C-3PO paper,
// Section VIII baselines).
//
// Normals: the eigenvector of the smallest eigenvalue of the covariance of the
// neighbours within normal_radius (PCA), oriented towards a viewpoint (depth
// clouds: the camera at the origin) or away from the centroid of the cloud.
//
// Pair feature (Rusu 2009, eqs. 1-3): for points p_s, p_t with normals n_s,
// n_t, the source is the one whose normal makes the smaller angle with the
// line joining them; with d = p_t - p_s, the Darboux frame u = n_s,
// v = u x d/|d|, w = u x v gives
//   alpha = v . n_t,  phi = u . d/|d|,  theta = atan2(w . n_t, u . n_t).
// SPFH(p): 11-bin histograms of theta in [-pi, pi], alpha in [-1, 1] and
// phi in [-1, 1] over the pairs (p, q), q within feature_radius, each
// normalised to sum 100 (33 bins).
// FPFH(p) = SPFH(p) + (1/k) sum_i SPFH(p_i) / w_i, w_i = |p - p_i| (eq. 4),
// then each 11-bin block is normalised to sum 100 again. Serial (callers
// parallelise over clouds).
#include <Eigen/Core>

#include "c3po/base/types.hpp"
#include "c3po/geometry/kdtree.hpp"

namespace c3po {

constexpr int kFpfhBinsPerFeature = 11;
constexpr int kFpfhBins = 3 * kFpfhBinsPerFeature;
using FpfhFeatures = Eigen::Matrix<double, kFpfhBins, Eigen::Dynamic>;   // one column per point

enum class NormalOrientation {
  kTowardViewpoint,     // n . (viewpoint - p) >= 0
  kAwayFromCentroid,    // n . (p - centroid) >= 0 (rigid-motion invariant)
};

struct FpfhOptions {
  double normal_radius = 0.0;    // object units, > 0
  double feature_radius = 0.0;   // object units, > 0
  // Neighbours considered per point (the nearest ones within the radius).
  int max_neighbors = 64;
  NormalOrientation orientation = NormalOrientation::kTowardViewpoint;
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();
  void Check() const;   // throws std::invalid_argument
};

// Voxel-grid downsampling: the centroid of the finite points of every occupied
// cell of side `voxel` (> 0), cells in lexicographic order of their indices
// (deterministic). Non-finite points are dropped.
PointSet VoxelDownsample(const PointSet& points, double voxel);

// (alpha, phi, theta) of one ordered pair, with the source/target choice above.
Eigen::Vector3d PairFeature(const Eigen::Vector3d& p1, const Eigen::Vector3d& n1,
                            const Eigen::Vector3d& p2, const Eigen::Vector3d& n2);

// Unit normals (3 x n) of `tree.points()`; a point with fewer than 3
// neighbours within `radius` (itself included) gets a zero normal.
PointSet EstimateNormals(const PointTree& tree, const FpfhOptions& options);

// Descriptors of every point of `tree.points()` given its normals (zero
// normals: zero SPFH). Points without neighbours get the zero descriptor.
// Throws std::invalid_argument when normals has the wrong size or the options
// fail Check().
FpfhFeatures ComputeFpfh(const PointTree& tree, const PointSet& normals, const FpfhOptions& options);

}  // namespace c3po
