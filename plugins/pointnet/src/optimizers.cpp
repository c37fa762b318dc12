#include "optimizers.hpp"

#include <cmath>
#include <stdexcept>

namespace c3po::pointnet {

StatefulOptimizer::StatefulOptimizer(std::vector<tiny_dnn::vec_t*> order, int slots_per_vector)
    : order_(std::move(order)), slots_per_vector_(slots_per_vector) {
  for (std::size_t i = 0; i < order_.size(); ++i) {
    index_[order_[i]] = i;
    for (int s = 0; s < slots_per_vector_; ++s) state_.emplace_back(order_[i]->size(), 0.0f);
  }
}

std::vector<float>& StatefulOptimizer::Slot(const tiny_dnn::vec_t& weights, int slot) {
  const auto it = index_.find(&weights);
  if (it == index_.end()) throw std::logic_error("optimizer: unregistered weight vector");
  return state_[it->second * static_cast<std::size_t>(slots_per_vector_) +
                static_cast<std::size_t>(slot)];
}

void StatefulOptimizer::SaveState(std::ostream& out) const {
  const std::int64_t step = step_;
  const std::uint64_t count = state_.size();
  out.write(reinterpret_cast<const char*>(&step), sizeof step);
  out.write(reinterpret_cast<const char*>(&count), sizeof count);
  for (const auto& slot : state_) {
    const std::uint64_t size = slot.size();
    out.write(reinterpret_cast<const char*>(&size), sizeof size);
    out.write(reinterpret_cast<const char*>(slot.data()),
              static_cast<std::streamsize>(slot.size() * sizeof(float)));
  }
}

bool StatefulOptimizer::LoadState(std::istream& in) {
  std::int64_t step = 0;
  std::uint64_t count = 0;
  if (!in.read(reinterpret_cast<char*>(&step), sizeof step)) return false;
  if (!in.read(reinterpret_cast<char*>(&count), sizeof count) || count != state_.size()) return false;
  std::vector<std::vector<float>> state(state_.size());
  for (std::size_t i = 0; i < state.size(); ++i) {
    std::uint64_t size = 0;
    if (!in.read(reinterpret_cast<char*>(&size), sizeof size) || size != state_[i].size()) return false;
    state[i].resize(size);
    if (!in.read(reinterpret_cast<char*>(state[i].data()),
                 static_cast<std::streamsize>(size * sizeof(float)))) {
      return false;
    }
  }
  step_ = step;
  state_ = std::move(state);
  return true;
}

AdamOptimizer::AdamOptimizer(std::vector<tiny_dnn::vec_t*> order, double lr)
    : StatefulOptimizer(std::move(order), 2), learning_rate(lr) {}

// m <- b1 m + (1-b1) g;  v <- b2 v + (1-b2) g^2;
// W <- W - lr * (m / (1-b1^t)) / (sqrt(v / (1-b2^t)) + eps).
void AdamOptimizer::update(const tiny_dnn::vec_t& dW, tiny_dnn::vec_t& W, bool) {
  std::vector<float>& m = Slot(W, 0);
  std::vector<float>& v = Slot(W, 1);
  const double t = static_cast<double>(step_ > 0 ? step_ : 1);
  const float correction1 = static_cast<float>(1.0 / (1.0 - std::pow(beta1, t)));
  const float correction2 = static_cast<float>(1.0 / (1.0 - std::pow(beta2, t)));
  const float b1 = static_cast<float>(beta1), b2 = static_cast<float>(beta2);
  const float lr = static_cast<float>(learning_rate), eps = static_cast<float>(epsilon);
  for (std::size_t i = 0; i < W.size(); ++i) {
    m[i] = b1 * m[i] + (1.0f - b1) * dW[i];
    v[i] = b2 * v[i] + (1.0f - b2) * dW[i] * dW[i];
    W[i] -= lr * (m[i] * correction1) / (std::sqrt(v[i] * correction2) + eps);
  }
}

MomentumSgdOptimizer::MomentumSgdOptimizer(std::vector<tiny_dnn::vec_t*> order, double lr,
                                           double mu)
    : StatefulOptimizer(std::move(order), 1), learning_rate(lr), momentum(mu) {}

void MomentumSgdOptimizer::update(const tiny_dnn::vec_t& dW, tiny_dnn::vec_t& W, bool) {
  std::vector<float>& velocity = Slot(W, 0);
  const float mu = static_cast<float>(momentum), lr = static_cast<float>(learning_rate);
  for (std::size_t i = 0; i < W.size(); ++i) {
    velocity[i] = mu * velocity[i] + dW[i];
    W[i] -= lr * velocity[i];
  }
}

std::unique_ptr<StatefulOptimizer> MakeOptimizer(const std::string& kind,
                                                 std::vector<tiny_dnn::vec_t*> order,
                                                 double learning_rate, double momentum) {
  if (kind == "adam") return std::make_unique<AdamOptimizer>(std::move(order), learning_rate);
  if (kind == "sgd") {
    return std::make_unique<MomentumSgdOptimizer>(std::move(order), learning_rate, momentum);
  }
  throw std::invalid_argument("unknown optimizer '" + kind + "' (adam or sgd)");
}

}  // namespace c3po::pointnet
