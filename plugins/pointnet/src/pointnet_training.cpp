// PointNetDetector training: Fit (epochs, validation, best weights,
// checkpoints), TrainStep (one batch, for self-training) and Evaluate.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "c3po/base/interrupt.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/base/random.hpp"
#include "detector_impl.hpp"
#include "input_preparation.hpp"

namespace c3po {

void PointNetTrainOptions::Check() const {
  if (epochs < 1) throw std::invalid_argument("epochs must be >= 1");
  if (batch < 1) throw std::invalid_argument("batch must be >= 1");
  if (!(std::isfinite(lr) && lr > 0.0)) throw std::invalid_argument("lr must be > 0");
  if (optimizer != "adam" && optimizer != "sgd") {
    throw std::invalid_argument("optimizer must be 'adam' or 'sgd'");
  }
  if (!(momentum >= 0.0 && momentum < 1.0)) throw std::invalid_argument("momentum must be in [0, 1)");
  if (!(validation_fraction >= 0.0 && validation_fraction < 1.0)) {
    throw std::invalid_argument("validation_fraction must be in [0, 1)");
  }
  if (!(rotate_about_camera_deg >= 0.0 && rotate_about_camera_deg <= 180.0)) {
    throw std::invalid_argument("rotate_about_camera_deg must be in [0, 180]");
  }
  if (!(point_dropout >= 0.0 && point_dropout < 1.0)) {
    throw std::invalid_argument("point_dropout must be in [0, 1)");
  }
  if (!(noise_sigma >= 0.0 && std::isfinite(noise_sigma))) {
    throw std::invalid_argument("noise_sigma must be >= 0");
  }
  if (num_points < 1) throw std::invalid_argument("num_points must be >= 1");
}

namespace {

using Clock = std::chrono::steady_clock;

void CheckKeypointCount(const PointSet& keypoints, int expected) {
  if (keypoints.cols() != expected || !keypoints.allFinite()) {
    throw std::invalid_argument("training keypoints must be 3 x " + std::to_string(expected) +
                                " and finite (got 3 x " + std::to_string(keypoints.cols()) + ")");
  }
}

// Per-epoch seed: every random choice of epoch e comes from it, so a resumed
// run repeats exactly what an uninterrupted run would have done.
std::uint64_t EpochSeed(std::uint64_t seed, int epoch) {
  return Rng::ForItem(seed, 0x9E3779B97F4A7C15ULL + static_cast<std::uint64_t>(epoch)).Next();
}

std::vector<std::size_t> Shuffled(std::size_t count, Rng* rng) {
  std::vector<std::size_t> order(count);
  std::iota(order.begin(), order.end(), 0);
  for (std::size_t i = count; i > 1; --i) {
    std::swap(order[i - 1], order[static_cast<std::size_t>(rng->UniformInt(static_cast<int>(i)))]);
  }
  return order;
}

struct Split {
  std::vector<const TrainingSample*> train;
  std::vector<const TrainingSample*> validation;
};

Split SplitSamples(const std::vector<TrainingSample>& train,
                   const std::vector<TrainingSample>& validation, const PointNetTrainOptions& options) {
  Split split;
  for (const auto& s : validation) split.validation.push_back(&s);
  if (!validation.empty() || options.validation_fraction <= 0.0 || train.size() < 2) {
    for (const auto& s : train) split.train.push_back(&s);
    return split;
  }
  Rng rng(options.seed);
  const std::vector<std::size_t> order = Shuffled(train.size(), &rng);
  const std::size_t held_out = std::min(
      train.size() - 1,
      std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(options.validation_fraction * train.size()))));
  std::vector<std::size_t> held(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(held_out));
  std::sort(held.begin(), held.end());
  std::vector<bool> is_held(train.size(), false);
  for (std::size_t i : held) is_held[i] = true;
  for (std::size_t i = 0; i < train.size(); ++i) (is_held[i] ? split.validation : split.train).push_back(&train[i]);
  return split;
}

// Squared distance between two normalised keypoint vectors.
double SquaredDistance(const tiny_dnn::vec_t& a, const tiny_dnn::vec_t& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += static_cast<double>(a[i] - b[i]) * static_cast<double>(a[i] - b[i]);
  return sum;
}

// Index into {keypoints, symmetric_keypoints...} of the labelling nearest
// `detected` (0 = keypoints; ties keep the lower index).
std::size_t NearestLabellingIndex(const PointSet& detected, const TrainingSample& sample) {
  std::size_t best = 0;
  double best_distance = (detected - sample.keypoints).squaredNorm();
  for (std::size_t j = 0; j < sample.symmetric_keypoints.size(); ++j) {
    const double distance = (detected - sample.symmetric_keypoints[j]).squaredNorm();
    if (distance < best_distance) best = j + 1, best_distance = distance;
  }
  return best;
}

}  // namespace

// One optimisation step on prepared inputs; returns the loss before the step
// in normalised units.
static double StepOnPrepared(PointNetDetector::Impl* impl, const tiny_dnn::tensor_t& inputs,
                             const tiny_dnn::tensor_t& targets) {
  const double loss = impl->network->ForwardBackward(inputs, targets);
  impl->optimizer->BeginStep();
  impl->network->Update(impl->optimizer.get(), static_cast<int>(inputs.size()));
  impl->WeightsChanged();
  return loss;
}

// Symmetry-aware loss min_j ||ỹ - y_j||² (method.md "Symmetric labellings in
// supervised training"): where a sample has symmetric labellings, its target
// becomes the labelling nearest the network's current output on the same
// input. Returns how many targets changed. No forward pass when no sample has
// symmetric labellings (the plain loss, bit for bit).
static int ChooseNearestTargets(PointNetDetector::Impl* impl, const tiny_dnn::tensor_t& inputs,
                                const std::vector<tiny_dnn::tensor_t>& symmetric_targets,
                                tiny_dnn::tensor_t* targets) {
  if (std::all_of(symmetric_targets.begin(), symmetric_targets.end(),
                  [](const tiny_dnn::tensor_t& t) { return t.empty(); })) {
    return 0;
  }
  const tiny_dnn::tensor_t outputs = impl->network->Forward(inputs);
  int switched = 0;
  for (std::size_t i = 0; i < symmetric_targets.size(); ++i) {
    double best = SquaredDistance(outputs[i], (*targets)[i]);
    const tiny_dnn::vec_t* chosen = nullptr;
    for (const tiny_dnn::vec_t& labelling : symmetric_targets[i]) {
      const double distance = SquaredDistance(outputs[i], labelling);
      if (distance < best) best = distance, chosen = &labelling;
    }
    if (chosen) (*targets)[i] = *chosen, ++switched;
  }
  return switched;
}

double PointNetDetector::TrainStep(const std::vector<PointSet>& clouds,
                                   const std::vector<PointSet>& keypoints,
                                   const PointNetTrainOptions& options) {
  options.Check();
  if (clouds.empty() || clouds.size() != keypoints.size()) {
    throw std::invalid_argument("TrainStep: need as many keypoint sets as clouds (> 0)");
  }
  for (const auto& k : keypoints) CheckKeypointCount(k, impl_->identity.num_keypoints);
  impl_->EnsureOptimizer(options);
  const int count = static_cast<int>(clouds.size());
  tiny_dnn::tensor_t inputs(clouds.size()), targets(clouds.size());
  ParallelFor(0, count, [&](int i) {
    const std::size_t s = static_cast<std::size_t>(i);
    auto prepared = pointnet::PrepareCloud(clouds[s], impl_->architecture.num_points, impl_->identity.scale);
    targets[s] = pointnet::NormaliseKeypoints(keypoints[s], prepared.centroid, impl_->identity.scale);
    inputs[s] = std::move(prepared.points);
  }, impl_->threads);
  const double scale = impl_->identity.scale;
  return StepOnPrepared(impl_.get(), inputs, targets) * scale * scale;
}

double PointNetDetector::TrainStep(const std::vector<PointSet>& clouds,
                                   const std::vector<PointSet>& targets) {
  return TrainStep(clouds, targets, impl_->step_options);
}

void PointNetDetector::SetTrainOptions(const PointNetTrainOptions& options) {
  options.Check();
  impl_->step_options = options;
}

const PointNetTrainOptions& PointNetDetector::train_options() const { return impl_->step_options; }

PointNetDetector::Evaluation PointNetDetector::Evaluate(const std::vector<TrainingSample>& samples) const {
  Evaluation evaluation;
  if (samples.empty()) {
    evaluation.loss = evaluation.keypoint_error = std::nan("");
    return evaluation;
  }
  std::vector<PointSet> clouds;
  clouds.reserve(samples.size());
  for (const auto& s : samples) clouds.push_back(s.cloud);
  const std::vector<PointSet> detected = impl_->DetectAll(clouds);
  double squared = 0.0, distance = 0.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    CheckKeypointCount(samples[i].keypoints, impl_->identity.num_keypoints);
    // Symmetric labellings: the error to the nearest one (the loss trained).
    const std::size_t nearest = NearestLabellingIndex(detected[i], samples[i]);
    const PointSet& truth = nearest == 0 ? samples[i].keypoints : samples[i].symmetric_keypoints[nearest - 1];
    const Eigen::VectorXd d = (detected[i] - truth).colwise().norm();
    squared += d.squaredNorm() / static_cast<double>(d.size());
    distance += d.mean();
  }
  evaluation.loss = squared / static_cast<double>(samples.size());
  evaluation.keypoint_error = distance / static_cast<double>(samples.size());
  return evaluation;
}

static void CheckFitSamples(const PointNetDetector::Impl& impl, const std::vector<TrainingSample>& train,
                            const std::vector<TrainingSample>& validation, const PointNetTrainOptions& options) {
  if (options.num_points != impl.architecture.num_points) {
    throw std::invalid_argument("options.num_points (" + std::to_string(options.num_points) +
                                ") differs from the network's (" +
                                std::to_string(impl.architecture.num_points) + ")");
  }
  for (const auto& s : train) CheckKeypointCount(s.keypoints, impl.identity.num_keypoints);
  for (const auto& s : validation) CheckKeypointCount(s.keypoints, impl.identity.num_keypoints);
  if (train.empty()) throw std::invalid_argument("Fit: no training samples");
}

// A batch ready for the network: the samples at order[begin, begin + count), each augmented and
// prepared with its own seeded generator (so a batch does not depend on the threads).
struct PreparedBatch {
  tiny_dnn::tensor_t inputs, targets;
  std::vector<tiny_dnn::tensor_t> symmetric_targets;
};

static PreparedBatch PrepareBatch(const PointNetDetector::Impl& impl, const std::vector<const TrainingSample*>& train,
                                  const std::vector<std::size_t>& order, std::size_t begin, std::size_t count,
                                  std::uint64_t epoch_seed, const pointnet::Augmentation& augmentation) {
  PreparedBatch batch{tiny_dnn::tensor_t(count), tiny_dnn::tensor_t(count), std::vector<tiny_dnn::tensor_t>(count)};
  const double scale = impl.identity.scale;
  ParallelFor(0, static_cast<int>(count), [&](int i) {
    const std::size_t position = begin + static_cast<std::size_t>(i);
    Rng rng = Rng::ForItem(epoch_seed, position);
    const TrainingSample& original = *train[order[position]];
    const TrainingSample sample = augmentation.active() ? pointnet::Augment(original, augmentation, &rng) : original;
    auto prepared = pointnet::PrepareCloud(sample.cloud, impl.architecture.num_points, scale, &rng);
    const std::size_t s = static_cast<std::size_t>(i);
    batch.targets[s] = pointnet::NormaliseKeypoints(sample.keypoints, prepared.centroid, scale);
    for (const PointSet& labelling : sample.symmetric_keypoints) {
      batch.symmetric_targets[s].push_back(pointnet::NormaliseKeypoints(labelling, prepared.centroid, scale));
    }
    batch.inputs[s] = std::move(prepared.points);
  }, impl.threads);
  return batch;
}

// One pass over the training samples in a seeded order; the epoch's log with its training loss
// (metres squared) and switched labellings.
static EpochLog TrainEpoch(PointNetDetector::Impl* impl, const std::vector<const TrainingSample*>& train, int epoch,
                           const PointNetTrainOptions& options) {
  const pointnet::Augmentation augmentation{options.rotate_about_camera_deg, options.point_dropout,
                                            options.noise_sigma};
  const std::uint64_t epoch_seed = EpochSeed(options.seed, epoch);
  Rng shuffle_rng(epoch_seed);
  const std::vector<std::size_t> order = Shuffled(train.size(), &shuffle_rng);
  double loss_sum = 0.0;
  int switched = 0;
  for (std::size_t begin = 0; begin < order.size(); begin += static_cast<std::size_t>(options.batch)) {
    HoldForInterruptAt(epoch, static_cast<long long>(begin / static_cast<std::size_t>(options.batch)));
    ThrowIfInterrupted();
    const std::size_t count = std::min(order.size() - begin, static_cast<std::size_t>(options.batch));
    PreparedBatch batch = PrepareBatch(*impl, train, order, begin, count, epoch_seed, augmentation);
    switched += ChooseNearestTargets(impl, batch.inputs, batch.symmetric_targets, &batch.targets);
    loss_sum += StepOnPrepared(impl, batch.inputs, batch.targets) * static_cast<double>(count);
  }
  const double scale = impl->identity.scale;
  EpochLog log;
  log.epoch = epoch;
  log.train_loss = loss_sum / static_cast<double>(order.size()) * scale * scale;
  log.labellings_switched = switched;
  return log;
}

// The model file's training record: the run's counts, options and best epoch.
static std::string TrainingInfo(const std::string& before, const PointNetFitResult& result, int epochs_done,
                                const PointNetTrainOptions& options) {
  nlohmann::json info = nlohmann::json::parse(before);
  info["epochs"] = epochs_done;
  info["best_epoch"] = result.best_epoch;
  if (std::isfinite(result.best_val_loss)) info["best_val_loss"] = result.best_val_loss;
  info["train_samples"] = result.train_samples;
  info["validation_samples"] = result.validation_samples;
  info["optimizer"] = options.optimizer;
  info["lr"] = options.lr;
  info["batch"] = options.batch;
  info["seed"] = options.seed;
  info["augmentation"] = {{"rotate_about_camera_deg", options.rotate_about_camera_deg},
                          {"point_dropout", options.point_dropout},
                          {"noise_sigma", options.noise_sigma}};
  return info.dump();
}

PointNetFitResult PointNetDetector::Fit(const std::vector<TrainingSample>& train,
                                        const std::vector<TrainingSample>& validation,
                                        const PointNetTrainOptions& options,
                                        const PointNetEpochCallback& on_epoch) {
  options.Check();
  Impl& impl = *impl_;
  CheckFitSamples(impl, train, validation, options);
  const Split split = SplitSamples(train, validation, options);
  std::vector<TrainingSample> validation_set;
  for (const auto* s : split.validation) validation_set.push_back(*s);
  // Records an epoch's validation and keeps its weights when they are the best so far.
  const auto validate = [&](EpochLog* log, Clock::time_point start, bool always_best) {
    const Evaluation evaluation = Evaluate(validation_set);
    log->val_loss = evaluation.loss;
    log->val_keypoint_error = evaluation.keypoint_error;
    log->best = always_best || validation_set.empty() || evaluation.loss < impl.progress.best_val_loss;
    if (log->best) {
      impl.progress.best_val_loss = validation_set.empty() ? std::nan("") : evaluation.loss;
      impl.progress.best_epoch = log->epoch;
      impl.progress.best_weights = impl.network->Weights();
    }
    log->seconds = std::chrono::duration<double>(Clock::now() - start).count();
  };

  if (!options.resume || impl.progress.epochs_done == 0) {
    impl.progress = PointNetProgress{};
    impl.optimizer.reset();
  }
  impl.EnsureOptimizer(options);
  if (options.validate_initial && impl.progress.epochs_done == 0) {
    // Epoch 0: the starting weights, kept unless an epoch beats them.
    const auto start = Clock::now();
    std::vector<TrainingSample> train_set;
    for (const auto* s : split.train) train_set.push_back(*s);
    EpochLog log;
    log.epoch = 0;
    log.train_loss = Evaluate(train_set).loss;
    validate(&log, start, true);
    impl.progress.history.push_back(log);
    if (on_epoch) on_epoch(log);
  }
  for (int epoch = impl.progress.epochs_done + 1; epoch <= options.epochs; ++epoch) {
    const auto start = Clock::now();
    EpochLog log = TrainEpoch(&impl, split.train, epoch, options);
    validate(&log, start, false);
    impl.progress.epochs_done = epoch;
    impl.progress.history.push_back(log);
    if (!options.checkpoint_path.empty()) SaveCheckpoint(options.checkpoint_path, "");
    if (on_epoch) on_epoch(log);
  }

  PointNetFitResult result;
  result.epochs = impl.progress.history;
  result.best_epoch = impl.progress.best_epoch;
  result.best_val_loss = impl.progress.best_val_loss;
  result.train_samples = split.train.size();
  result.validation_samples = split.validation.size();
  if (!impl.progress.best_weights.empty()) {
    impl.network->SetWeights(impl.progress.best_weights);
    impl.WeightsChanged();
  }
  impl.training_info = TrainingInfo(impl.training_info, result, impl.progress.epochs_done, options);
  return result;
}

}  // namespace c3po
