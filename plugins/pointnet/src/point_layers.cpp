#include "point_layers.hpp"

#include <algorithm>
#include <stdexcept>

#include "c3po/base/parallel.hpp"

namespace c3po::pointnet {
namespace {

using MatrixF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic>;
using VectorF = Eigen::Matrix<float, Eigen::Dynamic, 1>;
using MapF = Eigen::Map<MatrixF>;
using ConstMapF = Eigen::Map<const MatrixF>;

tiny_dnn::shape3d Shape(int width, int height = 1) {
  return tiny_dnn::shape3d(static_cast<tiny_dnn::serial_size_t>(width),
                           static_cast<tiny_dnn::serial_size_t>(height), 1);
}

std::vector<tiny_dnn::vector_type> InputTypes(std::size_t num_layers) {
  std::vector<tiny_dnn::vector_type> types = {tiny_dnn::vector_type::data};
  for (std::size_t l = 0; l < num_layers; ++l) {
    types.push_back(tiny_dnn::vector_type::weight);
    types.push_back(tiny_dnn::vector_type::bias);
  }
  return types;
}

// Runs body(sample, &scratch) for every sample, the samples split into one
// contiguous block per thread, each block with its own Scratch (buffers reused
// from sample to sample).
template <typename Scratch, typename Body>
void ForEachSampleBlock(int samples, int threads, const Body& body) {
  const int blocks = std::max(1, std::min(samples, threads > 0 ? threads : DefaultThreadCount()));
  ParallelFor(0, blocks, [&](int block) {
    Scratch scratch;
    const int begin = samples * block / blocks, end = samples * (block + 1) / blocks;
    for (int s = begin; s < end; ++s) body(s, &scratch);
  }, blocks);
}

// Column-wise maximum of z (channels x points) and, per channel, the first
// point attaining it. Branch-free so the channel loop vectorises.
void MaxOverColumns(const MatrixF& z, float* maxima, int* argmax) {
  const Eigen::Index channels = z.rows();
  for (Eigen::Index c = 0; c < channels; ++c) {
    maxima[c] = z(c, 0);
    argmax[c] = 0;
  }
  for (Eigen::Index j = 1; j < z.cols(); ++j) {
    const float* column = z.col(j).data();
    const int index = static_cast<int>(j);
    for (Eigen::Index c = 0; c < channels; ++c) {
      const bool greater = column[c] > maxima[c];
      maxima[c] = greater ? column[c] : maxima[c];
      argmax[c] = greater ? index : argmax[c];
    }
  }
}

}  // namespace

PointEncoderLayer::PointEncoderLayer(std::vector<int> widths, int num_points)
    : tiny_dnn::layer(InputTypes(widths.size() - 1), {tiny_dnn::vector_type::data}),
      widths_(std::move(widths)),
      num_points_(num_points) {
  if (widths_.size() < 2 || widths_[0] != 3 || num_points_ < 1) {
    throw std::invalid_argument("PointEncoderLayer: widths must be {3, m1, ...} and n >= 1");
  }
}

std::vector<tiny_dnn::shape3d> PointEncoderLayer::in_shape() const {
  std::vector<tiny_dnn::shape3d> shapes = {Shape(3, num_points_)};
  for (int l = 0; l < num_layers(); ++l) {
    shapes.push_back(Shape(widths_[l], widths_[l + 1]));
    shapes.push_back(Shape(widths_[l + 1]));
  }
  return shapes;
}

std::vector<tiny_dnn::shape3d> PointEncoderLayer::out_shape() const {
  return {Shape(widths_.back())};
}

tiny_dnn::serial_size_t PointEncoderLayer::fan_in_size() const {
  return static_cast<tiny_dnn::serial_size_t>(widths_[0]);
}

tiny_dnn::serial_size_t PointEncoderLayer::fan_out_size() const {
  return static_cast<tiny_dnn::serial_size_t>(widths_[1]);
}

void PointEncoderLayer::forward_propagation(const std::vector<tiny_dnn::tensor_t*>& in_data,
                                            std::vector<tiny_dnn::tensor_t*>& out_data) {
  const int samples = static_cast<int>(in_data[0]->size());
  cache_.resize(static_cast<std::size_t>(samples));
  tiny_dnn::tensor_t& output = *out_data[0];
  ForEachSampleBlock<std::vector<MatrixF>>(samples, threads_, [&](int s, std::vector<MatrixF>* scratch) {
    ForwardSample(in_data, s, scratch, output[static_cast<std::size_t>(s)].data());
  });
}

// A_{l+1} = relu(W_l A_l + b_l), then g = relu(max over points of W_L A_L + b_L).
void PointEncoderLayer::ForwardSample(const std::vector<tiny_dnn::tensor_t*>& in_data, int s,
                                      std::vector<MatrixF>* activations, float* output) {
  const int layers = num_layers();
  activations->resize(static_cast<std::size_t>(layers + 1));
  std::vector<MatrixF>& a = *activations;
  const ConstMapF points((*in_data[0])[static_cast<std::size_t>(s)].data(), 3, num_points_);
  for (int l = 0; l < layers; ++l) {
    const ConstMapF weight((*in_data[1 + 2 * l])[0].data(), widths_[l + 1], widths_[l]);
    const Eigen::Map<const VectorF> bias((*in_data[2 + 2 * l])[0].data(), widths_[l + 1]);
    MatrixF& next = a[static_cast<std::size_t>(l + 1)];
    next.resize(widths_[l + 1], num_points_);
    if (l == 0) {
      next.noalias() = weight.lazyProduct(points);   // inner dimension 3: no GEMM blocking
    } else {
      next.noalias() = weight * a[static_cast<std::size_t>(l)];
    }
    if (l + 1 < layers) {
      next = (next.colwise() + bias).cwiseMax(0.0f);
    } else {
      next.colwise() += bias;
    }
  }
  // Max pool; relu(max) = max(relu), so the ReLU is applied to the maxima only.
  const int channels = widths_.back();
  SampleCache& cache = cache_[static_cast<std::size_t>(s)];
  cache.maxima.resize(channels);
  std::vector<int> argmax(static_cast<std::size_t>(channels));
  MaxOverColumns(a[static_cast<std::size_t>(layers)], cache.maxima.data(), argmax.data());
  for (int c = 0; c < channels; ++c) output[c] = std::max(cache.maxima[c], 0.0f);
  // Keep the inputs of every stage at the winning points only (in point order).
  std::vector<int> slot_of_point(static_cast<std::size_t>(num_points_), -1);
  for (int c = 0; c < channels; ++c) slot_of_point[static_cast<std::size_t>(argmax[static_cast<std::size_t>(c)])] = 0;
  std::vector<int> winners;
  for (int j = 0; j < num_points_; ++j) {
    if (slot_of_point[static_cast<std::size_t>(j)] < 0) continue;
    slot_of_point[static_cast<std::size_t>(j)] = static_cast<int>(winners.size());
    winners.push_back(j);
  }
  cache.winner_slot.resize(static_cast<std::size_t>(channels));
  for (int c = 0; c < channels; ++c) {
    cache.winner_slot[static_cast<std::size_t>(c)] =
        slot_of_point[static_cast<std::size_t>(argmax[static_cast<std::size_t>(c)])];
  }
  const Eigen::Index k = static_cast<Eigen::Index>(winners.size());
  cache.inputs.resize(static_cast<std::size_t>(layers));
  for (int l = 0; l < layers; ++l) {
    MatrixF& kept = cache.inputs[static_cast<std::size_t>(l)];
    kept.resize(widths_[l], k);
    for (Eigen::Index w = 0; w < k; ++w) {
      const int j = winners[static_cast<std::size_t>(w)];
      if (l == 0) {
        kept.col(w) = points.col(j);
      } else {
        kept.col(w) = a[static_cast<std::size_t>(l)].col(j);
      }
    }
  }
}

void PointEncoderLayer::back_propagation(const std::vector<tiny_dnn::tensor_t*>& in_data,
                                         const std::vector<tiny_dnn::tensor_t*>& out_data,
                                         std::vector<tiny_dnn::tensor_t*>& out_grad,
                                         std::vector<tiny_dnn::tensor_t*>& in_grad) {
  const int samples = static_cast<int>(out_grad[0]->size());
  if (static_cast<int>(cache_.size()) < samples) {
    throw std::logic_error("PointEncoderLayer: backward without forward");
  }
  ForEachSampleBlock<int>(samples, threads_, [&](int s, int*) {
    BackwardSample(in_data, (*out_grad[0])[static_cast<std::size_t>(s)].data(), in_grad, s);
  });
}

// With G_l = dL/d(pre-activation of stage l) restricted to the winning points:
//   last stage: dL/dz_c = dL/dg_c [m_c > 0] at the arg-max point only, so
//     dW_L(c,:) += g_c A_L(:, j_c)^T,  db_L(c) += g_c,  dA_L(:, j_c) += W_L(c,:)^T g_c;
//   earlier:    G_l = dA_{l+1} ⊙ [A_{l+1} > 0],  dW_l += G_l A_l^T,  db_l += G_l 1,
//               dA_l = W_l^T G_l.
void PointEncoderLayer::BackwardSample(const std::vector<tiny_dnn::tensor_t*>& in_data,
                                       const float* output_grad,
                                       std::vector<tiny_dnn::tensor_t*>& in_grad, int s) const {
  const std::size_t sample = static_cast<std::size_t>(s);
  const SampleCache& cache = cache_[sample];
  const int layers = num_layers();
  const int last = layers - 1;
  const Eigen::Index k = cache.inputs[0].cols();
  const ConstMapF last_weight((*in_data[1 + 2 * last])[0].data(), widths_[last + 1], widths_[last]);
  MapF last_weight_grad((*in_grad[1 + 2 * last])[sample].data(), widths_[last + 1], widths_[last]);
  float* last_bias_grad = (*in_grad[2 + 2 * last])[sample].data();
  const MatrixF& last_input = cache.inputs[static_cast<std::size_t>(last)];
  MatrixF input_grad = MatrixF::Zero(widths_[last], k);
  for (int c = 0; c < widths_.back(); ++c) {
    const float g = cache.maxima[c] > 0.0f ? output_grad[c] : 0.0f;
    if (g == 0.0f) continue;
    const int slot = cache.winner_slot[static_cast<std::size_t>(c)];
    last_weight_grad.row(c) += g * last_input.col(slot).transpose();
    last_bias_grad[c] += g;
    input_grad.col(slot) += g * last_weight.row(c).transpose();
  }
  for (int l = last - 1; l >= 0; --l) {
    const MatrixF& output_of_stage = cache.inputs[static_cast<std::size_t>(l + 1)];
    const MatrixF stage_grad = (output_of_stage.array() > 0.0f).select(input_grad, 0.0f);
    MapF weight_grad((*in_grad[1 + 2 * l])[sample].data(), widths_[l + 1], widths_[l]);
    weight_grad.noalias() += stage_grad * cache.inputs[static_cast<std::size_t>(l)].transpose();
    Eigen::Map<VectorF> bias_grad((*in_grad[2 + 2 * l])[sample].data(), widths_[l + 1]);
    bias_grad += stage_grad.rowwise().sum();
    if (l > 0) {
      const ConstMapF weight((*in_data[1 + 2 * l])[0].data(), widths_[l + 1], widths_[l]);
      input_grad.noalias() = weight.transpose() * stage_grad;
    }
  }
}

}  // namespace c3po::pointnet
