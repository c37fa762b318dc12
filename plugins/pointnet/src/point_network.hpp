#pragma once
// The PointNet keypoint regressor as a tiny-dnn network:
//   per-point MLP 3 -> m1 -> ... -> mk (ReLU) and max over points
//   (PointEncoderLayer, a custom tiny-dnn layer, point_layers.hpp)
//   -> fully connected head mk -> h1 -> ... (ReLU) -> 3N outputs (identity):
//   tiny-dnn fully_connected_layers with a batched forward pass (HeadLayer).
// tiny-dnn carries the graph (edges, per-sample tensors), the fully connected
// layers and the weight update (layer::update_weight with a tiny_dnn::optimizer);
// this class drives forward / backward / update over a batch.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tiny_dnn_parts.hpp"

namespace c3po::pointnet {

struct NetworkShape {
  int num_points = 512;
  std::vector<int> point_mlp = {64, 128, 256};   // widths after the 3 input channels
  std::vector<int> head = {256, 128};            // hidden widths of the head
  int outputs = 3;                               // 3N
};

struct WeightBlock {
  std::string name;       // e.g. "point_mlp.1.weight", "head.0.bias"
  std::size_t offset = 0; // into the flat weight vector
  std::size_t size = 0;
};

class PointNetwork {
 public:
  // Weights drawn from `seed` (He-uniform for ReLU layers, Glorot for the
  // output layer, zero biases).
  PointNetwork(const NetworkShape& shape, std::uint64_t seed, int threads = 0);

  const NetworkShape& shape() const { return shape_; }
  // inputs: one vec_t of 3 x n floats (column-major points) per sample.
  // Returns one vec_t of `outputs` floats per sample.
  tiny_dnn::tensor_t Forward(const tiny_dnn::tensor_t& inputs);
  // Loss L = mean over the batch of (1/N) sum_i |out_i - target_i|^2 (N = outputs/3)
  // and back-propagation of dL/d(weights) into tiny-dnn's gradient tensors.
  double ForwardBackward(const tiny_dnn::tensor_t& inputs, const tiny_dnn::tensor_t& targets);
  // One optimiser step on the gradients of the last ForwardBackward.
  void Update(tiny_dnn::optimizer* optimizer, int batch_size);
  // Mean gradient over the batch of the last ForwardBackward (flat, same order
  // as Weights()); clears the gradients.
  std::vector<double> TakeGradient(int batch_size);

  std::vector<float> Weights() const;
  // Throws std::invalid_argument if the size differs from Weights().size().
  void SetWeights(const std::vector<float>& weights);
  std::vector<WeightBlock> Blocks() const;
  // The trainable vectors in a fixed order (optimiser state is stored in it).
  std::vector<tiny_dnn::vec_t*> WeightVectors();

 private:
  void Build();
  void Initialise(std::uint64_t seed);

  NetworkShape shape_;
  int threads_;
  tiny_dnn::network<tiny_dnn::sequential> net_;
  std::vector<std::string> layer_names_;
};

}  // namespace c3po::pointnet
