#pragma once
// From a point cloud to the network's input and back (see pointnet.hpp):
//   input_j = (x_j - centroid) / scale for n points of X (subsampled without
//   replacement, or repeated cyclically when X has fewer than n points);
//   keypoints = centroid + scale * output.
#include <cstdint>
#include <vector>

#include "c3po/base/random.hpp"
#include "c3po/base/types.hpp"
#include "c3po/method/detector.hpp"
#include "tiny_dnn_parts.hpp"

namespace c3po::pointnet {

struct PreparedCloud {
  tiny_dnn::vec_t points;                     // 3 x n floats, column-major
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
};

// The finite columns of `cloud`. Throws InputError when there are none.
PointSet FinitePoints(const PointSet& cloud);

// `rng` chooses the subsample; nullptr means the deterministic choice of
// Detect (an Rng seeded by the number of finite points).
PreparedCloud PrepareCloud(const PointSet& cloud, int num_points, double scale, Rng* rng = nullptr);

// (keypoints - centroid) / scale as 3N floats, keypoint after keypoint.
tiny_dnn::vec_t NormaliseKeypoints(const PointSet& keypoints, const Eigen::Vector3d& centroid,
                                   double scale);
PointSet DenormaliseKeypoints(const tiny_dnn::vec_t& output, const Eigen::Vector3d& centroid,
                              double scale);

struct Augmentation {
  double rotate_about_camera_deg = 0.0;
  double point_dropout = 0.0;
  double noise_sigma = 0.0;
  bool active() const {
    return rotate_about_camera_deg > 0.0 || point_dropout > 0.0 || noise_sigma > 0.0;
  }
};

// A randomly perturbed copy of a training pair: rotation about the sensor's z
// axis (cloud and keypoints, symmetric labellings included, together), dropout of a random fraction in
// [0, point_dropout] of the points (at least one point stays), Gaussian noise
// on the cloud.
TrainingSample Augment(const TrainingSample& sample, const Augmentation& augmentation, Rng* rng);

}  // namespace c3po::pointnet
