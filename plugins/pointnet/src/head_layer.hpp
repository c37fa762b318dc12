#pragma once
// The fully connected head layers: tiny-dnn's fully_connected_layer (weights,
// initialisation, activation, backward pass and weight update unchanged) with
// the forward pass done by Eigen.
//
// tiny-dnn 1.0.0a3's forward kernel is a scalar loop that walks the weight
// matrix with a stride of out_size (out[i] += W[c * out + i] * in[c], i outer);
// it took ~16 % of a training step's CPU time. Here a = W x + b with W the
// out x in column-major matrix tiny-dnn stores (entry (i, c) at c * out + i).
#include <Eigen/Core>

#include "tiny_dnn_parts.hpp"

namespace c3po::pointnet {

template <typename Activation>
class HeadLayer : public tiny_dnn::fully_connected_layer<Activation> {
 public:
  using Base = tiny_dnn::fully_connected_layer<Activation>;
  HeadLayer(int in_size, int out_size)
      : Base(static_cast<tiny_dnn::serial_size_t>(in_size),
             static_cast<tiny_dnn::serial_size_t>(out_size), /*has_bias=*/true),
        in_size_(in_size),
        out_size_(out_size) {}

  void forward_propagation(const std::vector<tiny_dnn::tensor_t*>& in_data,
                           std::vector<tiny_dnn::tensor_t*>& out_data) override {
    using MatrixF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic>;
    const tiny_dnn::tensor_t& input = *in_data[0];
    const Eigen::Index samples = static_cast<Eigen::Index>(input.size());
    const Eigen::Map<const MatrixF> weight((*in_data[1])[0].data(), out_size_, in_size_);
    const Eigen::Map<const Eigen::VectorXf> bias((*in_data[2])[0].data(), out_size_);
    tiny_dnn::tensor_t& pre_activation = *out_data[1];
    // One matrix-vector product per sample (not one matrix product for the
    // batch): a sample's result must not depend on the batch it is in.
    for (Eigen::Index s = 0; s < samples; ++s) {
      const std::size_t i = static_cast<std::size_t>(s);
      Eigen::Map<Eigen::VectorXf> a(pre_activation[i].data(), out_size_);
      a.noalias() = weight * Eigen::Map<const Eigen::VectorXf>(input[i].data(), in_size_);
      a += bias;
    }
    this->forward_activation(*out_data[0], *out_data[1]);
  }

 private:
  int in_size_;
  int out_size_;
};

}  // namespace c3po::pointnet
