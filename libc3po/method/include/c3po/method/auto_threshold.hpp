#pragma once
// Automatic eps_oc (the paper's Remark "Automatic Tuning of eps_oc", named
// there as future work). Theorem 12 needs eps_oc > eps_w + eps_s:
// - eps_s (Assumption "Dense CAD Model Sampling"): every surface point lies
//   within eps_s of a point of B̂. Estimated directly as the largest distance
//   from fresh uniform surface points (probes) to B̂.
// - eps_w (Assumption "Bounded Noise"): estimated from the unlabelled clouds
//   themselves. For each point, a local surface is fitted to its k nearest
//   neighbours in its own cloud (the point excluded): a quadric height field
//   in the neighbours' PCA frame, so curvature is not mistaken for noise. The
//   point's offset from it along the normal, divided by sqrt(1 + leverage), has
//   variance sigma^2 under normal noise of sigma. Surface noise is what moves a
//   point off the surface (tangential noise does not), so sigma is estimated
//   robustly as 1.4826 * MAD of the offsets (edges and creases are a minority
//   of the points); eps_w = noise_sigmas * sigma.
// - geometric proposal: margin * (eps_w + eps_s).
// - oc distances (optional): max_x dist(x, T̂·B̂) of a detector + corrector on
//   the same clouds. Correct estimates form a tight low cluster (a maximum of
//   gap + noise over each cloud), wrong ones spread above. The cluster edge
//   (median + 3 * 1.4826 * MAD of the distances below max_oc_factor times the
//   geometric value) raises eps_oc when the geometric value would reject the
//   bulk of the cluster, capped at max_oc_factor times the geometric value.
#include <cstdint>
#include <string>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/method/certificate.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct AutoEpsOcOptions {
  int neighbours = 16;             // k of the local quadric fits (>= 8)
  int max_points_per_cloud = 1000; // evenly strided subsample of each cloud
  int max_clouds = 200;            // clouds used for the noise (evenly strided)
  double noise_sigmas = 3.0;       // eps_w = noise_sigmas * sigma
  int sampling_probes = 20000;     // fresh surface points for eps_s
  std::uint64_t seed = 0;          // of the probes
  double margin = 1.25;            // geometric eps_oc = margin * (eps_w + eps_s)
  double max_oc_factor = 2.0;      // the oc-distance cluster may raise eps_oc up to this factor
  int min_oc_distances = 10;       // fewer (finite) oc distances: they are not used
  void Check() const;              // throws InputError("auto eps_oc: ...")
};

struct SamplingDensityEstimate {
  double spacing = 0.0;      // mean nearest-neighbour distance in B̂ (ObjectModel::SampleSpacing)
  double max_gap = 0.0;      // largest nearest-neighbour distance in B̂
  double probe_q99 = 0.0;    // 99th percentile of probe -> B̂ distances
  double eps_s = 0.0;        // largest probe -> B̂ distance
  int probes = 0;
};

struct NoiseEstimate {
  int clouds = 0;            // clouds used
  int residuals = 0;         // points with a surface fit
  double sigma = 0.0;        // robust sigma of the normal offsets
  double median = 0.0;       // of |offset|
  double q90 = 0.0;
  double q99 = 0.0;
  double eps_w = 0.0;        // noise_sigmas * sigma
};

struct AutoEpsOcResult {
  double eps_oc = 0.0;       // the proposal (absolute, object units)
  SamplingDensityEstimate sampling;
  NoiseEstimate noise;
  double geometric = 0.0;    // margin * (eps_w + eps_s)
  // oc-distance evidence (when given)
  int oc_count = 0;          // finite distances given
  int oc_cluster = 0;        // of which below max_oc_factor * geometric
  double oc_q10 = 0.0, oc_q50 = 0.0, oc_q90 = 0.0;
  double oc_cluster_edge = 0.0;   // median + 3 * 1.4826 * MAD of the cluster
  double oc_fraction_below = 0.0; // fraction of all given distances below eps_oc
  std::string rule;          // which rule set eps_oc
  std::string ToJson() const;     // every field above
};

SamplingDensityEstimate EstimateSamplingDensity(const ObjectModel& object, const AutoEpsOcOptions& options);
NoiseEstimate EstimateSensorNoise(const std::vector<PointSet>& clouds, const AutoEpsOcOptions& options);

// The proposal with its evidence. Throws InputError("auto eps_oc: ...") when
// no cloud has enough points for a local surface fit.
AutoEpsOcResult EstimateEpsOc(const ObjectModel& object, const std::vector<PointSet>& clouds,
                              const AutoEpsOcOptions& options,
                              const std::vector<double>* oc_distances = nullptr);

// q in [0, 1]: linear interpolation between order statistics; 0 when empty.
double SampleQuantile(std::vector<double> values, double q);

}  // namespace c3po
