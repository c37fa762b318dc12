// The background's dominant plane from flat image blocks (support_plane.hpp).
#include "c3po/io/support_plane.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <vector>

namespace c3po {
namespace {

// Background samples on a pixel grid of step `stride`, row-major in grid
// coordinates; samples without depth (or inside the mask) are absent.
struct SampleGrid {
  int stride = 1, columns = 0, rows = 0;
  std::vector<Eigen::Vector3d> points;   // present samples
  std::vector<int> index;                // grid cell -> points index, -1 if absent
};

// About 20 000 grid cells whatever the image size.
constexpr double kTargetSamples = 20000.0;
// Hypotheses come from blocks of kBlock x kBlock grid cells.
constexpr int kBlock = 8;
constexpr int kMinBlockSamples = kBlock * kBlock / 2;

SampleGrid BackgroundSamples(const DepthImage& depth, const Mask& object_mask, const PinholeCamera& camera) {
  SampleGrid grid;
  const double pixels = static_cast<double>(depth.width) * depth.height;
  grid.stride = std::max(1, static_cast<int>(std::ceil(std::sqrt(pixels / kTargetSamples))));
  grid.columns = (depth.width + grid.stride - 1) / grid.stride;
  grid.rows = (depth.height + grid.stride - 1) / grid.stride;
  grid.index.assign(static_cast<std::size_t>(grid.columns) * grid.rows, -1);
  for (int gv = 0; gv < grid.rows; ++gv) {
    for (int gu = 0; gu < grid.columns; ++gu) {
      const int u = gu * grid.stride, v = gv * grid.stride;
      const float z = depth.at(u, v);
      if (!DepthImage::Valid(z) || object_mask.at(u, v)) continue;
      const Eigen::Vector3d p = camera.BackProject(u, v, z);
      if (!p.allFinite()) continue;
      grid.index[static_cast<std::size_t>(gv) * grid.columns + gu] = static_cast<int>(grid.points.size());
      grid.points.push_back(p);
    }
  }
  return grid;
}

// Least-squares plane through the points (smallest principal direction of
// their covariance) and its RMS residual; nothing for degenerate input.
struct PlaneWithResidual {
  Plane plane;
  double rms = 0.0;
};
std::optional<PlaneWithResidual> FitPlane(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 3) return std::nullopt;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) covariance += (p - mean) * (p - mean).transpose();
  covariance /= static_cast<double>(points.size());
  if (!covariance.allFinite() || !mean.allFinite()) return std::nullopt;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  if (eigen.info() != Eigen::Success) return std::nullopt;
  // A plane needs two spread directions: the middle eigenvalue must exceed the
  // smallest (a line of samples fits every plane through it).
  const Eigen::Vector3d values = eigen.eigenvalues();
  if (!(values(1) > 4.0 * std::max(values(0), 0.0))) return std::nullopt;
  PlaneWithResidual fit;
  fit.plane.normal = eigen.eigenvectors().col(0).normalized();
  fit.plane.offset = fit.plane.normal.dot(mean);
  fit.rms = std::sqrt(std::max(values(0), 0.0));
  return fit;
}

int CountWithin(const std::vector<Eigen::Vector3d>& points, const Plane& plane, double distance) {
  int count = 0;
  for (const Eigen::Vector3d& p : points) count += plane.Distance(p) <= distance;
  return count;
}

// One hypothesis per flat block of the grid.
std::vector<Plane> BlockHypotheses(const SampleGrid& grid, double distance) {
  std::vector<Plane> hypotheses;
  std::vector<Eigen::Vector3d> block;
  for (int bv = 0; bv < grid.rows; bv += kBlock) {
    for (int bu = 0; bu < grid.columns; bu += kBlock) {
      block.clear();
      for (int gv = bv; gv < std::min(grid.rows, bv + kBlock); ++gv) {
        for (int gu = bu; gu < std::min(grid.columns, bu + kBlock); ++gu) {
          const int i = grid.index[static_cast<std::size_t>(gv) * grid.columns + gu];
          if (i >= 0) block.push_back(grid.points[static_cast<std::size_t>(i)]);
        }
      }
      if (static_cast<int>(block.size()) < kMinBlockSamples) continue;
      const std::optional<PlaneWithResidual> fit = FitPlane(block);
      if (fit && fit->rms <= 0.5 * distance) hypotheses.push_back(fit->plane);
    }
  }
  return hypotheses;
}

}  // namespace

std::optional<SupportPlaneFit> FitSupportPlane(const DepthImage& depth, const Mask& object_mask,
                                               const PinholeCamera& camera, double distance,
                                               double min_image_fraction) {
  if (!(distance > 0.0) || depth.width <= 0 || depth.height <= 0 || object_mask.width != depth.width ||
      object_mask.height != depth.height) {
    return std::nullopt;
  }
  const SampleGrid grid = BackgroundSamples(depth, object_mask, camera);
  const std::vector<Plane> hypotheses = BlockHypotheses(grid, distance);
  int best_count = 0;
  const Plane* best = nullptr;
  for (const Plane& plane : hypotheses) {
    const int count = CountWithin(grid.points, plane, distance);
    if (count > best_count) best_count = count, best = &plane;   // first of equals: deterministic
  }
  if (best == nullptr) return std::nullopt;
  // Refit to the inliers; keep the refit only when it holds at least as many.
  std::vector<Eigen::Vector3d> inliers;
  for (const Eigen::Vector3d& p : grid.points) {
    if (best->Distance(p) <= distance) inliers.push_back(p);
  }
  SupportPlaneFit result;
  result.plane = *best;
  result.inlier_samples = best_count;
  if (const std::optional<PlaneWithResidual> refit = FitPlane(inliers)) {
    const int count = CountWithin(grid.points, refit->plane, distance);
    if (count >= best_count) result.plane = refit->plane, result.inlier_samples = count;
  }
  // The camera's side is positive: Signed(camera centre) = -offset > 0.
  if (result.plane.offset > 0.0) result.plane.normal = -result.plane.normal, result.plane.offset = -result.plane.offset;
  result.image_samples = grid.columns * grid.rows;
  result.background_samples = static_cast<int>(grid.points.size());
  if (result.inlier_samples < std::max(3.0, min_image_fraction * result.image_samples)) return std::nullopt;
  return result;
}

}  // namespace c3po
