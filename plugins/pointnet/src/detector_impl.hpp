#pragma once
// PointNetDetector's private state, shared by the detector, training and
// model-file sources of the plugin.
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "c3po/plugins/pointnet.hpp"
#include "optimizers.hpp"
#include "point_network.hpp"

namespace c3po {

// Fit's progress: what a checkpoint must hold besides weights and optimiser.
struct PointNetProgress {
  int epochs_done = 0;
  std::vector<EpochLog> history;
  int best_epoch = 0;
  double best_val_loss = std::numeric_limits<double>::infinity();
  std::vector<float> best_weights;
};

struct PointNetDetector::Impl {
  struct InferenceCopy {
    std::unique_ptr<pointnet::PointNetwork> network;
    std::uint64_t version = 0;
  };
  PointNetIdentity identity;
  PointNetArchitecture architecture;
  int threads = 0;
  std::unique_ptr<pointnet::PointNetwork> network;        // the trained one
  std::unique_ptr<pointnet::StatefulOptimizer> optimizer; // built by Fit / TrainStep
  double optimizer_lr = 0.0;
  double optimizer_momentum = 0.0;
  PointNetProgress progress;
  std::string training_info = "{}";
  PointNetTrainOptions step_options;                      // for TrainStep(clouds, targets)
  std::string checkpoint_state;                           // state_json of the loaded checkpoint

  // Inference copies of `network` (Detect may run on several threads).
  mutable std::mutex pool_mutex;
  mutable std::vector<InferenceCopy> pool;
  std::uint64_t weights_version = 0;      // copies made from older weights are dropped

  Impl(const PointNetIdentity& id, const PointNetArchitecture& arch, std::uint64_t seed);
  pointnet::NetworkShape Shape() const;
  // Call after any change of `network`'s weights.
  void WeightsChanged();
  InferenceCopy AcquireInferenceNetwork() const;
  void ReleaseInferenceNetwork(InferenceCopy copy) const;
  // Forward pass of prepared clouds (any count; chunks of 64).
  std::vector<PointSet> DetectAll(const std::vector<PointSet>& clouds) const;
  // Builds the optimiser if there is none or its settings differ.
  void EnsureOptimizer(const PointNetTrainOptions& options);
};

}  // namespace c3po
