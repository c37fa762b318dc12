// Automatic eps_oc: eps_s from the model sample, eps_w from local surface fits
// on the unlabelled clouds, and the cluster of oc distances (see the header).
#include "c3po/method/auto_threshold.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "c3po/base/error.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/geometry/kdtree.hpp"
#include "c3po/geometry/mesh.hpp"

namespace c3po {
namespace {

constexpr double kMadToSigma = 1.4826;   // sigma / MAD of a Gaussian

// Offset of `point` from the quadric height field fitted (least squares) to
// its neighbours in their PCA frame (normal = least-variance axis):
//   h = a u^2 + b uv + c v^2 + d u + e v + f.
// A quadric absorbs curvature, which a plane fit would count as noise. The
// offset is divided by sqrt(1 + leverage) (leverage = phi^T (A^T A)^-1 phi of
// the query), so that under pure normal noise of sigma it has variance sigma^2.
// NaN when the fit is ill-posed.
double QuadricResidual(const PointSet& patch, const Eigen::Vector3d& point) {
  const Eigen::Vector3d mean = patch.rowwise().mean();
  const PointSet centred = patch.colwise() - mean;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca(centred * centred.transpose());
  const Eigen::Matrix3d frame = pca.eigenvectors();   // columns: normal, tangent, tangent
  auto features = [](double u, double v) {
    Eigen::Matrix<double, 6, 1> phi;
    phi << u * u, u * v, v * v, u, v, 1.0;
    return phi;
  };
  // Scale tangent coordinates to O(1) for conditioning.
  const double scale = std::sqrt(std::max(pca.eigenvalues()(2) / patch.cols(), 1e-300));
  Eigen::MatrixXd a(patch.cols(), 6);
  Eigen::VectorXd h(patch.cols());
  for (Eigen::Index j = 0; j < patch.cols(); ++j) {
    const Eigen::Vector3d local = frame.transpose() * centred.col(j);
    a.row(j) = features(local(1) / scale, local(2) / scale).transpose();
    h(j) = local(0);
  }
  const Eigen::Matrix<double, 6, 6> normal_matrix = a.transpose() * a;
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(normal_matrix);
  if (solver.info() != Eigen::Success || solver.rcond() < 1e-10) return std::nan("");
  const Eigen::Matrix<double, 6, 1> theta = solver.solve(a.transpose() * h);
  const Eigen::Vector3d local = frame.transpose() * (point - mean);
  const Eigen::Matrix<double, 6, 1> phi = features(local(1) / scale, local(2) / scale);
  const double leverage = phi.dot(solver.solve(phi));
  return (local(0) - phi.dot(theta)) / std::sqrt(1.0 + std::max(0.0, leverage));
}

// Normal offsets of (a stride of) the points of one cloud from the quadric of
// their k nearest neighbours (the point itself excluded).
std::vector<double> SurfaceResiduals(const PointSet& cloud, int k, int max_points) {
  std::vector<double> residuals;
  const PointSet all = FiniteColumns(cloud);
  if (all.cols() < k + 1) return residuals;
  const PointTree tree(all);
  const Eigen::Index stride = std::max<Eigen::Index>(1, all.cols() / std::max(1, max_points));
  for (Eigen::Index q = 0; q < all.cols(); q += stride) {
    PointSet patch(3, k);
    int used = 0;
    for (const auto& nb : tree.KNearest(all.col(q), k + 1)) {
      if (nb.index != q && used < k) patch.col(used++) = all.col(nb.index);
    }
    if (used < k) continue;
    const double residual = QuadricResidual(patch, all.col(q));
    if (std::isfinite(residual)) residuals.push_back(residual);
  }
  return residuals;
}

double MedianAbsoluteDeviation(const std::vector<double>& values, double median) {
  std::vector<double> deviations;
  for (double v : values) deviations.push_back(std::abs(v - median));
  return SampleQuantile(deviations, 0.5);
}

}  // namespace

double SampleQuantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double position = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const std::size_t low = static_cast<std::size_t>(std::floor(position));
  const std::size_t high = std::min(low + 1, values.size() - 1);
  return values[low] + (position - static_cast<double>(low)) * (values[high] - values[low]);
}

void AutoEpsOcOptions::Check() const {
  auto fail = [](const std::string& problem) { throw InputError("auto eps_oc", problem); };
  if (neighbours < 8 || neighbours > 200) fail("neighbours must be in [8, 200]");
  if (max_points_per_cloud < 1) fail("max_points_per_cloud must be positive");
  if (max_clouds < 1) fail("max_clouds must be positive");
  if (!(noise_sigmas > 0 && std::isfinite(noise_sigmas))) fail("noise_sigmas must be positive");
  if (sampling_probes < 100) fail("sampling_probes must be at least 100");
  if (!(margin >= 1.0 && std::isfinite(margin))) fail("margin must be at least 1");
  if (!(max_oc_factor >= 1.0 && std::isfinite(max_oc_factor))) fail("max_oc_factor must be at least 1");
  if (min_oc_distances < 3) fail("min_oc_distances must be at least 3");
}

SamplingDensityEstimate EstimateSamplingDensity(const ObjectModel& object, const AutoEpsOcOptions& options) {
  options.Check();
  SamplingDensityEstimate estimate;
  estimate.spacing = object.SampleSpacing();
  const PointSet& sample = object.sample();
  std::vector<double> gaps(sample.cols(), 0.0);
  ParallelFor(0, static_cast<int>(sample.cols()), [&](int i) {
    const auto nb = object.tree().KNearest(sample.col(i), 2);
    if (nb.size() == 2) gaps[i] = std::sqrt(nb[1].squared_distance);
  });
  estimate.max_gap = gaps.empty() ? 0.0 : *std::max_element(gaps.begin(), gaps.end());
  // Assumption "Dense CAD Model Sampling": sup over the surface of the
  // distance to B̂, estimated on fresh uniform surface points.
  const PointSet probes = SampleSurface(object.mesh(), options.sampling_probes, options.seed ^ 0x9e3779b97f4a7c15ULL);
  const Eigen::VectorXd distances = object.DistancesToPosedModel(probes, Pose::Identity());
  estimate.probes = static_cast<int>(probes.cols());
  estimate.eps_s = distances.size() ? distances.maxCoeff() : 0.0;
  estimate.probe_q99 = SampleQuantile(std::vector<double>(distances.data(), distances.data() + distances.size()), 0.99);
  return estimate;
}

NoiseEstimate EstimateSensorNoise(const std::vector<PointSet>& clouds, const AutoEpsOcOptions& options) {
  options.Check();
  const int count = static_cast<int>(std::min<std::size_t>(clouds.size(), options.max_clouds));
  std::vector<std::vector<double>> per_cloud(count);
  ParallelFor(0, count, [&](int j) {
    const std::size_t index = static_cast<std::size_t>(j) * clouds.size() / count;
    per_cloud[j] = SurfaceResiduals(clouds[index], options.neighbours, options.max_points_per_cloud);
  });
  NoiseEstimate estimate;
  std::vector<double> residuals, magnitudes;
  for (const auto& r : per_cloud) {
    estimate.clouds += !r.empty();
    residuals.insert(residuals.end(), r.begin(), r.end());
  }
  for (double r : residuals) magnitudes.push_back(std::abs(r));
  estimate.residuals = static_cast<int>(residuals.size());
  if (residuals.empty()) return estimate;
  const double centre = SampleQuantile(residuals, 0.5);
  estimate.sigma = kMadToSigma * MedianAbsoluteDeviation(residuals, centre);
  estimate.median = SampleQuantile(magnitudes, 0.5);
  estimate.q90 = SampleQuantile(magnitudes, 0.9);
  estimate.q99 = SampleQuantile(magnitudes, 0.99);
  estimate.eps_w = options.noise_sigmas * estimate.sigma;
  return estimate;
}

AutoEpsOcResult EstimateEpsOc(const ObjectModel& object, const std::vector<PointSet>& clouds,
                              const AutoEpsOcOptions& options, const std::vector<double>* oc_distances) {
  options.Check();
  AutoEpsOcResult result;
  result.noise = EstimateSensorNoise(clouds, options);
  if (result.noise.residuals == 0) {
    throw InputError("auto eps_oc", "no cloud has " + std::to_string(options.neighbours + 1) +
                                        " finite points for a local surface fit");
  }
  result.sampling = EstimateSamplingDensity(object, options);
  result.geometric = options.margin * (result.noise.eps_w + result.sampling.eps_s);   // Theorem 12
  result.eps_oc = result.geometric;
  result.rule = "margin * (eps_w + eps_s)";
  if (oc_distances) {
    std::vector<double> finite, cluster;
    for (double d : *oc_distances) {
      if (std::isfinite(d)) finite.push_back(d);
    }
    const double cap = options.max_oc_factor * result.geometric;
    for (double d : finite) {
      if (d < cap) cluster.push_back(d);
    }
    result.oc_count = static_cast<int>(finite.size());
    result.oc_cluster = static_cast<int>(cluster.size());
    result.oc_q10 = SampleQuantile(finite, 0.1);
    result.oc_q50 = SampleQuantile(finite, 0.5);
    result.oc_q90 = SampleQuantile(finite, 0.9);
    if (result.oc_cluster >= options.min_oc_distances) {
      const double median = SampleQuantile(cluster, 0.5);
      result.oc_cluster_edge = median + 3.0 * kMadToSigma * MedianAbsoluteDeviation(cluster, median);
      if (result.oc_cluster_edge > result.eps_oc) {
        result.eps_oc = std::min(result.oc_cluster_edge, cap);
        result.rule = result.oc_cluster_edge < cap ? "edge of the oc-distance cluster"
                                                   : "max_oc_factor * margin * (eps_w + eps_s) (cluster edge capped)";
      }
    }
    const auto below = std::count_if(finite.begin(), finite.end(), [&](double d) { return d < result.eps_oc; });
    result.oc_fraction_below = finite.empty() ? 0.0 : static_cast<double>(below) / finite.size();
  }
  return result;
}

std::string AutoEpsOcResult::ToJson() const {
  nlohmann::json doc;
  doc["eps_oc"] = eps_oc;
  doc["rule"] = rule;
  doc["geometric"] = geometric;
  doc["eps_s"] = sampling.eps_s;
  doc["sample_spacing"] = sampling.spacing;
  doc["sample_max_gap"] = sampling.max_gap;
  doc["probe_q99"] = sampling.probe_q99;
  doc["probes"] = sampling.probes;
  doc["eps_w"] = noise.eps_w;
  doc["noise_sigma"] = noise.sigma;
  doc["residual_median"] = noise.median;
  doc["residual_q90"] = noise.q90;
  doc["residual_q99"] = noise.q99;
  doc["residuals"] = noise.residuals;
  doc["noise_clouds"] = noise.clouds;
  if (oc_count > 0) {
    doc["oc_count"] = oc_count;
    doc["oc_cluster"] = oc_cluster;
    doc["oc_q10"] = oc_q10;
    doc["oc_q50"] = oc_q50;
    doc["oc_q90"] = oc_q90;
    doc["oc_cluster_edge"] = oc_cluster_edge;
    doc["oc_fraction_below"] = oc_fraction_below;
  }
  return doc.dump();
}

}  // namespace c3po
