// PointNetDetector: construction, inference, weights access. Training is in
// pointnet_training.cpp, the model file in pointnet_model_io.cpp.
#include <cmath>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "c3po/base/error.hpp"
#include "c3po/base/parallel.hpp"
#include "detector_impl.hpp"
#include "input_preparation.hpp"

namespace c3po {
namespace {

constexpr int kInferenceChunk = 64;

void CheckWidths(const std::vector<int>& widths, const char* what, bool allow_empty) {
  if (widths.empty() && !allow_empty) throw std::invalid_argument(std::string(what) + " is empty");
  for (int w : widths) {
    if (w < 1 || w > 8192) throw std::invalid_argument(std::string(what) + ": widths must be in [1, 8192]");
  }
}

}  // namespace

void PointNetArchitecture::Check() const {
  if (num_points < 1 || num_points > 65536) {
    throw std::invalid_argument("num_points must be in [1, 65536]");
  }
  CheckWidths(point_mlp, "point_mlp", false);
  CheckWidths(head, "head", true);
  if (point_mlp.size() + head.size() > 32) throw std::invalid_argument("more than 32 layers");
}

void PointNetIdentity::Check() const {
  if (num_keypoints < 1 || num_keypoints > 100000) {
    throw std::invalid_argument("the number of keypoints must be in [1, 100000]");
  }
  if (!(std::isfinite(scale) && scale > 0.0)) throw std::invalid_argument("scale must be finite and > 0");
}

PointNetIdentity PointNetIdentity::ForObject(const ObjectModel& object) {
  PointNetIdentity identity;
  identity.object_name = object.name();
  identity.keypoint_hash = object.KeypointHash();
  identity.num_keypoints = object.num_keypoints();
  identity.scale = object.diameter();
  return identity;
}

// ---------------------------------------------------------------------------
PointNetDetector::Impl::Impl(const PointNetIdentity& id, const PointNetArchitecture& arch,
                             std::uint64_t seed)
    : identity(id), architecture(arch) {
  identity.Check();
  architecture.Check();
  step_options.num_points = architecture.num_points;
  network = std::make_unique<pointnet::PointNetwork>(Shape(), seed, threads);
}

pointnet::NetworkShape PointNetDetector::Impl::Shape() const {
  pointnet::NetworkShape shape;
  shape.num_points = architecture.num_points;
  shape.point_mlp = architecture.point_mlp;
  shape.head = architecture.head;
  shape.outputs = 3 * identity.num_keypoints;
  return shape;
}

void PointNetDetector::Impl::WeightsChanged() {
  std::lock_guard<std::mutex> lock(pool_mutex);
  pool.clear();
  ++weights_version;
}

PointNetDetector::Impl::InferenceCopy PointNetDetector::Impl::AcquireInferenceNetwork() const {
  std::lock_guard<std::mutex> lock(pool_mutex);
  if (!pool.empty()) {
    InferenceCopy copy = std::move(pool.back());
    pool.pop_back();
    return copy;
  }
  InferenceCopy copy;
  copy.network = std::make_unique<pointnet::PointNetwork>(Shape(), 0, threads);
  copy.network->SetWeights(network->Weights());
  copy.version = weights_version;
  return copy;
}

void PointNetDetector::Impl::ReleaseInferenceNetwork(InferenceCopy copy) const {
  std::lock_guard<std::mutex> lock(pool_mutex);
  if (copy.version == weights_version) pool.push_back(std::move(copy));
}

std::vector<PointSet> PointNetDetector::Impl::DetectAll(const std::vector<PointSet>& clouds) const {
  std::vector<PointSet> keypoints(clouds.size());
  if (clouds.empty()) return keypoints;
  auto copy = AcquireInferenceNetwork();
  const int total = static_cast<int>(clouds.size());
  for (int begin = 0; begin < total; begin += kInferenceChunk) {
    const int count = std::min(kInferenceChunk, total - begin);
    std::vector<pointnet::PreparedCloud> prepared(static_cast<std::size_t>(count));
    ParallelFor(0, count, [&](int i) {
      prepared[static_cast<std::size_t>(i)] = pointnet::PrepareCloud(
          clouds[static_cast<std::size_t>(begin + i)], architecture.num_points, identity.scale);
    }, count > 1 ? threads : 1);
    tiny_dnn::tensor_t inputs(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) inputs[static_cast<std::size_t>(i)] = std::move(prepared[static_cast<std::size_t>(i)].points);
    const tiny_dnn::tensor_t outputs = copy.network->Forward(inputs);
    for (int i = 0; i < count; ++i) {
      keypoints[static_cast<std::size_t>(begin + i)] = pointnet::DenormaliseKeypoints(
          outputs[static_cast<std::size_t>(i)], prepared[static_cast<std::size_t>(i)].centroid, identity.scale);
    }
  }
  ReleaseInferenceNetwork(std::move(copy));
  return keypoints;
}

void PointNetDetector::Impl::EnsureOptimizer(const PointNetTrainOptions& options) {
  if (optimizer && optimizer->kind() == options.optimizer && optimizer_lr == options.lr &&
      optimizer_momentum == options.momentum) {
    return;
  }
  optimizer = pointnet::MakeOptimizer(options.optimizer, network->WeightVectors(), options.lr,
                                      options.momentum);
  optimizer_lr = options.lr;
  optimizer_momentum = options.momentum;
}

// ---------------------------------------------------------------------------
PointNetDetector::PointNetDetector(const ObjectModel& object, const PointNetArchitecture& architecture,
                                   std::uint64_t seed)
    : PointNetDetector(PointNetIdentity::ForObject(object), architecture, seed) {}

PointNetDetector::PointNetDetector(const PointNetIdentity& identity,
                                   const PointNetArchitecture& architecture, std::uint64_t seed)
    : impl_(std::make_unique<Impl>(identity, architecture, seed)) {}

PointNetDetector::PointNetDetector(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PointNetDetector::~PointNetDetector() = default;
PointNetDetector::PointNetDetector(PointNetDetector&&) noexcept = default;
PointNetDetector& PointNetDetector::operator=(PointNetDetector&&) noexcept = default;

int PointNetDetector::num_keypoints() const { return impl_->identity.num_keypoints; }

PointSet PointNetDetector::Detect(const PointSet& cloud) const {
  return impl_->DetectAll({cloud}).front();
}

std::vector<PointSet> PointNetDetector::DetectBatch(const std::vector<PointSet>& clouds) const {
  return impl_->DetectAll(clouds);
}

const PointNetIdentity& PointNetDetector::identity() const { return impl_->identity; }
const PointNetArchitecture& PointNetDetector::architecture() const { return impl_->architecture; }
std::string PointNetDetector::training_info_json() const { return impl_->training_info; }

void PointNetDetector::set_training_info_json(const std::string& json) {
  nlohmann::json parsed;
  try {
    parsed = nlohmann::json::parse(json);
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("training info is not JSON: ") + e.what());
  }
  if (!parsed.is_object()) throw std::invalid_argument("training info must be a JSON object");
  impl_->training_info = parsed.dump();
}

std::vector<PointNetDetector::WeightBlock> PointNetDetector::WeightBlocks() const {
  std::vector<WeightBlock> blocks;
  for (const auto& b : impl_->network->Blocks()) blocks.push_back({b.name, b.offset, b.size});
  return blocks;
}

std::vector<float> PointNetDetector::GetWeights() const { return impl_->network->Weights(); }

void PointNetDetector::SetWeights(const std::vector<float>& weights) {
  impl_->network->SetWeights(weights);
  impl_->WeightsChanged();
}

double PointNetDetector::LossAndGradient(const std::vector<PointSet>& clouds,
                                         const std::vector<PointSet>& keypoints,
                                         std::vector<double>* gradient) {
  if (clouds.empty() || clouds.size() != keypoints.size()) {
    throw std::invalid_argument("LossAndGradient: need as many keypoint sets as clouds (> 0)");
  }
  tiny_dnn::tensor_t inputs, targets;
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    auto prepared = pointnet::PrepareCloud(clouds[i], impl_->architecture.num_points, impl_->identity.scale);
    targets.push_back(pointnet::NormaliseKeypoints(keypoints[i], prepared.centroid, impl_->identity.scale));
    inputs.push_back(std::move(prepared.points));
  }
  const double loss = impl_->network->ForwardBackward(inputs, targets);
  const std::vector<double> mean_gradient = impl_->network->TakeGradient(static_cast<int>(clouds.size()));
  if (gradient) *gradient = mean_gradient;
  return loss;
}

}  // namespace c3po
