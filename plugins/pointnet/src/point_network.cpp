#include "point_network.hpp"

#include <cmath>
#include <stdexcept>

#include "c3po/base/parallel.hpp"
#include "c3po/base/random.hpp"
#include "head_layer.hpp"
#include "point_layers.hpp"

namespace c3po::pointnet {
namespace {

namespace activation = tiny_dnn::activation;

// Uniform(-limit, limit) for every entry.
void FillUniform(tiny_dnn::vec_t* values, double limit, Rng* rng) {
  for (auto& v : *values) v = static_cast<float>(rng->Uniform(-limit, limit));
}

}  // namespace

PointNetwork::PointNetwork(const NetworkShape& shape, std::uint64_t seed, int threads)
    : shape_(shape), threads_(threads) {
  if (shape_.num_points < 1 || shape_.point_mlp.empty() || shape_.outputs < 1) {
    throw std::invalid_argument("PointNetwork: invalid shape");
  }
  Build();
  Initialise(seed);
}

void PointNetwork::Build() {
  std::vector<int> widths = {3};
  widths.insert(widths.end(), shape_.point_mlp.begin(), shape_.point_mlp.end());
  PointEncoderLayer encoder(widths, shape_.num_points);
  encoder.set_threads(threads_);
  net_ << std::move(encoder);
  layer_names_.push_back("point_mlp");
  int channels = widths.back();
  for (std::size_t h = 0; h < shape_.head.size(); ++h) {
    net_ << HeadLayer<activation::relu>(channels, shape_.head[h]);
    layer_names_.push_back("head." + std::to_string(h));
    channels = shape_.head[h];
  }
  net_ << HeadLayer<activation::identity>(channels, shape_.outputs);
  layer_names_.push_back("output");
  // tiny-dnn's backward kernel of a fully connected layer would start threads
  // per sample and layer (std::async); the head is small, so it runs serially.
  for (auto* layer : net_) {
    if (layer->layer_type() == "fully-connected") layer->set_parallelize(false);
  }
  net_.init_weight();   // allocates every edge; values are replaced below
}

void PointNetwork::Initialise(std::uint64_t seed) {
  Rng rng(seed);
  const std::size_t last = net_.layer_size() - 1;
  for (std::size_t i = 0; i < net_.layer_size(); ++i) {
    tiny_dnn::layer* layer = net_[i];
    auto weights = layer->weights();
    if (weights.empty()) continue;
    const double fan_in = layer->fan_in_size();
    const double fan_out = layer->fan_out_size();
    // He (ReLU layers) / Glorot (linear output layer) uniform limits.
    const double limit = i == last ? std::sqrt(6.0 / (fan_in + fan_out)) : std::sqrt(6.0 / fan_in);
    // Weights and biases alternate (the encoder has one pair per MLP stage).
    for (std::size_t w = 0; w < weights.size(); w += 2) {
      const double stage_fan_in = i == 0 ? static_cast<double>(weights[w]->size() / weights[w + 1]->size()) : fan_in;
      const double stage_limit = i == 0 ? std::sqrt(6.0 / stage_fan_in) : limit;
      FillUniform(weights[w], stage_limit, &rng);
      std::fill(weights[w + 1]->begin(), weights[w + 1]->end(), 0.0f);
    }
  }
}

tiny_dnn::tensor_t PointNetwork::Forward(const tiny_dnn::tensor_t& inputs) {
  net_[0]->set_in_data({inputs});
  for (auto* layer : net_) layer->forward();
  return net_[net_.layer_size() - 1]->output()[0];
}

double PointNetwork::ForwardBackward(const tiny_dnn::tensor_t& inputs,
                                     const tiny_dnn::tensor_t& targets) {
  const tiny_dnn::tensor_t outputs = Forward(inputs);
  const double num_keypoints = shape_.outputs / 3.0;
  tiny_dnn::tensor_t output_grad(outputs.size(), tiny_dnn::vec_t(outputs[0].size()));
  double loss = 0.0;
  for (std::size_t s = 0; s < outputs.size(); ++s) {
    for (std::size_t k = 0; k < outputs[s].size(); ++k) {
      const double diff = static_cast<double>(outputs[s][k]) - targets[s][k];
      loss += diff * diff / num_keypoints;
      output_grad[s][k] = static_cast<float>(2.0 * diff / num_keypoints);
    }
  }
  // tiny-dnn averages the per-sample weight gradients over the batch in
  // update_weight, so the per-sample gradient is that of the sample's loss.
  net_[net_.layer_size() - 1]->set_out_grads({output_grad});
  for (std::size_t i = net_.layer_size(); i-- > 0;) net_[i]->backward();
  return loss / static_cast<double>(outputs.size());
}

// Layers update independently (each its own weights, gradients and optimiser
// slots), so they are spread over the threads; the result does not depend on
// the schedule.
void PointNetwork::Update(tiny_dnn::optimizer* optimizer, int batch_size) {
  ParallelFor(0, static_cast<int>(net_.layer_size()), [&](int i) {
    net_[static_cast<std::size_t>(i)]->update_weight(optimizer, static_cast<tiny_dnn::serial_size_t>(batch_size));
  }, threads_);
}

std::vector<double> PointNetwork::TakeGradient(int batch_size) {
  std::vector<double> gradient;
  for (auto* layer : net_) {
    for (tiny_dnn::tensor_t* per_sample : layer->weights_grads()) {
      const std::size_t size = (*per_sample)[0].size();
      std::vector<double> sum(size, 0.0);
      for (const auto& sample : *per_sample) {
        for (std::size_t k = 0; k < size; ++k) sum[k] += sample[k];
      }
      for (double v : sum) gradient.push_back(v / batch_size);
    }
    layer->clear_grads();
  }
  return gradient;
}

std::vector<float> PointNetwork::Weights() const {
  std::vector<float> flat;
  for (std::size_t i = 0; i < net_.layer_size(); ++i) {
    for (const tiny_dnn::vec_t* w : net_[i]->weights()) flat.insert(flat.end(), w->begin(), w->end());
  }
  return flat;
}

void PointNetwork::SetWeights(const std::vector<float>& weights) {
  std::size_t offset = 0;
  for (tiny_dnn::vec_t* w : WeightVectors()) {
    if (offset + w->size() > weights.size()) {
      throw std::invalid_argument("PointNetwork::SetWeights: too few weights");
    }
    std::copy(weights.begin() + static_cast<std::ptrdiff_t>(offset),
              weights.begin() + static_cast<std::ptrdiff_t>(offset + w->size()), w->begin());
    offset += w->size();
  }
  if (offset != weights.size()) {
    throw std::invalid_argument("PointNetwork::SetWeights: too many weights");
  }
}

std::vector<WeightBlock> PointNetwork::Blocks() const {
  std::vector<WeightBlock> blocks;
  std::size_t offset = 0;
  for (std::size_t i = 0; i < net_.layer_size(); ++i) {
    const auto weights = net_[i]->weights();
    for (std::size_t w = 0; w < weights.size(); ++w) {
      const std::string stage = i == 0 ? "." + std::to_string(w / 2) : "";
      blocks.push_back({layer_names_[i] + stage + (w % 2 == 0 ? ".weight" : ".bias"), offset,
                        weights[w]->size()});
      offset += weights[w]->size();
    }
  }
  return blocks;
}

std::vector<tiny_dnn::vec_t*> PointNetwork::WeightVectors() {
  std::vector<tiny_dnn::vec_t*> vectors;
  for (auto* layer : net_) {
    for (tiny_dnn::vec_t* w : layer->weights()) vectors.push_back(w);
  }
  return vectors;
}

}  // namespace c3po::pointnet
