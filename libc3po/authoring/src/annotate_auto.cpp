// Snapping and automatic keypoint proposal (c3po annotate --keypoint / --auto).
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "c3po/authoring/annotate.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/base/random.hpp"
#include "c3po/geometry/kdtree.hpp"

namespace c3po {
namespace {

// Seed stream of the dense sample, distinct from the stream of the first pick.
constexpr std::uint64_t kSampleStream = 0;
constexpr std::uint64_t kPickStream = 1;

// Indices of the samples with the smallest and largest projection on each
// principal axis of the whole sample (the shape's tips).
std::vector<int> ExtremalSamples(const PointSet& points) {
  const Eigen::Vector3d mean = points.rowwise().mean();
  const PointSet centred = points.colwise() - mean;
  const Eigen::Matrix3d covariance = centred * centred.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  std::vector<int> extremal;
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::VectorXd projection = solver.eigenvectors().col(axis).transpose() * centred;
    Eigen::Index low = 0, high = 0;
    projection.minCoeff(&low);
    projection.maxCoeff(&high);
    extremal.push_back(static_cast<int>(low));
    extremal.push_back(static_cast<int>(high));
  }
  return extremal;
}

// Candidate samples: the top `fraction` by saliency (ties broken by index)
// plus the extremal samples, without duplicates, in increasing index order.
std::vector<int> SalientCandidates(const std::vector<double>& saliency, double fraction,
                                   const std::vector<int>& extremal) {
  const int n = static_cast<int>(saliency.size());
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  const int keep = std::clamp(static_cast<int>(std::ceil(fraction * n)), 1, n);
  std::partial_sort(order.begin(), order.begin() + keep, order.end(), [&](int a, int b) {
    return saliency[a] != saliency[b] ? saliency[a] > saliency[b] : a < b;
  });
  std::vector<int> candidates(order.begin(), order.begin() + keep);
  candidates.insert(candidates.end(), extremal.begin(), extremal.end());
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  return candidates;
}

// Weighted farthest-point sampling over `candidates` (indices into `points`;
// `weight` per candidate, > 0). Distances
// start at the distance to `existing` (infinite when there is none); the first
// pick is `first` when there are no existing keypoints.
std::vector<int> FarthestPointSampling(const PointSet& points, const std::vector<int>& candidates,
                                       const std::vector<double>& weight, int count, int first,
                                       const PointSet& existing) {
  // Next pick: the candidate maximising weight x distance to the picks so far.
  const auto next_pick = [&](const std::vector<double>& distance) {
    int best = 0;
    for (int c = 1; c < static_cast<int>(distance.size()); ++c) {
      if (distance[c] * weight[c] > distance[best] * weight[best]) best = c;
    }
    return best;
  };
  const int n = static_cast<int>(candidates.size());
  std::vector<double> distance(n, std::numeric_limits<double>::infinity());
  for (int c = 0; c < n; ++c) {
    for (Eigen::Index e = 0; e < existing.cols(); ++e) {
      distance[c] = std::min(distance[c], (points.col(candidates[c]) - existing.col(e)).norm());
    }
  }
  std::vector<int> picked;
  int next = existing.cols() == 0 ? first : next_pick(distance);
  while (static_cast<int>(picked.size()) < count) {
    if (!(distance[next] > 0.0)) break;   // every remaining candidate coincides with a pick
    picked.push_back(next);
    const Eigen::Vector3d p = points.col(candidates[next]);
    for (int c = 0; c < n; ++c) {
      distance[c] = std::min(distance[c], (points.col(candidates[c]) - p).norm());
    }
    next = next_pick(distance);
  }
  for (int& p : picked) p = candidates[p];
  return picked;
}

// Candidates whose saliency is the largest among their k nearest points
// (ties: smaller index wins): one per salient corner or tip instead of a band.
std::vector<int> LocalMaxima(const PointTree& tree, const std::vector<double>& saliency,
                             const std::vector<int>& candidates, int neighbours) {
  std::vector<char> is_maximum(candidates.size(), 0);
  ParallelFor(0, static_cast<int>(candidates.size()), [&](int c) {
    const int i = candidates[c];
    bool maximum = true;
    for (const auto& n : tree.KNearest(tree.points().col(i), neighbours)) {
      const int j = static_cast<int>(n.index);
      if (saliency[j] > saliency[i] || (saliency[j] == saliency[i] && j < i)) maximum = false;
    }
    is_maximum[c] = maximum;
  });
  std::vector<int> maxima;
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    if (is_maximum[c]) maxima.push_back(candidates[c]);
  }
  return maxima;
}

// FPS weight of each peak: its saliency relative to the most salient peak
// (corners beat edge points at similar distances); tips count at least half,
// as smooth tips have low surface variation but are distinctive.
std::vector<double> PeakWeights(const std::vector<double>& saliency, const std::vector<int>& peaks,
                                const std::vector<int>& extremal) {
  double top = 0.0;
  for (int i : peaks) top = std::max(top, saliency[i]);
  std::vector<double> weight;
  for (int i : peaks) {
    const bool tip = std::find(extremal.begin(), extremal.end(), i) != extremal.end();
    const double w = top > 0.0 ? saliency[i] / top : 1.0;
    weight.push_back(std::max(tip ? 0.5 : 0.05, w));
  }
  return weight;
}

// The dense sample plus the mesh vertices (exact corners) when there are not
// too many of them.
PointSet CandidatePool(const Mesh& mesh, const PointSet& sample, int max_vertices) {
  if (mesh.vertices.cols() > max_vertices) return sample;
  PointSet pool(3, sample.cols() + mesh.vertices.cols());
  pool << sample, mesh.vertices;
  return pool;
}

double MinSeparation(const PointSet& points) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    for (Eigen::Index j = i + 1; j < points.cols(); ++j) {
      best = std::min(best, (points.col(i) - points.col(j)).norm());
    }
  }
  return points.cols() < 2 ? 0.0 : best;
}

}  // namespace

std::vector<SnapResult> SnapToSurface(const Mesh& mesh, const PointSet& points) {
  if (mesh.empty()) throw std::invalid_argument("SnapToSurface: mesh has no triangles");
  std::vector<SnapResult> results(points.cols());
  ParallelFor(0, static_cast<int>(points.cols()), [&](int i) {
    const SurfacePoint closest = ClosestSurfacePoint(mesh, points.col(i));
    results[i] = {points.col(i), closest.point, closest.distance, closest.triangle};
  });
  return results;
}

void AutoKeypointOptions::Check() const {
  if (count < 1) throw std::invalid_argument("AutoKeypointOptions: count must be >= 1");
  if (sample_size < 100) throw std::invalid_argument("AutoKeypointOptions: sample_size must be >= 100");
  if (small_neighbourhood < 4 || large_neighbourhood < small_neighbourhood) {
    throw std::invalid_argument("AutoKeypointOptions: need 4 <= small_neighbourhood <= large_neighbourhood");
  }
  if (!(salient_fraction > 0.0 && salient_fraction <= 1.0)) {
    throw std::invalid_argument("AutoKeypointOptions: salient_fraction must be in (0, 1]");
  }
}

std::vector<double> SurfaceVariation(const PointSet& points, int neighbours) {
  const PointTree tree(points);
  std::vector<double> variation(points.cols(), 0.0);
  ParallelFor(0, static_cast<int>(points.cols()), [&](int i) {
    const auto near = tree.KNearest(points.col(i), neighbours);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& n : near) mean += points.col(n.index);
    mean /= static_cast<double>(near.size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const auto& n : near) {
      const Eigen::Vector3d d = points.col(n.index) - mean;
      covariance += d * d.transpose();
    }
    const Eigen::Vector3d eigenvalues =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance, Eigen::EigenvaluesOnly)
            .eigenvalues();   // increasing
    const double total = eigenvalues.sum();
    variation[i] = total > 0.0 ? std::max(0.0, eigenvalues(0)) / total : 0.0;
  });
  return variation;
}

AutoKeypoints ProposeKeypoints(const Mesh& mesh, const AutoKeypointOptions& options,
                               const PointSet& existing) {
  options.Check();
  if (mesh.empty()) throw std::invalid_argument("ProposeKeypoints: mesh has no triangles");
  const PointSet sample = SampleSurface(mesh, options.sample_size,
                                        Rng::ForItem(options.seed, kSampleStream).Next());
  const PointTree tree(CandidatePool(mesh, sample, options.max_mesh_vertices));
  const PointSet& points = tree.points();

  // Saliency: the larger surface variation of two neighbourhood scales.
  std::vector<double> saliency = SurfaceVariation(points, options.small_neighbourhood);
  const std::vector<double> coarse = SurfaceVariation(points, options.large_neighbourhood);
  for (std::size_t i = 0; i < saliency.size(); ++i) saliency[i] = std::max(saliency[i], coarse[i]);

  // Spread-out picks among the local saliency maxima and the tips first, then
  // (when there are not enough) among every salient candidate.
  const std::vector<int> extremal = ExtremalSamples(points);
  const std::vector<int> candidates = SalientCandidates(saliency, options.salient_fraction, extremal);
  std::vector<int> peaks = LocalMaxima(tree, saliency, candidates, options.large_neighbourhood);
  peaks.insert(peaks.end(), extremal.begin(), extremal.end());
  std::sort(peaks.begin(), peaks.end());
  peaks.erase(std::unique(peaks.begin(), peaks.end()), peaks.end());
  Rng pick_rng = Rng::ForItem(options.seed, kPickStream);
  const int first = pick_rng.UniformInt(static_cast<int>(peaks.size()));
  std::vector<int> picks = FarthestPointSampling(points, peaks, PeakWeights(saliency, peaks, extremal),
                                                 options.count, first, existing);
  if (static_cast<int>(picks.size()) < options.count) {
    PointSet taken(3, existing.cols() + static_cast<Eigen::Index>(picks.size()));
    taken.leftCols(existing.cols()) = existing;
    for (std::size_t k = 0; k < picks.size(); ++k) taken.col(existing.cols() + k) = points.col(picks[k]);
    const std::vector<int> more = FarthestPointSampling(
        points, candidates, std::vector<double>(candidates.size(), 1.0),
        options.count - static_cast<int>(picks.size()), 0, taken);
    picks.insert(picks.end(), more.begin(), more.end());
  }
  if (static_cast<int>(picks.size()) < options.count) {
    throw InputError("--auto: the mesh offers only " + std::to_string(picks.size()) +
                     " distinct candidate keypoints, " + std::to_string(options.count) + " requested");
  }

  AutoKeypoints result;
  result.candidate_count = static_cast<int>(peaks.size());
  result.points.resize(3, static_cast<Eigen::Index>(picks.size()));
  for (std::size_t k = 0; k < picks.size(); ++k) {
    result.points.col(static_cast<Eigen::Index>(k)) = points.col(picks[k]);
    result.saliency.push_back(saliency[picks[k]]);
    result.triangle.push_back(ClosestSurfacePoint(mesh, points.col(picks[k])).triangle);
  }
  result.min_separation = MinSeparation(result.points);
  return result;
}

}  // namespace c3po
