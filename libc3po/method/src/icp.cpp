#include "c3po/method/icp.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "c3po/geometry/registration.hpp"

namespace c3po {
namespace {

// Rotation angle of a^T b: atan2(|sin|, cos) stays accurate near 0 and pi.
double RotationAngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const Eigen::Matrix3d delta = a.transpose() * b;
  const Eigen::Vector3d axis(delta(2, 1) - delta(1, 2), delta(0, 2) - delta(2, 0),
                             delta(1, 0) - delta(0, 1));
  return std::atan2(0.5 * axis.norm(), 0.5 * (delta.trace() - 1.0));
}

// Nearest model-sample point of every scene point under `pose`.
struct Correspondences {
  Eigen::VectorXi model_index;
  Eigen::VectorXd squared_distance;
  double Rms() const {
    return squared_distance.size() ? std::sqrt(squared_distance.mean()) : 0.0;
  }
};

Correspondences Match(const ObjectModel& model, const PointSet& scene, const Pose& pose) {
  Correspondences pairs;
  model.NearestInPosedModel(scene, pose, &pairs.model_index, &pairs.squared_distance);
  return pairs;
}

// Scene indices of the pairs kept: within the distance gate, then the
// (1 - trim) fraction with the smallest distances.
std::vector<Eigen::Index> SelectInliers(const Correspondences& pairs, const IcpOptions& options) {
  const double gate = options.max_correspondence_distance * options.max_correspondence_distance;
  std::vector<Eigen::Index> inliers;
  inliers.reserve(pairs.squared_distance.size());
  for (Eigen::Index i = 0; i < pairs.squared_distance.size(); ++i) {
    // A query the tree could not answer (distance overflow) has no pair.
    if (pairs.model_index(i) >= 0 && pairs.squared_distance(i) <= gate) inliers.push_back(i);
  }
  if (options.trim_fraction > 0 && !inliers.empty()) {
    const auto keep = static_cast<std::size_t>(
        std::ceil((1.0 - options.trim_fraction) * static_cast<double>(inliers.size())));
    auto closer = [&](Eigen::Index a, Eigen::Index b) {
      return pairs.squared_distance(a) < pairs.squared_distance(b);
    };
    std::nth_element(inliers.begin(), inliers.begin() + static_cast<long>(keep - 1),
                     inliers.end(), closer);
    inliers.resize(keep);
  }
  return inliers;
}

// Eq. (8) on the inlier pairs (p_i in the model frame, x_i in the scene).
RegistrationResult RegisterPairs(const ObjectModel& model, const PointSet& scene,
                                 const Correspondences& pairs,
                                 const std::vector<Eigen::Index>& inliers) {
  const Eigen::Index k = static_cast<Eigen::Index>(inliers.size());
  PointSet model_points(3, k), scene_points(3, k);
  for (Eigen::Index j = 0; j < k; ++j) {
    model_points.col(j) = model.sample().col(pairs.model_index(inliers[j]));
    scene_points.col(j) = scene.col(inliers[j]);
  }
  return RegisterPoints(model_points, scene_points);
}

}  // namespace

void IcpOptions::Check() const {
  if (max_iterations < 0) throw std::invalid_argument("IcpOptions: max_iterations must be >= 0");
  if (!(max_correspondence_distance > 0)) {
    throw std::invalid_argument("IcpOptions: max_correspondence_distance must be > 0");
  }
  if (!(convergence_translation >= 0) || !std::isfinite(convergence_translation)) {
    throw std::invalid_argument("IcpOptions: convergence_translation must be finite and >= 0");
  }
  if (!(convergence_rotation >= 0) || !std::isfinite(convergence_rotation)) {
    throw std::invalid_argument("IcpOptions: convergence_rotation must be finite and >= 0");
  }
  if (!(trim_fraction >= 0 && trim_fraction <= 0.9)) {
    throw std::invalid_argument("IcpOptions: trim_fraction must be in [0, 0.9]");
  }
}

IcpResult RefineIcp(const ObjectModel& model, const PointSet& scene, const Pose& initial,
                    const IcpOptions& options) {
  options.Check();
  IcpResult result;
  result.scene_from_model = initial;
  if (!initial.IsFinite()) {
    result.failure = "non-finite initial pose";
    return result;
  }
  const PointSet points = FiniteColumns(scene);
  result.scene_points = static_cast<int>(points.cols());
  if (points.cols() < 3) {
    result.failure = "fewer than 3 finite scene points";
    if (points.cols() > 0) result.rms_before = result.rms_after = Match(model, points, initial).Rms();
    return result;
  }

  Correspondences pairs = Match(model, points, initial);
  result.rms_before = result.rms_after = pairs.Rms();
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    const std::vector<Eigen::Index> inliers = SelectInliers(pairs, options);
    if (inliers.size() < 3) {
      result.failure = "fewer than 3 correspondences within the distance gate";
      break;
    }
    const RegistrationResult step = RegisterPairs(model, points, pairs, inliers);
    if (!step.ok()) {
      result.failure = std::string("correspondences are degenerate: ") + ToString(step.status);
      break;
    }
    if (!step.scene_from_model.IsFinite()) {   // overflow on huge coordinates
      result.failure = "non-finite pose update";
      break;
    }
    const double moved = (step.scene_from_model.t - result.scene_from_model.t).norm();
    const double turned = RotationAngleBetween(result.scene_from_model.R, step.scene_from_model.R);
    result.scene_from_model = step.scene_from_model;
    result.inliers = static_cast<int>(inliers.size());
    result.iterations = iteration + 1;
    pairs = Match(model, points, result.scene_from_model);   // residual at the new pose
    result.rms_after = pairs.Rms();
    if (moved <= options.convergence_translation && turned <= options.convergence_rotation) {
      result.converged = true;
      break;
    }
  }
  return result;
}

}  // namespace c3po
