#pragma once
// PointNet's point encoder (Qi et al. 2017, Fig. 2 without the T-nets) as one
// custom tiny-dnn layer backed by Eigen matrix products:
//
//   A_0 = X (3 x n, the points of one sample, one column per point)
//   A_{l+1} = relu(W_l A_l + b_l 1^T)        shared per-point MLP (1x1 convolutions)
//   g_c = max_j relu(W_L A_L + b_L 1^T)_cj   global max pool over the points
//
// tiny-dnn hands a layer the whole batch (tensor_t = one vec_t per sample); the
// layer runs each sample's MLP as C_out x C_in by C_in x n products, the samples
// split over both cores. It keeps, per sample, only the columns (points) that
// won the max of at least one channel: the gradient of g flows back only through
// them, so the backward pass costs O(k) columns (k = distinct arg-max points)
// instead of n, and the last layer's gradient is a sum of rank-one rows.
//
// Why one layer and not one per MLP stage: tiny-dnn clears every edge's
// per-sample gradient tensor on each forward pass and each update; with C x n
// features per sample those memsets alone took ~20 % of a training step. Inside
// one layer the features never become tiny-dnn edges.
//
// Weight gradients are written per sample (tiny-dnn's contract: a weight's
// gradient tensor has one vec_t per sample, summed in sample order by
// edge::merge_grads), so the result does not depend on the thread count.
//
// Data layout: the input vec_t of a sample is 3 x n floats, column-major (the
// layout of an Eigen 3 x n point set). Weight l is C_{l+1} x C_l, column-major.
#include <vector>

#include <Eigen/Core>

#include "tiny_dnn_parts.hpp"

namespace c3po::pointnet {

class PointEncoderLayer : public tiny_dnn::layer {
 public:
  // widths = {3, m_1, ..., m_L}: the point MLP's channel counts.
  PointEncoderLayer(std::vector<int> widths, int num_points);

  std::vector<tiny_dnn::shape3d> in_shape() const override;
  std::vector<tiny_dnn::shape3d> out_shape() const override;
  std::string layer_type() const override { return "c3po-point-encoder"; }
  tiny_dnn::serial_size_t fan_in_size() const override;
  tiny_dnn::serial_size_t fan_out_size() const override;

  void forward_propagation(const std::vector<tiny_dnn::tensor_t*>& in_data,
                           std::vector<tiny_dnn::tensor_t*>& out_data) override;
  void back_propagation(const std::vector<tiny_dnn::tensor_t*>& in_data,
                        const std::vector<tiny_dnn::tensor_t*>& out_data,
                        std::vector<tiny_dnn::tensor_t*>& out_grad,
                        std::vector<tiny_dnn::tensor_t*>& in_grad) override;

  // Threads used over the samples of a batch (0 = c3po::DefaultThreadCount()).
  void set_threads(int threads) { threads_ = threads; }
  int num_layers() const { return static_cast<int>(widths_.size()) - 1; }

 private:
  using MatrixF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic>;
  using VectorF = Eigen::Matrix<float, Eigen::Dynamic, 1>;

  // What the backward pass needs of one sample.
  struct SampleCache {
    std::vector<int> winner_slot;         // per output channel: column in `inputs`
    std::vector<MatrixF> inputs;          // A_l restricted to the winning points, l = 0..L-1
    VectorF maxima;                       // max_j (W_L A_L + b_L)_cj (before the ReLU)
  };

  void ForwardSample(const std::vector<tiny_dnn::tensor_t*>& in_data, int sample,
                     std::vector<MatrixF>* activations, float* output);
  void BackwardSample(const std::vector<tiny_dnn::tensor_t*>& in_data, const float* output_grad,
                      std::vector<tiny_dnn::tensor_t*>& in_grad, int sample) const;

  std::vector<int> widths_;
  int num_points_;
  int threads_ = 0;
  std::vector<SampleCache> cache_;
};

}  // namespace c3po::pointnet
