#pragma once
// Optimisers as tiny_dnn::optimizer subclasses (tiny-dnn's layer::update_weight
// calls update(dW, W) for every trainable vector with the batch-mean gradient).
//
// Why not tiny_dnn::adam / tiny_dnn::momentum directly: tiny-dnn 1.0.0a3's adam
// advances its bias-correction powers (b1_t *= b1) on every update() call, i.e.
// once per weight vector rather than once per step, and both keep their state in
// a map keyed by address that cannot be saved. These keep the same update rules
// with a per-step counter and a state that a checkpoint can store and restore.
#include <cstdint>
#include <istream>
#include <memory>
#include <ostream>
#include <string>
#include <unordered_map>
#include <vector>

#include "tiny_dnn_parts.hpp"

namespace c3po::pointnet {

// update() may run concurrently for different weight vectors (the state map is
// only read after construction).
class StatefulOptimizer : public tiny_dnn::optimizer {
 public:
  // `order` fixes the order in which per-vector state is saved.
  StatefulOptimizer(std::vector<tiny_dnn::vec_t*> order, int slots_per_vector);
  // Call once per optimisation step, before the updates of that step.
  void BeginStep() { ++step_; }
  std::int64_t step() const { return step_; }
  virtual std::string kind() const = 0;

  // Binary state: step and every slot of every vector (float32).
  void SaveState(std::ostream& out) const;
  // Returns false when the stream does not hold a state of this shape.
  bool LoadState(std::istream& in);

 protected:
  std::vector<float>& Slot(const tiny_dnn::vec_t& weights, int slot);
  std::int64_t step_ = 0;

 private:
  std::vector<tiny_dnn::vec_t*> order_;
  int slots_per_vector_;
  std::unordered_map<const tiny_dnn::vec_t*, std::size_t> index_;
  std::vector<std::vector<float>> state_;   // [vector * slots + slot]
};

// Adam (Kingma & Ba 2015) with bias correction by the step count.
class AdamOptimizer : public StatefulOptimizer {
 public:
  AdamOptimizer(std::vector<tiny_dnn::vec_t*> order, double learning_rate);
  void update(const tiny_dnn::vec_t& dW, tiny_dnn::vec_t& W, bool parallelize) override;
  std::string kind() const override { return "adam"; }
  double learning_rate = 1e-3;
  double beta1 = 0.9;
  double beta2 = 0.999;
  double epsilon = 1e-8;
};

// SGD with (heavy-ball) momentum: v <- mu v + g, W <- W - lr v (PyTorch's rule).
class MomentumSgdOptimizer : public StatefulOptimizer {
 public:
  MomentumSgdOptimizer(std::vector<tiny_dnn::vec_t*> order, double learning_rate, double momentum);
  void update(const tiny_dnn::vec_t& dW, tiny_dnn::vec_t& W, bool parallelize) override;
  std::string kind() const override { return "sgd"; }
  double learning_rate = 1e-2;
  double momentum = 0.9;
};

std::unique_ptr<StatefulOptimizer> MakeOptimizer(const std::string& kind,
                                                 std::vector<tiny_dnn::vec_t*> order,
                                                 double learning_rate, double momentum);

}  // namespace c3po::pointnet
