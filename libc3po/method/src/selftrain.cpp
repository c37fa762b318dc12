#include "c3po/method/selftrain.hpp"

#include <algorithm>
#include <cstring>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <stdexcept>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/base/random.hpp"

namespace c3po {

void SelfTrainOptions::Check() const {
  if (epochs < 1) throw std::invalid_argument("epochs must be >= 1");
  if (batch < 1) throw std::invalid_argument("batch must be >= 1");
  if (!(validation_fraction > 0 && validation_fraction < 1)) {
    throw std::invalid_argument("validation fraction must be in (0, 1)");
  }
  pipeline.Check();
}

CertifiedFraction MeasureCertified(const ObjectModel& object, const std::vector<PointSet>& clouds,
                                   const Detector& detector, const PipelineOptions& options, bool auto_eps_oc) {
  CertifiedFraction result;
  if (clouds.empty()) return result;
  // The detector sees the clouds as one batch (DetectBatch); CertifyBatch
  // certifies them with the detections as given keypoints.
  CertifyBatchOptions batch;
  batch.pipeline = options;
  batch.auto_eps_oc = auto_eps_oc;
  CertifyBatchResult certified =
      CertifyBatch(object, InMemorySources(clouds, detector.DetectBatch(clouds)), nullptr, batch);
  result.auto_eps_oc = std::move(certified.auto_eps_oc);
  result.estimates.reserve(clouds.size());
  for (CloudOutcome& outcome : certified.outcomes) {
    if (!outcome.processed()) throw InputError("selftrain", "detector: " + outcome.error);
    result.estimates.push_back(std::move(outcome.estimate));
  }
  double oc = 0, certified_count = 0, iterations = 0, squared_error = 0;
  for (const auto& e : result.estimates) {
    const bool observably_correct = e.ok() && e.certificate.oc.passed;
    oc += observably_correct;
    certified_count += e.certified();
    iterations += e.correction.iterations;
    if (observably_correct) {
      squared_error += (e.detected_keypoints - e.keypoints).squaredNorm() / e.keypoints.cols();
    }
  }
  result.detection_error = oc > 0 ? std::sqrt(squared_error / oc) : 0.0;
  const double n = static_cast<double>(clouds.size());
  result.percent_oc = 100.0 * oc / n;
  result.percent_certified = 100.0 * certified_count / n;
  result.mean_iterations = iterations / n;
  return result;
}

namespace {

using nlohmann::json;

std::vector<int> Shuffled(std::vector<int> indices, Rng rng) {
  for (int i = static_cast<int>(indices.size()) - 1; i > 0; --i) {
    std::swap(indices[i], indices[rng.UniformInt(i + 1)]);
  }
  return indices;
}

json LogJson(const SelfTrainEpochLog& log) {
  return {{"epoch", log.epoch}, {"train_percent_oc", log.train_percent_oc},
          {"validation_percent_oc", log.validation_percent_oc},
          {"validation_percent_certified", log.validation_percent_certified},
          {"validation_detection_error", log.validation_detection_error}, {"loss", log.loss},
          {"mean_corrector_iterations", log.mean_corrector_iterations},
          {"certified_samples", log.certified_samples}, {"seconds", log.seconds}};
}

SelfTrainEpochLog LogFromJson(const json& j) {
  SelfTrainEpochLog log;
  log.epoch = j.at("epoch");
  log.train_percent_oc = j.at("train_percent_oc");
  log.validation_percent_oc = j.at("validation_percent_oc");
  log.validation_percent_certified = j.at("validation_percent_certified");
  log.validation_detection_error = j.at("validation_detection_error");
  log.loss = j.at("loss");
  log.mean_corrector_iterations = j.at("mean_corrector_iterations");
  log.certified_samples = j.at("certified_samples");
  log.seconds = j.at("seconds");
  return log;
}

// The best weights live beside the checkpoint as raw floats.
void SaveWeights(const std::string& path, const std::vector<float>& weights) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(weights.data()),
              static_cast<std::streamsize>(weights.size() * sizeof(float)));
  });
}

std::vector<float> LoadWeights(const std::string& path, std::size_t expected) {
  const std::string bytes = ReadFileToString(path);
  if (bytes.size() != expected * sizeof(float)) throw InputError(path, "best-weights file has the wrong size");
  std::vector<float> weights(expected);
  std::memcpy(weights.data(), bytes.data(), bytes.size());
  return weights;
}

struct EpochStats {
  double loss_sum = 0.0;
  int steps = 0;
  int certified = 0;
  int seen = 0;
  double iterations = 0.0;
};

// One pass over the training clouds: certify each batch with the current
// detector, then one regression step on its observably correct samples.
EpochStats RunEpoch(const ObjectModel& object, const std::vector<PointSet>& clouds,
                    const std::vector<int>& order, TrainableDetector& detector,
                    const SelfTrainOptions& options, const ProgressCallback& progress,
                    std::size_t progress_offset, std::size_t progress_total, int epoch) {
  EpochStats stats;
  for (std::size_t start = 0; start < order.size(); start += options.batch) {
    HoldForInterruptAt(epoch, static_cast<long long>(start / options.batch));
    ThrowIfInterrupted();
    const std::size_t end = std::min(order.size(), start + options.batch);
    std::vector<PointSet> batch;
    for (std::size_t k = start; k < end; ++k) batch.push_back(clouds[order[k]]);
    const std::vector<PoseEstimate> estimates = MeasureCertified(object, batch, detector, options.pipeline).estimates;
    std::vector<PointSet> certified_clouds, targets;
    for (std::size_t i = 0; i < batch.size(); ++i) {
      stats.iterations += estimates[i].correction.iterations;
      if (estimates[i].ok() && estimates[i].certificate.oc.passed) {
        certified_clouds.push_back(batch[i]);
        targets.push_back(estimates[i].keypoints);   // pseudo-label: corrected keypoints
      }
    }
    stats.seen += static_cast<int>(batch.size());
    stats.certified += static_cast<int>(certified_clouds.size());
    if (!certified_clouds.empty()) {
      stats.loss_sum += detector.TrainStep(certified_clouds, targets);
      ++stats.steps;
    }
    if (progress) progress(progress_offset + end, progress_total);
  }
  return stats;
}

}  // namespace

SelfTrainResult SelfTrain(const ObjectModel& object, const std::vector<PointSet>& clouds,
                          TrainableDetector& detector, const SelfTrainOptions& options,
                          const EpochCallback& on_epoch, const ProgressCallback& progress,
                          bool resume) {
  options.Check();
  if (clouds.size() < 2) throw InputError("selftrain", "need at least 2 unlabelled clouds");
  // Deterministic split: a seeded shuffle, the first part held out.
  std::vector<int> all(clouds.size());
  std::iota(all.begin(), all.end(), 0);
  all = Shuffled(all, Rng::ForItem(options.seed, 0xC3B0));
  const std::size_t validation_count = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::lround(options.validation_fraction * clouds.size())), 1, clouds.size() - 1);
  std::vector<PointSet> validation;
  for (std::size_t k = 0; k < validation_count; ++k) validation.push_back(clouds[all[k]]);
  const std::vector<int> train(all.begin() + static_cast<long>(validation_count), all.end());

  SelfTrainResult result;
  std::vector<float> best_weights;
  int first_epoch = 1;
  const std::string best_path = options.checkpoint_path + ".best";
  if (resume && !options.checkpoint_path.empty() && std::filesystem::exists(options.checkpoint_path)) {
    const json state = json::parse(detector.LoadCheckpoint(options.checkpoint_path));
    first_epoch = state.at("epoch").get<int>() + 1;
    result.best_epoch = state.at("best_epoch");
    result.best_validation_percent_oc = state.at("best_validation_percent_oc");
    result.best_validation_detection_error = state.at("best_validation_detection_error");
    result.initial_validation_percent_oc = state.at("initial_validation_percent_oc");
    for (const auto& log : state.at("logs")) result.epochs.push_back(LogFromJson(log));
    best_weights = LoadWeights(best_path, detector.GetWeights().size());
  } else {
    const CertifiedFraction initial = MeasureCertified(object, validation, detector, options.pipeline);
    result.initial_validation_percent_oc = initial.percent_oc;
    result.best_validation_percent_oc = initial.percent_oc;
    result.best_validation_detection_error = initial.detection_error;
    best_weights = detector.GetWeights();
  }

  const std::size_t progress_total = train.size() * static_cast<std::size_t>(options.epochs);
  for (int epoch = first_epoch; epoch <= options.epochs; ++epoch) {
    if (!result.epochs.empty() &&
        result.epochs.back().validation_percent_oc >= options.stop_at_percent_oc) {
      result.stopped_early = true;
      break;
    }
    const auto start = std::chrono::steady_clock::now();
    const std::vector<int> order = Shuffled(train, Rng::ForItem(options.seed, epoch));
    const EpochStats stats = RunEpoch(object, clouds, order, detector, options, progress,
                                      train.size() * (epoch - 1), progress_total, epoch);
    const CertifiedFraction held_out = MeasureCertified(object, validation, detector, options.pipeline);
    SelfTrainEpochLog log;
    log.epoch = epoch;
    log.train_percent_oc = stats.seen ? 100.0 * stats.certified / stats.seen : 0.0;
    log.validation_percent_oc = held_out.percent_oc;
    log.validation_percent_certified = held_out.percent_certified;
    log.validation_detection_error = held_out.detection_error;
    log.loss = stats.steps ? stats.loss_sum / stats.steps : 0.0;
    log.mean_corrector_iterations = stats.seen ? stats.iterations / stats.seen : 0.0;
    log.certified_samples = stats.certified;
    log.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (epoch == 1 && stats.certified == 0) {
      throw InputError("selftrain", "no training cloud was observably correct in the first epoch: nothing to "
                                    "learn from (check eps_oc, the object, or train the detector on sim data first)");
    }
    const bool better = log.validation_percent_oc > result.best_validation_percent_oc ||
                        (log.validation_percent_oc == result.best_validation_percent_oc &&
                         log.validation_detection_error < result.best_validation_detection_error);
    if (better) {
      result.best_validation_percent_oc = log.validation_percent_oc;
      result.best_validation_detection_error = log.validation_detection_error;
      result.best_epoch = epoch;
      best_weights = detector.GetWeights();
    }
    result.epochs.push_back(log);
    if (!options.checkpoint_path.empty()) {
      json state = {{"epoch", epoch}, {"best_epoch", result.best_epoch},
                    {"best_validation_percent_oc", result.best_validation_percent_oc},
                    {"best_validation_detection_error", result.best_validation_detection_error},
                    {"initial_validation_percent_oc", result.initial_validation_percent_oc},
                    {"logs", json::array()}};
      for (const auto& l : result.epochs) state["logs"].push_back(LogJson(l));
      SaveWeights(best_path, best_weights);
      detector.SaveCheckpoint(options.checkpoint_path, state.dump());
    }
    if (on_epoch) on_epoch(log);
  }
  if (!result.epochs.empty() && result.epochs.back().validation_percent_oc >= options.stop_at_percent_oc) {
    result.stopped_early = result.epochs.back().epoch < options.epochs;
  }
  detector.SetWeights(best_weights);
  return result;
}

}  // namespace c3po
