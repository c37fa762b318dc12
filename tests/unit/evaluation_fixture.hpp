#pragma once
// A tiny dataset with known poses for the evaluation and report tests.
//
// Object: the asymmetric test object with one indicator set {1, 2} (two
// corners at x = +0.10). Cloud i is the model sample posed by a random T_i;
// clouds with i % 3 == 2 keep only the points with model x < -0.02, so the
// set's keypoints are far from the cloud (nd = 0 at the right pose).
// detected_keypoints: the GT posed keypoints (i % 2 == 0), the keypoints
// posed by T_i * W with W a 90-degree turn (i % 4 == 1), or all equal (i % 4
// == 3: registration is degenerate, a failure).
#include <string>
#include <vector>

#include "c3po/base/random.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/object/object_model.hpp"
#include "test_objects.hpp"

namespace c3po::test {

inline ObjectModel EvaluationObject() {
  ObjectModel object = AsymmetricObject(1200);
  object.mutable_spec().indicator_sets = {{1, 2}};
  return object;
}

enum class DetectedKind { kTruth, kWrongPose, kDegenerate };

inline DetectedKind KindOf(int i) {
  if (i % 2 == 0) return DetectedKind::kTruth;
  return i % 4 == 1 ? DetectedKind::kWrongPose : DetectedKind::kDegenerate;
}
inline bool IsPartial(int i) { return i % 3 == 2; }

inline Pose WrongTurn() {
  Pose w;
  w.R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return w;
}

inline std::vector<Pose> EvaluationPoses(int count) {
  std::vector<Pose> poses;
  Rng rng(2024);
  for (int i = 0; i < count; ++i) {
    Pose pose;
    pose.R = rng.Rotation();
    pose.t = Eigen::Vector3d(rng.Uniform(), rng.Uniform(), rng.Uniform());
    poses.push_back(pose);
  }
  return poses;
}

inline PointSet EvaluationCloud(const ObjectModel& object, const Pose& pose, int i) {
  const PointSet& sample = object.sample();
  std::vector<Eigen::Index> kept;
  for (Eigen::Index k = 0; k < sample.cols(); ++k) {
    if (!IsPartial(i) || sample(0, k) < -0.02) kept.push_back(k);
  }
  PointSet cloud(3, static_cast<Eigen::Index>(kept.size()));
  for (std::size_t k = 0; k < kept.size(); ++k) cloud.col(static_cast<Eigen::Index>(k)) = pose * Eigen::Vector3d(sample.col(kept[k]));
  return cloud;
}

inline PointSet DetectedKeypoints(const ObjectModel& object, const Pose& pose, int i) {
  switch (KindOf(i)) {
    case DetectedKind::kTruth: return pose * object.keypoints();
    case DetectedKind::kWrongPose: return (pose * WrongTurn()) * object.keypoints();
    case DetectedKind::kDegenerate: break;
  }
  PointSet same(3, object.num_keypoints());
  same.colwise() = pose.t;
  return same;
}

inline void WriteEvaluationDataset(const ObjectModel& object, const std::string& dir, int count) {
  const std::vector<Pose> poses = EvaluationPoses(count);
  DatasetWriter writer(dir);
  for (int i = 0; i < count; ++i) {
    DatasetEntry entry;
    char name[32];
    std::snprintf(name, sizeof name, "%06d.ply", i);
    entry.cloud = name;
    entry.pose = poses[i];
    entry.keypoints = poses[i] * object.keypoints();
    entry.detected_keypoints = DetectedKeypoints(object, poses[i], i);
    writer.Add(i, entry, EvaluationCloud(object, poses[i], i));
  }
  writer.Commit();
}

}  // namespace c3po::test
