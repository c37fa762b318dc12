#pragma once
// Keypoint detectors (paper Section VI-A): a cloud X (3 x n) in, keypoints
// (3 x N) in the same frame out.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "c3po/types.hpp"

namespace c3po {

class Detector {
 public:
  virtual ~Detector() = default;
  virtual std::string name() const = 0;
  virtual int num_keypoints() const = 0;
  // Must be safe to call concurrently from several threads.
  virtual PointSet Detect(const PointSet& cloud) const = 0;
  // Default: Detect on each cloud, in parallel on both cores.
  virtual std::vector<PointSet> DetectBatch(const std::vector<PointSet>& clouds) const;
};

// A (cloud, keypoints) training pair; keypoints are posed, 3 x N.
struct TrainingSample {
  PointSet cloud;
  PointSet keypoints;
};

using ProgressCallback = std::function<void(std::size_t done, std::size_t total)>;

}  // namespace c3po
