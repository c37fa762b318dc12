#include "c3po/plugins/svd_detector.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/method/icp.hpp"
#include "distance_grid.hpp"

namespace c3po {
namespace {

// Cloud subsample that measures the cloud's extent for box-aligned translations.
constexpr int kExtentPoints = 2000;

// The finite columns, evenly strided down to at most `limit` of them (0 = no
// limit): the finite points of rank floor(j m / k), j = 0..k-1, of the m
// finite ones. Deterministic, one pass over the input plus one to count; with
// m <= limit every finite column is kept, in order.
PointSet FiniteStridedColumns(const PointSet& points, int limit) {
  Eigen::Index finite = 0;
  for (Eigen::Index i = 0; i < points.cols(); ++i) finite += points.col(i).allFinite() ? 1 : 0;
  const Eigen::Index kept = limit > 0 ? std::min<Eigen::Index>(finite, limit) : finite;
  PointSet subset(3, kept);
  Eigen::Index rank = 0, next = 0;
  for (Eigen::Index i = 0; i < points.cols() && next < kept; ++i) {
    if (!points.col(i).allFinite()) continue;
    if (rank == next * finite / kept) subset.col(next++) = points.col(i);
    ++rank;
  }
  return subset;
}

// At most `count` distinct columns, chosen by a partial Fisher-Yates shuffle.
PointSet Subsample(const PointSet& points, int count, std::uint64_t seed) {
  if (points.cols() <= count) return points;
  std::vector<Eigen::Index> order(points.cols());
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  Rng rng(seed);
  for (int k = 0; k < count; ++k) {
    const int remaining = static_cast<int>(order.size()) - k;
    std::swap(order[k], order[k + rng.UniformInt(remaining)]);
  }
  PointSet subset(3, count);
  for (int k = 0; k < count; ++k) subset.col(k) = points.col(order[k]);
  return subset;
}

// Proper rotations among the 6 permutation matrices (signs are applied apart).
std::vector<Eigen::Matrix3d> AxisPermutations(bool all) {
  std::vector<Eigen::Matrix3d> permutations;
  std::array<int, 3> order{0, 1, 2};
  do {
    Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
    for (int row = 0; row < 3; ++row) P(row, order[row]) = 1.0;
    permutations.push_back(P);
  } while (all && std::next_permutation(order.begin(), order.end()));
  return permutations;
}

Pose CentroidAligned(const Eigen::Matrix3d& R, const Eigen::Vector3d& cloud_centroid,
                     const Eigen::Vector3d& model_centroid) {
  return {R, cloud_centroid - R * model_centroid};
}

}  // namespace

void SvdDetectorOptions::Check() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("SvdDetectorOptions: ") + what);
  };
  require(uniform_rotations >= 0, "uniform_rotations must be >= 0");
  require(max_input_points == 0 || max_input_points >= 100, "max_input_points must be 0 or >= 100");
  require(coarse_model_points >= 100, "coarse_model_points must be >= 100");
  require(grid_cells >= 2 && grid_cells <= 256, "grid_cells must be in [2, 256]");
  require(screening_points >= 3 && max_hypothesis_points >= 3 && max_final_points >= 3,
          "subsample sizes must be >= 3");
  require(screened_hypotheses >= 1 && refined_hypotheses >= 1, "kept hypotheses must be >= 1");
  require(hypothesis_icp_iterations >= 0 && final_icp_iterations >= 0,
          "ICP iterations must be >= 0");
  require(trim_fraction >= 0 && trim_fraction <= 0.9, "trim_fraction must be in [0, 0.9]");
}

Eigen::Matrix3d PrincipalAxes(const PointSet& points, const Eigen::Vector3d& centroid) {
  const PointSet centred = points.colwise() - centroid;
  const Eigen::Matrix3d covariance = centred * centred.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  // Eigen sorts eigenvalues increasingly; reverse to decreasing variance.
  Eigen::Matrix3d axes = eigen.eigenvectors().rowwise().reverse();
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
  return axes;
}

std::vector<Eigen::Matrix3d> PrincipalAxisRotations(const Eigen::Matrix3d& model_axes,
                                                    const Eigen::Matrix3d& cloud_axes,
                                                    bool permutations) {
  std::vector<Eigen::Matrix3d> rotations;
  for (const Eigen::Matrix3d& P : AxisPermutations(permutations)) {
    for (int signs = 0; signs < 8; ++signs) {
      const Eigen::Vector3d s((signs & 1) ? -1.0 : 1.0, (signs & 2) ? -1.0 : 1.0,
                              (signs & 4) ? -1.0 : 1.0);
      const Eigen::Matrix3d R = cloud_axes * s.asDiagonal() * P * model_axes.transpose();
      if (R.determinant() > 0) rotations.push_back(R);
    }
  }
  return rotations;
}

namespace {

ObjectModel CoarseCopy(const ObjectModel& object, const SvdDetectorOptions& options) {
  options.Check();
  ObjectModelOptions coarse;
  coarse.sample_size = options.coarse_model_points;
  coarse.seed = options.seed;
  return ObjectModel(object.spec(), object.mesh(), coarse);
}

}  // namespace

struct SvdDetector::Candidate {
  Pose scene_from_model;
  double score = 0.0;
};

SvdDetector::SvdDetector(const ObjectModel& object, const SvdDetectorOptions& options)
    : object_(object), coarse_(CoarseCopy(object, options)), options_(options) {
  model_centroid_ = object_.sample().rowwise().mean();
  model_axes_ = PrincipalAxes(object_.sample(), model_centroid_);
  model_box_ = Eigen::AlignedBox3d(object_.sample().rowwise().minCoeff(),
                                   object_.sample().rowwise().maxCoeff());
  grid_ = std::make_shared<const DistanceGrid>(object_.tree(), options_.grid_cells, 0.1);
  Rng rng(options_.seed ^ 0x5644u);
  for (int k = 0; k < options_.uniform_rotations; ++k) uniform_rotations_.push_back(rng.Rotation());
}

// Stage 1: every (rotation, translation) hypothesis scored on a few points
// with the distance field of B̂, without refinement; the best ones are returned.
std::vector<SvdDetector::Candidate> SvdDetector::Screen(const PointSet& points,
                                                        const Eigen::Vector3d& centroid) const {
  std::vector<Eigen::Matrix3d> rotations =
      PrincipalAxisRotations(model_axes_, PrincipalAxes(points, centroid), options_.try_permutations);
  rotations.insert(rotations.end(), uniform_rotations_.begin(), uniform_rotations_.end());
  const PointSet screening = Subsample(points, options_.screening_points, options_.seed + 2);
  const PointSet extent_points = Subsample(points, kExtentPoints, options_.seed + 3);
  const int choices = options_.box_translations ? 3 : 1;

  std::vector<Candidate> candidates;
  for (const Eigen::Matrix3d& R : rotations) {
    // Model-frame offsets s (t = R s): per axis, centroids match, or the
    // cloud's extent starts at the model box's low end, or ends at its high end.
    const PointSet rotated = R.transpose() * extent_points;
    const Eigen::Vector3d lows = rotated.rowwise().minCoeff(), highs = rotated.rowwise().maxCoeff();
    const Eigen::Vector3d centred = R.transpose() * centroid - model_centroid_;
    const Eigen::Matrix3d offsets = (Eigen::Matrix3d() << centred, lows - model_box_.min(),
                                     highs - model_box_.max()).finished();
    const PointSet rotated_screening = R.transpose() * screening;
    for (int code = 0; code < choices * choices * choices; ++code) {
      const Eigen::Vector3d s(offsets(0, code % 3), offsets(1, (code / 3) % 3), offsets(2, code / 9));
      const double score = grid_->MeanSquaredDistance(rotated_screening.colwise() - s);
      candidates.push_back({Pose{R, R * s}, score});
    }
  }
  const int keep = std::min<int>(options_.screened_hypotheses, static_cast<int>(candidates.size()));
  std::partial_sort(candidates.begin(), candidates.begin() + keep, candidates.end(),
                    [](const Candidate& a, const Candidate& b) { return a.score < b.score; });
  candidates.resize(keep);
  return candidates;
}

SvdEstimate SvdDetector::Estimate(const PointSet& cloud) const {
  // Huge clouds: every later stage (and the evidence) sees a strided subset.
  const PointSet points = FiniteStridedColumns(cloud, options_.max_input_points);
  if (points.cols() == 0) {
    throw InputError("cloud", "svd detector needs at least one finite point, got none of " +
                                  std::to_string(cloud.cols()));
  }
  const Eigen::Vector3d centroid = points.rowwise().mean();
  SvdEstimate estimate;
  estimate.scene_from_model = CentroidAligned(Eigen::Matrix3d::Identity(), centroid, model_centroid_);
  if (points.cols() < 3) return estimate;   // no axes: translation only

  const std::vector<Candidate> screened = Screen(points, centroid);
  estimate.screened = (options_.try_permutations ? 24 : 4) + options_.uniform_rotations;
  estimate.screened *= options_.box_translations ? 27 : 1;

  // Stage 2: brief ICP on the coarse model, eq. (9) score.
  const PointSet ranking_points = Subsample(points, options_.max_hypothesis_points, options_.seed);
  IcpOptions brief;
  brief.max_iterations = options_.hypothesis_icp_iterations;
  brief.trim_fraction = options_.trim_fraction;
  for (const Candidate& candidate : screened) {
    const IcpResult refined = RefineIcp(coarse_, ranking_points, candidate.scene_from_model, brief);
    estimate.hypotheses.push_back(
        {refined.scene_from_model, refined.rms_after * refined.rms_after, refined.iterations});
  }
  std::vector<int> order(estimate.hypotheses.size());
  std::iota(order.begin(), order.end(), 0);
  const int refined_count = std::min<int>(options_.refined_hypotheses, static_cast<int>(order.size()));
  std::partial_sort(order.begin(), order.begin() + refined_count, order.end(), [&](int a, int b) {
    return estimate.hypotheses[a].chamfer < estimate.hypotheses[b].chamfer;
  });

  // Stage 3: the best few, refined on B̂ and a larger subsample.
  const PointSet final_points = Subsample(points, options_.max_final_points, options_.seed + 1);
  IcpOptions longer = brief;
  longer.max_iterations = options_.final_icp_iterations;
  estimate.chamfer = std::numeric_limits<double>::infinity();
  for (int k = 0; k < refined_count; ++k) {
    const IcpResult refined =
        RefineIcp(object_, final_points, estimate.hypotheses[order[k]].scene_from_model, longer);
    const double chamfer = refined.rms_after * refined.rms_after;
    if (chamfer < estimate.chamfer) {
      estimate.chamfer = chamfer;
      estimate.scene_from_model = refined.scene_from_model;
      estimate.best_hypothesis = order[k];
    }
  }
  // Evidence on every used point (all finite ones up to max_input_points): eq. (9) to the posed B̂.
  Eigen::VectorXd squared;
  object_.NearestInPosedModel(points, estimate.scene_from_model, nullptr, &squared);
  estimate.chamfer = squared.mean();
  return estimate;
}

PointSet SvdDetector::Detect(const PointSet& cloud) const {
  return Estimate(cloud).scene_from_model * object_.keypoints();
}

}  // namespace c3po
