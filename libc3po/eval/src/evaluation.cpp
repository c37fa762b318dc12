// Evaluation of the paper's table rows on a dataset with ground truth.
#include "c3po/eval/evaluation.hpp"

#include "c3po/method/model_symmetries.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "c3po/base/error.hpp"
#include "c3po/method/certificate.hpp"
#include "c3po/method/certify_batch.hpp"
#include "c3po/method/keypoint_ransac.hpp"
#include "c3po/method/model_symmetries.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/method/refusal.hpp"

namespace c3po {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The three estimates of one detector on one cloud, indexed by Stage.
enum Stage { kRegistration = 0, kIcp = 1, kCorrected = 2, kRansacIcp = 3, kStages = 4 };

using DetectorResults = std::vector<std::vector<SampleResult>>;   // [stage][cloud]

SampleResult Failure(std::size_t index, const std::string& cloud, const std::string& why) {
  SampleResult sample;
  sample.index = index;
  sample.cloud = cloud;
  sample.error = why;
  sample.adds = kInf;
  sample.rotation_error = M_PI;
  sample.translation_error = kInf;
  sample.oc_distance = kInf;
  return sample;
}

// Errors of an estimate against the ground truth (a non-finite pose is a failure).
void ScoreAgainstTruth(const ObjectModel& object, const Pose& truth, const EvaluationOptions& options,
                       SampleResult* sample) {
  if (!sample->ok()) return;
  if (!sample->scene_from_model.IsFinite()) {
    const SampleResult failed = Failure(sample->index, sample->cloud, "non-finite pose");
    *sample = failed;
    return;
  }
  sample->adds = AddS(object.tree(), truth, sample->scene_from_model, options.adds_variant);
  const Pose nearest = NearestSymmetricTruth(truth, sample->scene_from_model, options.symmetries);
  sample->rotation_error = RotationError(sample->scene_from_model.R, nearest.R);
  sample->translation_error = TranslationError(sample->scene_from_model.t, nearest.t);
  if (sample->certified()) {
    sample->hausdorff = PosedModelHausdorff(object, StridedColumns(object.sample(), 2000), truth,
                                            sample->scene_from_model);
  }
}

// The certificate's decisions and the evidence a report shows.
void SetCertificate(const Certificate& certificate, SampleResult* sample) {
  sample->oc = certificate.oc.passed;
  sample->nd = certificate.nd.passed;
  sample->free_space = !certificate.free_space.refutes();
  sample->oc_distance = certificate.oc.max_point_distance;
  sample->outlier_indices = certificate.oc.outlier_indices;
  sample->refusal = RefusalSummary(certificate);
  const GlobalUniqueness& global = certificate.nd.global;
  sample->rival_scene_from_model.reset();
  if (certificate.nd.global_checked && !global.passed && global.rival_axis >= 0) {
    sample->rival_scene_from_model = global.rival_scene_from_model;
  }
}

SampleResult FromEstimate(std::size_t index, const std::string& cloud, const PoseEstimate& estimate) {
  if (!estimate.ok()) {
    SampleResult failed = Failure(index, cloud, std::string("registration failed: ") +
                                                    ToString(estimate.correction.registration));
    failed.detected_keypoints = estimate.detected_keypoints;
    return failed;
  }
  SampleResult sample;
  sample.index = index;
  sample.cloud = cloud;
  sample.scene_from_model = estimate.scene_from_model;
  sample.keypoints = estimate.keypoints;
  sample.detected_keypoints = estimate.detected_keypoints;
  SetCertificate(estimate.certificate, &sample);
  sample.milliseconds = estimate.milliseconds;
  return sample;
}

// "KeyPo + ICP": ICP from the registration, certified with keypoints T·b.
SampleResult RefineAndCertify(const ObjectModel& object, const PointSet& cloud,
                              const SampleResult& registration, const EvaluationOptions& options,
                              const FreeSpaceTest* free_space, bool ransac = false) {
  if (!registration.ok()) {
    SampleResult failed = Failure(registration.index, registration.cloud, registration.error);
    failed.detected_keypoints = registration.detected_keypoints;
    return failed;
  }
  const auto start = std::chrono::steady_clock::now();
  Pose initial = registration.scene_from_model;
  if (ransac) {
    // "KeyPo + RANSAC + ICP": RANSAC over triples of (ỹ_i, b_i) replaces eq. (8) on all of ỹ.
    const KeypointRansacResult fit =
        RegisterKeypointsRansac(object.keypoints(), registration.detected_keypoints, options.ransac);
    if (!fit.ok()) {
      SampleResult failed = Failure(registration.index, registration.cloud, "ransac: " + fit.failure);
      failed.detected_keypoints = registration.detected_keypoints;
      return failed;
    }
    initial = fit.scene_from_model;
  }
  const IcpResult icp = RefineIcp(object, cloud, initial, options.icp);
  if (!icp.ok()) {
    SampleResult failed = Failure(registration.index, registration.cloud, "icp: " + icp.failure);
    failed.detected_keypoints = registration.detected_keypoints;
    return failed;
  }
  SampleResult sample = registration;
  sample.scene_from_model = icp.scene_from_model;
  sample.keypoints = icp.scene_from_model * object.keypoints();
  PoseEstimate refined;   // the whole certificate, with the global rival search (pipeline.hpp)
  refined.scene_from_model = sample.scene_from_model;
  refined.keypoints = sample.keypoints;
  refined.certificate = Certify(object, cloud, sample.scene_from_model, sample.keypoints,
                                options.pipeline.certificate);
  CompleteCertificate(object, cloud, options.pipeline, free_space, &refined);
  SetCertificate(refined.certificate, &sample);
  sample.milliseconds = registration.milliseconds +
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return sample;
}

// One detector on every cloud: CertifyBatch certifies the corrected estimate
// (and, for a detector that is not self-trained, the plain registration T(ỹ));
// the visitor adds "+ ICP" while the cloud is in memory and scores every
// stage against the ground truth. Clouds that could not be read or whose
// detection failed are failures of every stage.
DetectorResults EvaluateDetector(const ObjectModel& object, const Dataset& dataset,
                                 const std::vector<CloudSource>& sources, const EvaluatedDetector& detector,
                                 const EvaluationOptions& options, const ProgressCallback& progress) {
  const std::size_t count = sources.size();
  DetectorResults out(kStages, std::vector<SampleResult>(count));
  CertifyBatchOptions batch;
  batch.pipeline = options.pipeline;
  batch.pipeline.correct = true;
  batch.also_uncorrected = !detector.self_trained;
  const auto visit = [&](std::size_t i, const PointSet& cloud, const FreeSpaceTest* free_space,
                         CloudOutcome* outcome) {
    const std::string& name = dataset.entries[i].cloud;
    const Pose& truth = *dataset.entries[i].pose;
    if (outcome->uncorrected) {
      out[kRegistration][i] = FromEstimate(i, name, *outcome->uncorrected);
      ScoreAgainstTruth(object, truth, options, &out[kRegistration][i]);
      if (options.run_icp) {
        out[kIcp][i] = RefineAndCertify(object, cloud, out[kRegistration][i], options, free_space);
        ScoreAgainstTruth(object, truth, options, &out[kIcp][i]);
        if (options.run_ransac) {
          out[kRansacIcp][i] = RefineAndCertify(object, cloud, out[kRegistration][i], options, free_space, true);
          ScoreAgainstTruth(object, truth, options, &out[kRansacIcp][i]);
        }
      }
    }
    out[kCorrected][i] = FromEstimate(i, name, outcome->estimate);
    ScoreAgainstTruth(object, truth, options, &out[kCorrected][i]);
  };
  const CertifyBatchResult result = CertifyBatch(object, sources, detector.detector, batch, progress, visit);
  for (std::size_t i = 0; i < count; ++i) {
    const CloudOutcome& outcome = result.outcomes[i];
    if (outcome.processed()) continue;
    const std::string why =
        outcome.failure == CloudOutcome::Failure::kDetect ? "detector: " + outcome.error : outcome.error;
    for (int s = 0; s < kStages; ++s) out[s][i] = Failure(i, dataset.entries[i].cloud, why);
  }
  return out;
}

// The indices of the dataset's clouds that show `object` (all of them unless
// the set is mixed).
std::vector<std::size_t> OwnIndices(const ObjectModel& object, const Dataset& dataset) {
  std::vector<std::size_t> own;
  for (std::size_t i = 0; i < dataset.entries.size(); ++i) {
    if (dataset.Shows(i, object.name())) own.push_back(i);
  }
  return own;
}

void AppendRows(const EvaluatedDetector& detector, DetectorResults results,
                const EvaluationOptions& options, double diameter, std::vector<EvaluationRow>* rows) {
  const std::string& label = detector.label;
  if (detector.self_trained) {
    for (EvalSubset subset : {EvalSubset::kAll, EvalSubset::kObservablyCorrect, EvalSubset::kCertified}) {
      rows->push_back(MakeEvaluationRow(EvalMethod::kC3po, subset, label, results[kCorrected], options, diameter));
    }
    return;
  }
  rows->push_back(MakeEvaluationRow(EvalMethod::kKeyPo, EvalSubset::kAll, label, std::move(results[kRegistration]),
                          options, diameter));
  if (options.run_icp) {
    rows->push_back(MakeEvaluationRow(EvalMethod::kKeyPoIcp, EvalSubset::kAll, label, std::move(results[kIcp]),
                            options, diameter));
    if (options.run_ransac) {
      rows->push_back(MakeEvaluationRow(EvalMethod::kKeyPoRansacIcp, EvalSubset::kAll, label,
                              std::move(results[kRansacIcp]), options, diameter));
    }
  }
  rows->push_back(MakeEvaluationRow(EvalMethod::kKeyPoCorrector, EvalSubset::kAll, label,
                          std::move(results[kCorrected]), options, diameter));
}

double Percent(int count, int n) { return n > 0 ? 100.0 * count / n : kNaN; }

}  // namespace

void EvaluationOptions::Check() const {
  if (!(adds_threshold > 0) || !std::isfinite(adds_threshold)) {
    throw std::invalid_argument("EvaluationOptions: adds_threshold must be positive and finite");
  }
  if (!(auc_max > 0) || !std::isfinite(auc_max)) {
    throw std::invalid_argument("EvaluationOptions: auc_max must be positive and finite");
  }
  if (worst_listed < 0) throw std::invalid_argument("EvaluationOptions: worst_listed must be >= 0");
  for (const Pose& symmetry : symmetries) {
    if (!symmetry.IsFinite()) throw std::invalid_argument("EvaluationOptions: non-finite symmetry");
  }
  pipeline.Check();
  if (run_icp) icp.Check();
  if (run_icp && run_ransac) ransac.Check();
}

EvaluationOptions EvaluationOptions::Defaults(const ObjectModel& object) {
  EvaluationOptions options;
  options.adds_threshold = 0.05 * object.diameter();
  options.auc_max = 0.10 * object.diameter();
  options.pipeline.certificate = CertificateOptions::FromObject(object.spec());
  options.ransac.inlier_threshold = 0.05 * object.diameter();
  return options;
}

const char* ToString(EvalMethod method) {
  switch (method) {
    case EvalMethod::kKeyPo: return "keypo";
    case EvalMethod::kKeyPoIcp: return "keypo+icp";
    case EvalMethod::kKeyPoRansacIcp: return "keypo+ransac+icp";
    case EvalMethod::kKeyPoCorrector: return "keypo+corrector";
    case EvalMethod::kC3po: return "c3po";
  }
  return "?";
}

const char* ToString(EvalSubset subset) {
  switch (subset) {
    case EvalSubset::kAll: return "all";
    case EvalSubset::kObservablyCorrect: return "oc=1";
    case EvalSubset::kCertified: return "oc=nd=1";
  }
  return "?";
}

std::string RowLabel(EvalMethod method, EvalSubset subset, const std::string& detector_label) {
  std::string label;
  switch (method) {
    case EvalMethod::kKeyPo: label = "KeyPo (" + detector_label + ")"; break;
    case EvalMethod::kKeyPoIcp: label = "KeyPo (" + detector_label + ") + ICP"; break;
    case EvalMethod::kKeyPoRansacIcp: label = "KeyPo (" + detector_label + ") + RANSAC + ICP"; break;
    case EvalMethod::kKeyPoCorrector: label = "KeyPo (" + detector_label + ") + corrector"; break;
    case EvalMethod::kC3po: label = "C-3PO (" + detector_label + ")"; break;
  }
  if (subset == EvalSubset::kObservablyCorrect) label += " (oc = 1)";
  if (subset == EvalSubset::kCertified) label += " (oc = nd = 1)";
  return label;
}

int Evaluation::total_false_certificates() const {
  int total = 0;
  for (const auto& row : rows) {
    if (row.subset == EvalSubset::kAll) total += row.summary.false_certificates;
  }
  return total;
}

int Evaluation::total_false_certificates_hausdorff() const {
  int total = 0;
  for (const auto& row : rows) {
    if (row.subset == EvalSubset::kAll) total += row.summary.false_certificates_hausdorff;
  }
  return total;
}

int Evaluation::other_objects_accepted() const {
  int accepted = 0;
  for (const ObjectAcceptance& a : objects) accepted += a.evaluated_object ? 0 : a.certified;
  return accepted;
}

const EvaluationRow* Evaluation::MainRow() const {
  for (const auto& row : rows) {
    if (row.method == EvalMethod::kC3po && row.subset == EvalSubset::kAll) return &row;
  }
  for (const auto& row : rows) {
    if (row.method == EvalMethod::kKeyPoCorrector) return &row;
  }
  return rows.empty() ? nullptr : &rows.front();
}

EvaluationRow MakeEvaluationRow(EvalMethod method, EvalSubset subset, const std::string& detector,
                                const std::vector<SampleResult>& all_samples, const EvaluationOptions& options,
                                double diameter) {
  EvaluationRow row;
  row.label = RowLabel(method, subset, detector);
  row.detector = detector;
  row.method = method;
  row.subset = subset;
  for (const auto& s : all_samples) {
    if (subset == EvalSubset::kAll || (subset == EvalSubset::kObservablyCorrect && s.fits_observation()) ||
        (subset == EvalSubset::kCertified && s.certified())) {
      row.samples.push_back(s);
    }
  }
  row.summary = Summarize(row.samples, options, diameter);
  return row;
}

RowSummary Summarize(const std::vector<SampleResult>& samples, const EvaluationOptions& options,
                     double diameter) {
  RowSummary summary;
  summary.n = static_cast<int>(samples.size());
  std::vector<double> adds, rotation, translation;
  int oc = 0, nd = 0;
  std::vector<FalseCertificate> false_certificates;
  for (const auto& s : samples) {
    adds.push_back(s.adds);
    rotation.push_back(s.rotation_error);
    translation.push_back(s.translation_error);
    summary.failures += !s.ok();
    oc += s.oc;
    nd += s.nd;
    summary.certified += s.certified();
    if (s.certified()) {
      summary.false_certificates_hausdorff += !(s.hausdorff < options.adds_threshold);
      if (std::isfinite(s.hausdorff)) {
        summary.max_certified_hausdorff = std::max(summary.max_certified_hausdorff, s.hausdorff);
      }
    }
    if (s.certified() && !(s.adds < options.adds_threshold)) {
      false_certificates.push_back({s.index, s.cloud, s.adds, s.rotation_error, s.translation_error});
    }
  }
  summary.adds_score = ThresholdScore(adds, options.adds_threshold);
  summary.adds_auc = adds.empty() ? kNaN : AddSAuc(adds, options.auc_max);
  summary.median_adds = Median(adds);
  summary.median_rotation_error = Median(rotation);
  summary.median_translation_error = Median(translation);
  summary.median_translation_error_over_d = summary.median_translation_error / diameter;
  summary.percent_oc = Percent(oc, summary.n);
  summary.percent_nd = Percent(nd, summary.n);
  summary.percent_certified = Percent(summary.certified, summary.n);
  summary.false_certificates = static_cast<int>(false_certificates.size());
  std::stable_sort(false_certificates.begin(), false_certificates.end(),
                   [](const FalseCertificate& a, const FalseCertificate& b) { return a.adds > b.adds; });
  if (static_cast<int>(false_certificates.size()) > options.worst_listed) {
    false_certificates.resize(options.worst_listed);
  }
  summary.worst_false_certificates = std::move(false_certificates);
  return summary;
}

void CheckEvaluationDataset(const ObjectModel& object, const Dataset& dataset,
                            const std::vector<EvaluatedDetector>& detectors) {
  const std::string where = dataset.dir + "/manifest.jsonl";
  if (dataset.entries.empty()) throw InputError(where, "the dataset has no clouds");
  const std::vector<std::size_t> own = OwnIndices(object, dataset);
  if (own.empty()) {
    throw InputError(where, "no cloud of object '" + object.name() + "' (every line's \"object\" names another)");
  }
  const bool needs_manifest_keypoints =
      std::any_of(detectors.begin(), detectors.end(), [](const EvaluatedDetector& d) { return !d.detector; });
  for (std::size_t i : own) {
    const DatasetEntry& entry = dataset.entries[i];
    const std::string line = where + ": line " + std::to_string(i + 1) + " (" + entry.cloud + ")";
    if (!entry.pose) throw InputError(line, "no ground-truth pose (\"R\", \"t\"): eval needs ground truth");
    if (needs_manifest_keypoints && !entry.detected_keypoints) {
      throw InputError(line, "--detector manifest needs \"detected_keypoints\"");
    }
  }
}

namespace {

// How the object's own clouds fared with one detector (the corrected samples).
ObjectAcceptance OwnAcceptance(const std::string& detector, const ObjectModel& object,
                               const std::vector<SampleResult>& corrected) {
  ObjectAcceptance own;
  own.detector = detector;
  own.object = object.name();
  own.evaluated_object = true;
  for (const SampleResult& sample : corrected) {
    ++own.clouds;
    own.failures += !sample.ok();
    own.observably_correct += sample.fits_observation();
    own.certified += sample.certified();
  }
  return own;
}

// What the object's certifier accepted of another object's clouds (`members` of `other`).
ObjectAcceptance OtherAcceptance(const std::string& detector, const std::string& label,
                                 const std::vector<std::size_t>& members, const CertifyBatchResult& other) {
  ObjectAcceptance a;
  a.detector = detector;
  a.object = label;
  for (std::size_t i : members) {
    const CloudOutcome& outcome = other.outcomes[i];
    ++a.clouds;
    a.failures += !outcome.processed();
    a.observably_correct +=
        outcome.processed() && outcome.estimate.ok() && outcome.estimate.certificate.fits_observation();
    a.certified += outcome.certified();
  }
  return a;
}

// Mixed datasets, per detector: the object's own clouds, then each other label's clouds certified
// as this object (every one accepted is a false certificate of the segmenter's kind).
std::vector<ObjectAcceptance> AcceptanceByObject(const ObjectModel& object, const Dataset& other_dataset,
                                                 const DatasetFrames& frames,
                                                 const std::vector<EvaluatedDetector>& detectors,
                                                 const std::vector<DetectorResults>& results,
                                                 const EvaluationOptions& options) {
  std::map<std::string, std::vector<std::size_t>> other_by_label;
  for (std::size_t i = 0; i < other_dataset.entries.size(); ++i) {
    other_by_label[*other_dataset.entries[i].object].push_back(i);
  }
  const std::vector<CloudSource> other_sources = DatasetSources(other_dataset, frames);
  CertifyBatchOptions batch;
  batch.pipeline = options.pipeline;
  batch.pipeline.correct = true;
  std::vector<ObjectAcceptance> objects;
  for (std::size_t d = 0; d < detectors.size(); ++d) {
    objects.push_back(OwnAcceptance(detectors[d].label, object, results[d][kCorrected]));
    if (other_sources.empty()) continue;
    // A detector's failure on a cloud (e.g. the manifest's detected
    // keypoints are another object's count) rejects that cloud.
    const CertifyBatchResult other = CertifyBatch(object, other_sources, detectors[d].detector, batch);
    for (const auto& [label, members] : other_by_label) {
      objects.push_back(OtherAcceptance(detectors[d].label, label, members, other));
    }
  }
  return objects;
}

}  // namespace

Evaluation Evaluate(const ObjectModel& object, const Dataset& dataset,
                    const std::vector<EvaluatedDetector>& detectors,
                    const EvaluationOptions& options, const ProgressCallback& progress,
                    const DatasetFrames& frames) {
  options.Check();
  if (detectors.empty()) throw std::invalid_argument("Evaluate: no detectors");
  // Mixed datasets: the object's own clouds make the rows, the others are
  // only certified and counted (per label).
  CheckEvaluationDataset(object, dataset, detectors);
  Dataset own_dataset, other_dataset;
  own_dataset.dir = other_dataset.dir = dataset.dir;
  const std::vector<std::size_t> own_index = OwnIndices(object, dataset);
  for (std::size_t i = 0; i < dataset.entries.size(); ++i) {
    (dataset.Shows(i, object.name()) ? own_dataset : other_dataset).entries.push_back(dataset.entries[i]);
  }
  const std::size_t count = own_dataset.entries.size();
  const std::vector<CloudSource> sources = DatasetSources(own_dataset, frames);
  std::vector<DetectorResults> results;
  for (std::size_t d = 0; d < detectors.size(); ++d) {
    // Progress over all detectors' clouds, reported as clouds of the dataset.
    const ProgressCallback per_detector = [&, d](std::size_t done, std::size_t) {
      if (progress) progress((d * count + done) / detectors.size(), count);
    };
    results.push_back(EvaluateDetector(object, own_dataset, sources, detectors[d], options, per_detector));
  }
  std::vector<ObjectAcceptance> objects;
  if (!other_dataset.entries.empty()) {
    objects = AcceptanceByObject(object, other_dataset, frames, detectors, results, options);
  }

  Evaluation evaluation;
  evaluation.object_name = object.name();
  evaluation.dataset_dir = dataset.dir;
  evaluation.clouds = count;
  evaluation.diameter = object.diameter();
  evaluation.options = options;
  for (std::size_t d = 0; d < detectors.size(); ++d) {
    AppendRows(detectors[d], std::move(results[d]), options, object.diameter(), &evaluation.rows);
  }
  // Sample indices name the dataset's entries, also when others were set aside.
  for (EvaluationRow& row : evaluation.rows) {
    for (SampleResult& sample : row.samples) sample.index = own_index[sample.index];
    for (FalseCertificate& f : row.summary.worst_false_certificates) f.index = own_index[f.index];
  }
  evaluation.objects = std::move(objects);
  return evaluation;
}

}  // namespace c3po
