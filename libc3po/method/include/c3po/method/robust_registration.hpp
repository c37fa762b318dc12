#pragma once
// Certifiable-style robust registration in the manner of TEASER++ (Yang, Shi,
// Carlone, T-RO 2021) with known scale (= 1), for the training-free
// "FPFH + TEASER" baseline of the C-3PO evaluation:
//   1. putative correspondences (model b_i, scene a_i) from descriptor matching;
//   2. pairwise invariants (TIMs): correspondences i, j are consistent when
//      | |a_j - a_i| - |b_j - b_i| | <= 2 noise_bound (TEASER eq. 13, s = 1);
//      the inliers are a maximum clique of the consistency graph (exact
//      branch and bound with greedy colouring bounds, capped);
//   3. rotation by graduated non-convexity on the truncated least squares cost
//      (GNC-TLS, Yang, Antonante, Tzoumas, Carlone, RA-L 2020) over the TIMs
//      a_j - a_i = R (b_j - b_i) of the clique;
//   4. translation by adaptive voting: the exact 1-D TLS minimiser per
//      component (TEASER Section V-B).
#include <cstdint>
#include <string>
#include <vector>

#include "c3po/base/types.hpp"

namespace c3po {

// Adjacency lists of an undirected graph on vertices 0..n-1.
using Graph = std::vector<std::vector<int>>;

struct MaxCliqueResult {
  std::vector<int> clique;   // sorted vertex indices
  bool exact = true;         // false: the branch-and-bound budget ran out
  std::int64_t branches = 0; // branch-and-bound nodes expanded
};
// Maximum clique by branch and bound (Tomita-Seki MCQ: vertices ordered by
// degree, greedy colouring bound). Gives up after `max_branches` nodes and
// returns the largest clique found so far (exact = false).
MaxCliqueResult MaximumClique(const Graph& graph, std::int64_t max_branches = 2000000);

struct GncTlsOptions {
  double noise_bound = 0.0;      // c-bar: residuals above it are outliers (> 0)
  double mu_factor = 1.4;        // mu <- mu * factor per outer iteration (> 1)
  int max_iterations = 100;
  double cost_tolerance = 1e-10; // relative change of the TLS cost that stops
  void Check() const;            // throws std::invalid_argument
};

struct GncTlsRotationResult {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();   // scene_from_model rotation
  std::vector<int> inliers;      // residual <= noise_bound at the final R
  int iterations = 0;
  bool ok = false;               // false: fewer than 2 non-degenerate TIMs
};
// argmin_R sum_i min(|a_i - R b_i|^2, noise_bound^2) by GNC (weighted
// Procrustes with TLS weights, mu from small to large). a, b are 3 x m.
GncTlsRotationResult GncTlsRotation(const PointSet& model, const PointSet& scene,
                                    const GncTlsOptions& options);

struct VotingResult {
  double value = 0.0;
  double cost = 0.0;             // sum_i min((x_i - value)^2, bound^2)
  std::vector<int> inliers;      // |x_i - value| <= bound
};
// Exact minimiser of the 1-D TLS cost sum_i min((x_i - t)^2, bound_i^2): the
// optimum is the mean of the members of one maximal consistent set, found by
// sweeping the interval ends x_i -+ bound_i. Empty input: value 0.
VotingResult AdaptiveVoting(const std::vector<double>& values, const std::vector<double>& bounds);

struct RobustRegistrationOptions {
  double noise_bound = 0.0;          // object units, > 0
  int max_correspondences = 400;     // before pruning (best descriptor matches)
  std::int64_t max_clique_branches = 2000000;
  int max_rotation_tims = 2000;      // TIMs of the clique used for rotation
  GncTlsOptions gnc;                 // noise_bound is set from the above (2x, TIMs)
  void Check() const;
};

struct RobustRegistrationResult {
  Pose scene_from_model;
  int correspondences = 0;           // given
  int clique_size = 0;               // after max-clique pruning
  bool clique_exact = true;
  int rotation_inliers = 0;          // TIMs within 2 noise_bound
  int translation_inliers = 0;       // correspondences agreeing on all 3 components
  std::string failure;               // empty on success
  bool ok() const { return failure.empty(); }
};
// Correspondences (model.col(i), scene.col(i)). Never throws on degenerate
// data (see failure); throws std::invalid_argument on bad options or sizes.
RobustRegistrationResult RegisterRobust(const PointSet& model, const PointSet& scene,
                                        const RobustRegistrationOptions& options);

}  // namespace c3po
