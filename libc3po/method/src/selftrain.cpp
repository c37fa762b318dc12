#include "c3po/method/selftrain.hpp"

#include "c3po/method/model_symmetries.hpp"

#include <algorithm>
#include <cstring>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <type_traits>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/base/json.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/method/model_symmetries.hpp"
#include "c3po/base/random.hpp"
#include "c3po/geometry/distances.hpp"
#include "c3po/method/selftrain_inputs.hpp"

namespace c3po {

namespace {

// The free-space test of cloud i's frame (frames: nullptr or one per cloud).
std::optional<FreeSpaceTest> FrameTest(const ObjectModel& object, const std::vector<DepthView>* frames,
                                       std::size_t i, const PipelineOptions& pipeline) {
  return MakeFreeSpaceTest(object, frames != nullptr ? (*frames)[i] : DepthView{}, pipeline.certificate.free_space,
                           pipeline.certificate.eps_oc);
}

}  // namespace

void SelfTrainOptions::Check() const {
  if (epochs < 1) throw std::invalid_argument("epochs must be >= 1");
  if (batch < 1) throw std::invalid_argument("batch must be >= 1");
  if (!(validation_fraction > 0 && validation_fraction < 1)) {
    throw std::invalid_argument("validation fraction must be in (0, 1)");
  }
  if (!(residual_tolerance >= 0 && std::isfinite(residual_tolerance))) {
    throw std::invalid_argument("residual tolerance must be >= 0");
  }
  if (patience < 0) throw std::invalid_argument("patience must be >= 0");
  pseudo_labels.Check();
  pipeline.Check();
}

bool FitsObservation(const PoseEstimate& estimate) {
  return estimate.ok() && estimate.certificate.fits_observation();
}

CertifiedFraction MeasureCertified(const ObjectModel& object, const std::vector<PointSet>& clouds,
                                   const Detector& detector, const PipelineOptions& options, bool auto_eps_oc,
                                   const std::vector<DepthView>* frames) {
  CertifiedFraction result;
  if (clouds.empty()) return result;
  // The detector sees the clouds as one batch (DetectBatch); CertifyBatch
  // certifies them with the detections as given keypoints.
  CertifyBatchOptions batch;
  batch.pipeline = options;
  batch.auto_eps_oc = auto_eps_oc;
  CertifyBatchResult certified =
      CertifyBatch(object, InMemorySources(clouds, detector.DetectBatch(clouds), frames), nullptr, batch);
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

// Linear-interpolation quantile; 0 for no values.
double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double position = q * static_cast<double>(values.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(values.size() - 1, below + 1);
  return values[below] + (position - static_cast<double>(below)) * (values[above] - values[below]);
}

double RotationAngleDegrees(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double cosine = std::clamp(((a.transpose() * b).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(cosine) * 180.0 / M_PI;
}

}  // namespace

ValidationFit MeasureValidationFit(const ObjectModel& object, const std::vector<PointSet>& clouds,
                                   const Detector& detector, const PipelineOptions& pipeline,
                                   const PseudoLabelOptions& pseudo_labels, const std::vector<Pose>* truth,
                                   const std::vector<Pose>& symmetries, const std::vector<DepthView>* frames) {
  ValidationFit fit;
  if (clouds.empty()) return fit;
  // The detector is validated as it is used: without the re-estimation's
  // restarts (GlobalUniquenessOptions::reestimate), which would rescue a
  // refuted estimate whatever the detector said and hide its regressions
  // (method.md "Self-training: epoch selection"). Training still uses them.
  PipelineOptions as_detected = pipeline;
  as_detected.certificate.global.reestimate = false;
  const CertifiedFraction measured = MeasureCertified(object, clouds, detector, as_detected, false, frames);
  fit.percent_oc = measured.percent_oc;
  fit.percent_certified = measured.percent_certified;
  fit.detection_error = measured.detection_error;
  const PrincipalFrame frame = ModelPrincipalFrame(object);
  std::vector<double> residuals;
  std::vector<char> identified(clouds.size(), 0), ambiguous(clouds.size(), 0);
  ParallelFor(0, static_cast<int>(clouds.size()), [&](int i) {
    const PoseEstimate& e = measured.estimates[i];
    if (!e.ok()) return;
    PseudoLabelOptions options = pseudo_labels;
    options.check_ambiguity = pseudo_labels.check_ambiguity && FitsObservation(e);
    const std::optional<FreeSpaceTest> free_space = FrameTest(object, frames, i, pipeline);
    const PseudoLabelCheck check =
        CheckPseudoLabel(object, clouds[i], e, as_detected, options, frame, free_space ? &*free_space : nullptr);
    ambiguous[i] = check.ambiguous;
    identified[i] = FitsObservation(e) && !check.ambiguous;
  });
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    // The fit residual of the clouds the certificate accepts as this object
    // (oc and free space): in mixed data the other objects' clouds, refused,
    // would otherwise set the median (75 % of a real mixed split).
    if (FitsObservation(measured.estimates[i])) {
      residuals.push_back(FitResidual(object, clouds[i], measured.estimates[i].scene_from_model));
    }
    fit.ambiguous += ambiguous[i];
    fit.percent_identified += identified[i];
  }
  fit.percent_identified *= 100.0 / static_cast<double>(clouds.size());
  fit.residual_q50 = Quantile(residuals, 0.5);
  fit.residual_q90 = Quantile(residuals, 0.9);
  if (truth != nullptr && truth->size() == clouds.size()) {
    // Hausdorff distance between the posed surfaces (~500 model points as
    // queries, distances to the mesh: a symmetry of the shape costs nothing).
    const PointSet queries = StridedColumns(object.sample(), 500);
    std::vector<double> rotation, hausdorff;
    for (std::size_t i = 0; i < clouds.size(); ++i) {
      const Pose& estimate = measured.estimates[i].scene_from_model;
      rotation.push_back(RotationAngleDegrees(NearestSymmetricTruth((*truth)[i], estimate, symmetries).R, estimate.R));
      hausdorff.push_back(PosedSurfaceHausdorff(object, queries, (*truth)[i], estimate));
    }
    fit.rotation_error_median = Quantile(rotation, 0.5);
    fit.hausdorff_median = Quantile(hausdorff, 0.5);
  }
  return fit;
}

namespace {

using nlohmann::json;

std::vector<int> Shuffled(std::vector<int> indices, Rng rng) {
  for (int i = static_cast<int>(indices.size()) - 1; i > 0; --i) {
    std::swap(indices[i], indices[rng.UniformInt(i + 1)]);
  }
  return indices;
}

#define C3PO_SELFTRAIN_LOG_FIELDS(X)                                                          \
  X(epoch) X(train_percent_oc) X(validation_percent_oc) X(validation_percent_certified)      \
  X(validation_detection_error) X(loss) X(mean_corrector_iterations) X(certified_samples)   \
  X(ambiguous_skipped) X(symmetric_trained) X(labelling_switched) X(validation_percent_identified) X(validation_ambiguous)             \
  X(validation_residual_q50) X(validation_residual_q90) X(rolled_back)                      \
  X(validation_rotation_error_median) X(validation_hausdorff_median) X(seconds)

json LogJson(const SelfTrainEpochLog& log) {
  json j;
#define C3PO_WRITE(field) j[#field] = log.field;
  C3PO_SELFTRAIN_LOG_FIELDS(C3PO_WRITE)
#undef C3PO_WRITE
  j["ambiguous_surface_q50"] = log.ambiguous_surface_q50;
  return j;
}

// One field of a checkpoint's resume state (a reader of a file the user
// hands back): integers through IntegerInRange, since converting a JSON float
// such as 1e300 to int is undefined behaviour; other types by nlohmann (its
// type errors become an InputError naming the checkpoint where SelfTrain
// reads the state).
template <class T>
void ReadStateField(const json& j, const char* key, T* out, const std::string& where) {
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    *out = static_cast<T>(IntegerInRange(j.at(key), std::numeric_limits<int>::min(),
                                         std::numeric_limits<int>::max(), where, key));
  } else {
    j.at(key).get_to(*out);
  }
}

SelfTrainEpochLog LogFromJson(const json& j, const std::string& where) {
  SelfTrainEpochLog log;
#define C3PO_READ(field) ReadStateField(j, #field, &log.field, where);
  C3PO_SELFTRAIN_LOG_FIELDS(C3PO_READ)
#undef C3PO_READ
  // Added 2026-12-01: checkpoints written before lack it (then -1).
  if (j.contains("ambiguous_surface_q50")) ReadStateField(j, "ambiguous_surface_q50", &log.ambiguous_surface_q50, where);
  return log;
}

json FitJson(const ValidationFit& f) {
  return {{"percent_oc", f.percent_oc}, {"percent_certified", f.percent_certified},
          {"percent_identified", f.percent_identified}, {"ambiguous", f.ambiguous},
          {"detection_error", f.detection_error}, {"residual_q50", f.residual_q50},
          {"residual_q90", f.residual_q90}, {"rotation_error_median", f.rotation_error_median},
          {"hausdorff_median", f.hausdorff_median}};
}

ValidationFit FitFromJson(const json& j, const std::string& where) {
  ValidationFit f;
  ReadStateField(j, "percent_oc", &f.percent_oc, where);
  ReadStateField(j, "percent_certified", &f.percent_certified, where);
  ReadStateField(j, "percent_identified", &f.percent_identified, where);
  ReadStateField(j, "ambiguous", &f.ambiguous, where);
  ReadStateField(j, "detection_error", &f.detection_error, where);
  ReadStateField(j, "residual_q50", &f.residual_q50, where);
  ReadStateField(j, "residual_q90", &f.residual_q90, where);
  ReadStateField(j, "rotation_error_median", &f.rotation_error_median, where);
  ReadStateField(j, "hausdorff_median", &f.hausdorff_median, where);
  return f;
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
  int ambiguous = 0;
  int symmetric = 0;   // trained samples with symmetric labellings
  int switched = 0;    // ... whose target was not y* (another labelling was nearer the detection)
  double iterations = 0.0;
  std::vector<double> ambiguous_surface;   // PseudoLabelCheck::rival_surface_distance of the ambiguous
};

// One regression step on the first `count` pending pseudo-labels.
void StepOnPending(TrainableDetector& detector, std::size_t count, std::vector<PointSet>* clouds,
                   std::vector<PointSet>* targets, EpochStats* stats) {
  const std::vector<PointSet> step_clouds(clouds->begin(), clouds->begin() + static_cast<long>(count));
  const std::vector<PointSet> step_targets(targets->begin(), targets->begin() + static_cast<long>(count));
  clouds->erase(clouds->begin(), clouds->begin() + static_cast<long>(count));
  targets->erase(targets->begin(), targets->begin() + static_cast<long>(count));
  stats->loss_sum += detector.TrainStep(step_clouds, step_targets);
  ++stats->steps;
}

// One pass over the training clouds: certify each batch of clouds with the
// current detector and collect the usable pseudo-labels; a regression step
// is taken on every `batch` of pseudo-labels (the remainder at the end of
// the epoch). Steps count pseudo-labels, not clouds: in mixed data the other
// objects' refused clouds do not turn one step into several smaller ones
// (measured on the real mixed run: 4 steps of ~7 samples per epoch instead
// of the object alone's one step of ~29).
EpochStats RunEpoch(const ObjectModel& object, const std::vector<PointSet>& clouds,
                    const std::vector<int>& order, TrainableDetector& detector,
                    const SelfTrainOptions& options, const ProgressCallback& progress,
                    std::size_t progress_offset, std::size_t progress_total, int epoch,
                    std::vector<int>* pseudo_label_uses, const std::vector<DepthView>* frames) {
  EpochStats stats;
  const PrincipalFrame frame = ModelPrincipalFrame(object);
  const auto batch_size = static_cast<std::size_t>(options.batch);
  std::vector<PointSet> pending_clouds, pending_targets;
  for (std::size_t start = 0; start < order.size(); start += options.batch) {
    HoldForInterruptAt(epoch, static_cast<long long>(start / options.batch));
    ThrowIfInterrupted();
    const std::size_t end = std::min(order.size(), start + options.batch);
    std::vector<PointSet> batch;
    std::vector<DepthView> batch_frames;
    for (std::size_t k = start; k < end; ++k) {
      batch.push_back(clouds[order[k]]);
      if (frames != nullptr) batch_frames.push_back((*frames)[order[k]]);
    }
    const std::vector<DepthView>* views = frames != nullptr ? &batch_frames : nullptr;
    const std::vector<PoseEstimate> estimates =
        MeasureCertified(object, batch, detector, options.pipeline, false, views).estimates;
    // Ambiguous pseudo-labels (pseudo_label.hpp) are refused; a sample with
    // symmetric labellings is trained on the one nearest its detection (one
    // step of the symmetry-aware loss min_j ||ỹ - y_j||²).
    std::vector<PseudoLabelCheck> checks(batch.size());
    std::vector<char> usable(batch.size(), 0);
    ParallelFor(0, static_cast<int>(batch.size()), [&](int i) {
      if (!FitsObservation(estimates[i])) return;
      const std::optional<FreeSpaceTest> free_space = FrameTest(object, views, i, options.pipeline);
      checks[i] = CheckPseudoLabel(object, batch[i], estimates[i], options.pipeline, options.pseudo_labels, frame,
                                   free_space ? &*free_space : nullptr);
      usable[i] = !checks[i].ambiguous;
    });
    for (std::size_t i = 0; i < batch.size(); ++i) {
      stats.iterations += estimates[i].correction.iterations;
      stats.certified += FitsObservation(estimates[i]);
      stats.ambiguous += checks[i].ambiguous;
      if (checks[i].ambiguous) stats.ambiguous_surface.push_back(checks[i].rival_surface_distance);
      if (usable[i]) {
        ++(*pseudo_label_uses)[static_cast<std::size_t>(order[start + i])];
        pending_clouds.push_back(batch[i]);
        // Pseudo-label: the corrected keypoints, or the symmetric labelling nearest the detection.
        const PointSet& target = NearestLabelling(estimates[i].detected_keypoints, estimates[i].keypoints,
                                                  checks[i].symmetric_labellings);
        stats.symmetric += !checks[i].symmetric_labellings.empty();
        stats.switched += &target != &estimates[i].keypoints;
        pending_targets.push_back(target);
      }
    }
    stats.seen += static_cast<int>(batch.size());
    while (pending_clouds.size() >= batch_size) {
      StepOnPending(detector, batch_size, &pending_clouds, &pending_targets, &stats);
    }
    if (progress) progress(progress_offset + end, progress_total);
  }
  if (!pending_clouds.empty()) {
    StepOnPending(detector, pending_clouds.size(), &pending_clouds, &pending_targets, &stats);
  }
  return stats;
}

}  // namespace

std::string ToJson(const SelfTrainEpochLog& log) { return LogJson(log).dump(); }

namespace {

// Label-free comparison of a validation fit against the best so far
// (method.md "Self-training: epoch selection"). Worse: fewer identified
// clouds, or the median fit residual up by more than the tolerance, or the
// detected keypoints far further from their corrections (the detector's
// agreement with its own pseudo-labels) than the best epoch's. Better: not
// worse, and more identified clouds, or as many with better agreement.
// The residual and agreement rules compare two fits only when both accepted
// some clouds (a quantile of none, an RMS over none, is 0: a detector that
// starts with no oc validation cloud must not make every later one worse).
bool Worse(const ValidationFit& candidate, const ValidationFit& best, double residual_tolerance, double eps_oc) {
  const bool residuals = candidate.residual_q50 > 0.0 && best.residual_q50 > 0.0;
  const bool agreement = candidate.percent_oc > 0.0 && best.percent_oc > 0.0;
  return candidate.percent_identified < best.percent_identified ||
         (residuals && candidate.residual_q50 > best.residual_q50 * (1.0 + residual_tolerance)) ||
         (agreement && candidate.detection_error > 1.5 * best.detection_error + 0.1 * eps_oc);
}
bool Better(const ValidationFit& candidate, const ValidationFit& best, double residual_tolerance, double eps_oc) {
  if (Worse(candidate, best, residual_tolerance, eps_oc)) return false;
  if (candidate.percent_identified != best.percent_identified) return true;
  if (candidate.detection_error != best.detection_error) return candidate.detection_error < best.detection_error;
  return candidate.residual_q50 < best.residual_q50;
}

// The held-out clouds (their frames and reference poses where given) and the training indices.
struct HeldOut {
  std::vector<PointSet> clouds;
  std::vector<Pose> truth;
  std::vector<DepthView> frames;
  std::vector<int> train;
};

HeldOut SplitHeldOut(const std::vector<PointSet>& clouds, const SelfTrainOptions& options,
                     const SelfTrainReference* reference, const std::vector<int>* groups,
                     const std::vector<DepthView>* frames) {
  // The split (by group when given): selftrain_inputs.hpp SplitValidation.
  const ValidationSplit split =
      SplitValidation(clouds.size(), groups, options.validation_fraction, options.seed, "selftrain");
  HeldOut held_out;
  for (const int k : split.validation) {
    held_out.clouds.push_back(clouds[k]);
    if (frames != nullptr) held_out.frames.push_back((*frames)[k]);
    if (reference != nullptr) held_out.truth.push_back(reference->scene_from_model[k]);
  }
  held_out.train = split.train;
  return held_out;
}

void CheckSelfTrainInputs(std::size_t clouds, const SelfTrainReference* reference, const std::vector<int>* groups,
                          const std::vector<DepthView>* frames) {
  if (clouds < 2) throw InputError("selftrain", "need at least 2 unlabelled clouds");
  if (reference != nullptr && reference->scene_from_model.size() != clouds) {
    throw std::invalid_argument("SelfTrain: reference poses must match the clouds");
  }
  if (groups != nullptr && groups->size() != clouds) {
    throw std::invalid_argument("SelfTrain: groups must match the clouds");
  }
  if (frames != nullptr && frames->size() != clouds) {
    throw std::invalid_argument("SelfTrain: frames must match the clouds");
  }
}

// Where a run resumes: the epoch after the checkpoint's, and the count of epochs without a new best.
struct ResumePoint {
  int first_epoch = 1;
  int stale = 0;
};

// Reads the checkpoint's state into `result` (epochs so far, best and initial fits, pseudo-label uses).
ResumePoint ReadCheckpointState(const std::string& where, const std::string& text, std::size_t clouds,
                                SelfTrainResult* result) {
  ResumePoint resume;
  try {
    const json state = json::parse(text);
    ReadStateField(state, "epoch", &resume.first_epoch, where);
    resume.first_epoch += 1;
    ReadStateField(state, "best_epoch", &result->best_epoch, where);
    ReadStateField(state, "best_validation_percent_oc", &result->best_validation_percent_oc, where);
    ReadStateField(state, "best_validation_detection_error", &result->best_validation_detection_error, where);
    ReadStateField(state, "initial_validation_percent_oc", &result->initial_validation_percent_oc, where);
    result->initial = FitFromJson(state.at("initial"), where);
    result->best = FitFromJson(state.at("best"), where);
    ReadStateField(state, "stale", &resume.stale, where);
    for (const auto& log : state.at("logs")) result->epochs.push_back(LogFromJson(log, where));
    const json uses = state.value("pseudo_label_uses", json::array());
    if (uses.size() == clouds) {
      for (std::size_t i = 0; i < uses.size(); ++i) {
        result->pseudo_label_uses[i] =
            static_cast<int>(IntegerInRange(uses[i], 0, std::numeric_limits<int>::max(), where, "pseudo_label_uses"));
      }
    }
  } catch (const json::exception& e) {
    throw InputError(where, std::string("corrupt self-training state: ") + e.what());
  }
  return resume;
}

void WriteCheckpoint(const SelfTrainOptions& options, const SelfTrainResult& result, int epoch, int stale,
                     const std::vector<float>& best_weights, TrainableDetector& detector) {
  json state = {{"epoch", epoch}, {"best_epoch", result.best_epoch},
                {"best_validation_percent_oc", result.best_validation_percent_oc},
                {"best_validation_detection_error", result.best_validation_detection_error},
                {"initial_validation_percent_oc", result.initial_validation_percent_oc},
                {"initial", FitJson(result.initial)}, {"best", FitJson(result.best)}, {"stale", stale},
                {"logs", json::array()}, {"pseudo_label_uses", result.pseudo_label_uses}};
  for (const auto& l : result.epochs) state["logs"].push_back(LogJson(l));
  SaveWeights(options.checkpoint_path + ".best", best_weights);
  detector.SaveCheckpoint(options.checkpoint_path, state.dump());
}

// The epoch's log line from its training statistics and the held-out fit.
SelfTrainEpochLog EpochLog(int epoch, const EpochStats& stats, const ValidationFit& held_out) {
  SelfTrainEpochLog log;
  log.epoch = epoch;
  log.train_percent_oc = stats.seen ? 100.0 * stats.certified / stats.seen : 0.0;
  log.validation_percent_oc = held_out.percent_oc;
  log.validation_percent_certified = held_out.percent_certified;
  log.validation_detection_error = held_out.detection_error;
  log.loss = stats.steps ? stats.loss_sum / stats.steps : 0.0;
  log.mean_corrector_iterations = stats.seen ? stats.iterations / stats.seen : 0.0;
  log.certified_samples = stats.certified;
  log.ambiguous_skipped = stats.ambiguous;
  log.symmetric_trained = stats.symmetric;
  log.labelling_switched = stats.switched;
  if (!stats.ambiguous_surface.empty()) log.ambiguous_surface_q50 = Quantile(stats.ambiguous_surface, 0.5);
  log.validation_percent_identified = held_out.percent_identified;
  log.validation_ambiguous = held_out.ambiguous;
  log.validation_residual_q50 = held_out.residual_q50;
  log.validation_residual_q90 = held_out.residual_q90;
  log.validation_rotation_error_median = held_out.rotation_error_median;
  log.validation_hausdorff_median = held_out.hausdorff_median;
  return log;
}

// A fresh run: the detector as given is the initial and best fit.
ResumePoint Start(const ValidationFit& initial, const TrainableDetector& detector, SelfTrainResult* result,
                  std::vector<float>* best_weights) {
  result->initial = initial;
  result->best = initial;
  result->initial_validation_percent_oc = initial.percent_oc;
  result->best_validation_percent_oc = initial.percent_oc;
  result->best_validation_detection_error = initial.detection_error;
  *best_weights = detector.GetWeights();
  return ResumePoint{};
}

// A resumed run: the checkpoint's weights, state and best weights.
ResumePoint Resume(const SelfTrainOptions& options, std::size_t clouds, TrainableDetector& detector,
                   SelfTrainResult* result, std::vector<float>* best_weights) {
  const std::string& where = options.checkpoint_path;
  const ResumePoint at = ReadCheckpointState(where, detector.LoadCheckpoint(where), clouds, result);
  *best_weights = LoadWeights(where + ".best", detector.GetWeights().size());
  return at;
}

// After an epoch: a better held-out fit becomes the best (its weights kept); a worse one rolls the
// detector back to the best weights (returns true). `stale` counts the epochs since the last best.
bool KeepOrRollBack(const ValidationFit& fit, int epoch, const SelfTrainOptions& options,
                    TrainableDetector& detector, SelfTrainResult* result, std::vector<float>* best_weights,
                    int* stale) {
  const double eps_oc = options.pipeline.certificate.eps_oc;
  if (Better(fit, result->best, options.residual_tolerance, eps_oc)) {
    result->best = fit;
    result->best_validation_percent_oc = fit.percent_oc;
    result->best_validation_detection_error = fit.detection_error;
    result->best_epoch = epoch;
    *best_weights = detector.GetWeights();
    *stale = 0;
    return false;
  }
  ++*stale;
  if (!Worse(fit, result->best, options.residual_tolerance, eps_oc)) return false;
  detector.SetWeights(*best_weights);   // roll back: continue from the best epoch
  return true;
}

}  // namespace

SelfTrainResult SelfTrain(const ObjectModel& object, const std::vector<PointSet>& clouds,
                          TrainableDetector& detector, const SelfTrainOptions& options,
                          const EpochCallback& on_epoch, const ProgressCallback& progress,
                          bool resume, const SelfTrainReference* reference, const std::vector<int>* groups,
                          const std::vector<DepthView>* frames) {
  options.Check();
  CheckSelfTrainInputs(clouds.size(), reference, groups, frames);
  const HeldOut held_out = SplitHeldOut(clouds, options, reference, groups, frames);
  const std::vector<int>& train = held_out.train;
  const auto measure = [&] {
    return MeasureValidationFit(object, held_out.clouds, detector, options.pipeline, options.pseudo_labels,
                                reference != nullptr ? &held_out.truth : nullptr,
                                reference != nullptr ? reference->symmetries : std::vector<Pose>{},
                                frames != nullptr ? &held_out.frames : nullptr);
  };

  SelfTrainResult result;
  result.pseudo_label_uses.assign(clouds.size(), 0);
  std::vector<float> best_weights;
  const bool resuming =
      resume && !options.checkpoint_path.empty() && std::filesystem::exists(options.checkpoint_path);
  const ResumePoint at = resuming ? Resume(options, clouds.size(), detector, &result, &best_weights)
                                  : Start(measure(), detector, &result, &best_weights);

  const std::size_t progress_total = train.size() * static_cast<std::size_t>(options.epochs);
  int stale = at.stale;   // epochs in a row without a new best
  for (int epoch = at.first_epoch; epoch <= options.epochs; ++epoch) {
    if (!result.epochs.empty() &&
        (result.best.percent_identified >= options.stop_at_percent_oc ||
         (options.patience > 0 && stale >= options.patience))) {
      result.stopped_early = true;
      break;
    }
    const auto start = std::chrono::steady_clock::now();
    const std::vector<int> order = Shuffled(train, Rng::ForItem(options.seed, epoch));
    const EpochStats stats = RunEpoch(object, clouds, order, detector, options, progress,
                                      train.size() * (epoch - 1), progress_total, epoch,
                                      &result.pseudo_label_uses, frames);
    if (epoch == 1 && stats.certified == 0) {
      throw InputError("selftrain", "no training cloud was observably correct in the first epoch: nothing to "
                                    "learn from (check eps_oc, the object, or train the detector on sim data first)");
    }
    const ValidationFit fit = measure();
    SelfTrainEpochLog log = EpochLog(epoch, stats, fit);
    log.rolled_back = KeepOrRollBack(fit, epoch, options, detector, &result, &best_weights, &stale);
    log.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.epochs.push_back(log);
    if (!options.checkpoint_path.empty()) WriteCheckpoint(options, result, epoch, stale, best_weights, detector);
    if (on_epoch) on_epoch(log);
  }
  detector.SetWeights(best_weights);
  return result;
}

}  // namespace c3po
