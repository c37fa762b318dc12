#pragma once
// Keypoint detectors (paper Section VI-A): a cloud X (3 x n) in, keypoints
// (3 x N) in the same frame out.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "c3po/base/types.hpp"

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
// symmetric_keypoints: other labellings equally right for the cloud (the
// keypoints turned by a symmetry of the object, model_symmetries.hpp);
// supervised training then regresses onto the labelling nearest the output
// (the loss min over all labellings), not onto `keypoints` alone.
struct TrainingSample {
  PointSet cloud;
  PointSet keypoints;
  std::vector<PointSet> symmetric_keypoints;
};

// A detector that can be trained by regression onto target keypoints (used by
// supervised training and by self-training on pseudo-labels).
class TrainableDetector : public Detector {
 public:
  // One optimiser step on a batch; returns the batch's mean squared keypoint
  // error before the step. clouds.size() == targets.size() > 0.
  virtual double TrainStep(const std::vector<PointSet>& clouds,
                           const std::vector<PointSet>& targets) = 0;
  // Parameters only (for keeping the best epoch in memory).
  virtual std::vector<float> GetWeights() const = 0;
  virtual void SetWeights(const std::vector<float>& weights) = 0;
  // Model file (self-describing, atomic). `header_extra` is merged into the
  // file's JSON header (e.g. {"selftrained": true}).
  virtual void Save(const std::string& path, const std::string& header_extra_json = "") const = 0;
  // Checkpoint = model + optimiser state + `state_json` (epoch, counters).
  virtual void SaveCheckpoint(const std::string& path, const std::string& state_json) const = 0;
  // Restores model + optimiser state; returns the state_json saved with it.
  virtual std::string LoadCheckpoint(const std::string& path) = 0;
};

using ProgressCallback = std::function<void(std::size_t done, std::size_t total)>;

}  // namespace c3po
