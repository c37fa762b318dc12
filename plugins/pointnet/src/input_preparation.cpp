#include "input_preparation.hpp"

#include <cmath>
#include <numeric>

#include "c3po/base/error.hpp"

namespace c3po::pointnet {

PointSet FinitePoints(const PointSet& cloud) {
  PointSet kept = FiniteColumns(cloud);
  if (kept.cols() == 0) throw InputError("point cloud has no finite point (pointnet needs at least one)");
  return kept;
}

PreparedCloud PrepareCloud(const PointSet& input, int num_points, double scale, Rng* rng) {
  const PointSet cloud = FinitePoints(input);
  const int m = static_cast<int>(cloud.cols());
  PreparedCloud prepared;
  prepared.centroid = cloud.rowwise().mean();
  std::vector<int> chosen(static_cast<std::size_t>(num_points));
  if (m <= num_points) {
    for (int i = 0; i < num_points; ++i) chosen[static_cast<std::size_t>(i)] = i % m;
  } else {
    // Partial Fisher-Yates: the first n entries of a random permutation.
    Rng deterministic(static_cast<std::uint64_t>(m));
    Rng& random = rng ? *rng : deterministic;
    std::vector<int> order(static_cast<std::size_t>(m));
    std::iota(order.begin(), order.end(), 0);
    for (int i = 0; i < num_points; ++i) {
      const int j = i + random.UniformInt(m - i);
      std::swap(order[static_cast<std::size_t>(i)], order[static_cast<std::size_t>(j)]);
    }
    std::copy(order.begin(), order.begin() + num_points, chosen.begin());
  }
  prepared.points.resize(static_cast<std::size_t>(3 * num_points));
  const double inverse_scale = 1.0 / scale;
  for (int i = 0; i < num_points; ++i) {
    const Eigen::Vector3d p = (cloud.col(chosen[static_cast<std::size_t>(i)]) - prepared.centroid) * inverse_scale;
    for (int r = 0; r < 3; ++r) prepared.points[static_cast<std::size_t>(3 * i + r)] = static_cast<float>(p(r));
  }
  return prepared;
}

tiny_dnn::vec_t NormaliseKeypoints(const PointSet& keypoints, const Eigen::Vector3d& centroid,
                                   double scale) {
  tiny_dnn::vec_t target(static_cast<std::size_t>(keypoints.size()));
  for (Eigen::Index i = 0; i < keypoints.cols(); ++i) {
    const Eigen::Vector3d k = (keypoints.col(i) - centroid) / scale;
    for (int r = 0; r < 3; ++r) target[static_cast<std::size_t>(3 * i + r)] = static_cast<float>(k(r));
  }
  return target;
}

PointSet DenormaliseKeypoints(const tiny_dnn::vec_t& output, const Eigen::Vector3d& centroid,
                              double scale) {
  const Eigen::Index n = static_cast<Eigen::Index>(output.size() / 3);
  PointSet keypoints(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int r = 0; r < 3; ++r) {
      keypoints(r, i) = centroid(r) + scale * static_cast<double>(output[static_cast<std::size_t>(3 * i + r)]);
    }
  }
  return keypoints;
}

TrainingSample Augment(const TrainingSample& sample, const Augmentation& augmentation, Rng* rng) {
  TrainingSample out = sample;
  if (augmentation.rotate_about_camera_deg > 0.0) {
    const double limit = augmentation.rotate_about_camera_deg * M_PI / 180.0;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(rng->Uniform(-limit, limit), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    out.cloud = R * out.cloud;
    out.keypoints = R * out.keypoints;
    for (PointSet& labelling : out.symmetric_keypoints) labelling = R * labelling;
  }
  if (augmentation.point_dropout > 0.0 && out.cloud.cols() > 1) {
    const double drop = rng->Uniform(0.0, augmentation.point_dropout);
    std::vector<Eigen::Index> kept;
    for (Eigen::Index j = 0; j < out.cloud.cols(); ++j) {
      if (rng->Uniform() >= drop) kept.push_back(j);
    }
    if (kept.empty()) kept.push_back(rng->UniformInt(static_cast<int>(out.cloud.cols())));
    PointSet cloud(3, static_cast<Eigen::Index>(kept.size()));
    for (std::size_t k = 0; k < kept.size(); ++k) cloud.col(static_cast<Eigen::Index>(k)) = out.cloud.col(kept[k]);
    out.cloud = std::move(cloud);
  }
  if (augmentation.noise_sigma > 0.0) {
    for (Eigen::Index i = 0; i < out.cloud.size(); ++i) {
      out.cloud.data()[i] += augmentation.noise_sigma * rng->Normal();
    }
  }
  return out;
}

}  // namespace c3po::pointnet
