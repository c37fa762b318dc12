#pragma once
// Evaluation on a dataset with ground truth: the rows of the paper's Tables
// II-IV (Section VIII) for every detector given.
//
// For a detector labelled L, on every cloud X with ground truth T*:
//   "KeyPo (L)"             T(ỹ): registration of the detected keypoints (eq. 8),
//                           certified like any other output (oc, nd);
//   "KeyPo (L) + ICP"       point-to-point ICP against X from T(ỹ) (RefineIcp),
//                           certified with keypoints T·b (agreement check trivial);
//   "KeyPo (L) + RANSAC + ICP"  RANSAC over triples of (ỹ_i, b_i)
//                           (RegisterKeypointsRansac) instead of eq. (8) on all
//                           of ỹ, then the same ICP and certification;
//   "KeyPo (L) + corrector" the corrector (eq. 17) from ỹ, certified.
// For a self-trained detector (Section VII) the corrector rows are named
//   "C-3PO (L)", "C-3PO (L) (oc = 1)", "C-3PO (L) (oc = nd = 1)"
// (all clouds; the observably correct ones; the certified ones).
//
// Per sample: ADD-S (the variant is part of the options and named in every
// output), rotation error, translation error (to the nearest symmetric truth
// when the options list the object's symmetries). A pose that could not be
// estimated (unreadable cloud, detector failure, degenerate keypoints) counts
// as a failure: ADD-S = +inf, rotation error = pi, translation error = +inf,
// oc = nd = 0.
//
// Soundness: a false certificate is a certified sample whose ADD-S is not
// below the ADD-S threshold; every row counts them and lists the worst.
#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "c3po/eval/metrics.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/method/certify_batch.hpp"
#include "c3po/method/detector.hpp"
#include "c3po/method/icp.hpp"
#include "c3po/method/keypoint_ransac.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct EvaluationOptions {
  double adds_threshold = 0.0;     // absolute (object units), e.g. 5 % of d
  double auc_max = 0.0;            // absolute, upper end of the AUC curve, e.g. 10 % of d
  AddSVariant adds_variant = AddSVariant::kSymmetric;
  PipelineOptions pipeline;        // corrector + certificate thresholds (absolute)
  IcpOptions icp;
  bool run_icp = true;             // false: no "+ ICP" rows (nor "+ RANSAC + ICP")
  bool run_ransac = true;          // false: no "+ RANSAC + ICP" rows
  KeypointRansacOptions ransac;    // Defaults: inlier threshold 5 % of d
  int worst_listed = 5;            // false certificates listed per row
  // Rotational symmetries of the object (model_from_model, e.g. from
  // FindModelSymmetries): rotation and translation errors are measured to
  // the nearest of the truth T* and the symmetric truths T*·S (the one with
  // the smallest rotation error); empty = to T* alone. ADD-S and the
  // Hausdorff check need none (distances between posed shapes).
  std::vector<Pose> symmetries;
  void Check() const;              // throws std::invalid_argument
  // Paper defaults: thresholds 5 % and 10 % of d; certificate thresholds of the object.
  static EvaluationOptions Defaults(const ObjectModel& object);
};

// One detector to evaluate.
struct EvaluatedDetector {
  std::string label;                   // "sim", "svd", ...
  const Detector* detector = nullptr;  // nullptr: the manifest's detected_keypoints
  bool self_trained = false;
};

enum class EvalMethod { kKeyPo, kKeyPoIcp, kKeyPoCorrector, kC3po, kKeyPoRansacIcp };
enum class EvalSubset { kAll, kObservablyCorrect, kCertified };
const char* ToString(EvalMethod method);   // "keypo", "keypo+icp", "keypo+corrector", "c3po", "keypo+ransac+icp"
const char* ToString(EvalSubset subset);   // "all", "oc=1", "oc=nd=1"
// "KeyPo (sim) + ICP", "C-3PO (real) (oc = nd = 1)", ...
std::string RowLabel(EvalMethod method, EvalSubset subset, const std::string& detector_label);

struct SampleResult {
  std::size_t index = 0;               // dataset entry
  std::string cloud;                   // manifest name of the cloud
  std::string error;                   // non-empty: no pose (why)
  Pose scene_from_model;               // estimate T̂
  PointSet keypoints;                  // output keypoints (corrected, or T̂·b for ICP)
  PointSet detected_keypoints;         // ỹ
  double adds = 0.0;                   // object units
  double rotation_error = 0.0;         // radians
  double translation_error = 0.0;      // object units
  bool oc = false;
  bool nd = false;
  // The depth frame's free-space test (docs/method.md) passed, or the cloud
  // came without its frame (Evaluate's `frames`).
  bool free_space = true;
  double oc_distance = 0.0;            // max_x min_p ||x - p|| (evidence of oc)
  // Certified samples only (NaN otherwise): the symmetric Hausdorff distance
  // between the model posed at the truth and at T̂ (PosedModelHausdorff, 2000
  // points of B̂), the pose error a certificate must bound (symmetries free).
  double hausdorff = std::numeric_limits<double>::quiet_NaN();
  std::vector<int> outlier_indices;    // input points at >= eps_oc (oc_m's outliers, ascending)
  // Not certified: the failed parts and their evidence (RefusalSummary), and
  // the second pose that explains the points when nd's global rival search
  // refused it (GlobalUniqueness::rival_scene_from_model).
  std::string refusal;
  std::optional<Pose> rival_scene_from_model;
  double milliseconds = 0.0;           // estimation + certification time of this method
  bool ok() const { return error.empty(); }
  bool fits_observation() const { return oc && free_space; }   // Certificate::fits_observation
  bool certified() const { return fits_observation() && nd; }
  // Certified although ADD-S or the Hausdorff distance (NaN counts) is not below `threshold`.
  bool false_certificate(double threshold) const {
    return certified() && !(adds < threshold && hausdorff < threshold);
  }
};

struct FalseCertificate {
  std::size_t index = 0;
  std::string cloud;
  double adds = 0.0;
  double rotation_error = 0.0;         // radians
  double translation_error = 0.0;
};

struct RowSummary {
  int n = 0;                           // samples in the row (the subset)
  int failures = 0;                    // samples without a pose
  double adds_score = 0.0;             // % with ADD-S < adds_threshold (NaN when n = 0)
  double adds_auc = 0.0;               // 0..100 (NaN when n = 0)
  double median_rotation_error = 0.0;  // radians
  double median_translation_error = 0.0;
  double median_translation_error_over_d = 0.0;
  double median_adds = 0.0;
  double percent_oc = 0.0;
  double percent_nd = 0.0;
  double percent_certified = 0.0;
  int certified = 0;
  int false_certificates = 0;          // certified with ADD-S >= adds_threshold
  int false_certificates_hausdorff = 0;   // certified with Hausdorff >= adds_threshold (NaN counts)
  double max_certified_hausdorff = 0.0;   // over the certified samples (0 when none)
  std::vector<FalseCertificate> worst_false_certificates;   // by ADD-S, descending
};

struct EvaluationRow {
  std::string label;                   // RowLabel(...)
  std::string detector;                // detector label
  EvalMethod method = EvalMethod::kKeyPo;
  EvalSubset subset = EvalSubset::kAll;
  std::vector<SampleResult> samples;   // the samples of the subset, dataset order
  RowSummary summary;
};

// Mixed datasets (manifest "object" labels, dataset.hpp): per detector and
// object label, how many clouds detector + corrector + certificates accepted.
// For the evaluated object itself these are its corrector (or C-3PO) row's
// counts; another object's clouds are certified as if they showed the
// evaluated object, and every accepted one is a false certificate in the
// sense of the paper's Section VIII-E (the certificate must reject them).
struct ObjectAcceptance {
  std::string detector;                // detector label
  std::string object;                  // manifest label
  bool evaluated_object = false;       // the object being evaluated
  int clouds = 0;
  int failures = 0;                    // no pose (unreadable cloud, detector failure)
  int observably_correct = 0;
  int certified = 0;                   // accepted: oc and nd
};

struct Evaluation {
  std::string object_name;
  std::string dataset_dir;
  std::size_t clouds = 0;
  double diameter = 0.0;
  EvaluationOptions options;           // absolute thresholds used
  std::vector<EvaluationRow> rows;
  // Datasets with other objects' clouds only (empty otherwise): this object
  // first, then the other labels in name order, for each detector.
  std::vector<ObjectAcceptance> objects;
  int total_false_certificates() const;
  int total_false_certificates_hausdorff() const;
  int other_objects_accepted() const;  // certified clouds of other objects, all detectors
  // The row whose examples a report shows: the first C-3PO row on all clouds,
  // else the first corrector row, else the first row; nullptr without rows.
  const EvaluationRow* MainRow() const;
};

// Summary statistics of a set of samples (any subset).
RowSummary Summarize(const std::vector<SampleResult>& samples, const EvaluationOptions& options,
                     double diameter);

// The row of `method` on `subset` of one detector's samples on all clouds
// (dataset order): the samples of the subset, labelled and summarized.
EvaluationRow MakeEvaluationRow(EvalMethod method, EvalSubset subset, const std::string& detector,
                                const std::vector<SampleResult>& all_samples, const EvaluationOptions& options,
                                double diameter);

// The checks Evaluate makes before any work, for callers that want to fail
// before their own long preparation (eval's symmetry search): InputError
// ("dir/manifest.jsonl: ...") when the dataset has no cloud, no cloud shows
// the object, or a cloud that shows it has no ground-truth pose or, for a
// manifest detector (EvaluatedDetector::detector null), no
// detected_keypoints (naming its line of the manifest).
void CheckEvaluationDataset(const ObjectModel& object, const Dataset& dataset,
                            const std::vector<EvaluatedDetector>& detectors);

// Runs every detector on every cloud of the dataset (in parallel over clouds)
// that shows the object (Dataset::Shows: no label or the object's name; the
// rows' sample indices are the dataset's entries; in a mixed dataset the other
// labels' clouds only fill Evaluation::objects; InputError when no cloud shows
// the object) and returns the rows in the order: for each detector, its KeyPo, + ICP,
// + RANSAC + ICP, + corrector rows (or its three C-3PO rows when self-trained). Throws
// CheckEvaluationDataset's InputErrors; std::invalid_argument
// for bad options. Unreadable clouds and detector failures are per-sample
// failures. `progress` is called (from worker threads) after each cloud.
// `frames` (when given) names the depth frame each entry's cloud came from
// (eval --bop): every row's certificate then includes the frame's free-space
// test (options.pipeline.certificate.free_space), as `certify --bop` does.
Evaluation Evaluate(const ObjectModel& object, const Dataset& dataset,
                    const std::vector<EvaluatedDetector>& detectors,
                    const EvaluationOptions& options, const ProgressCallback& progress = {},
                    const DatasetFrames& frames = {});

// The terminal table: aligned columns, one line per row, then the settings
// (ADD-S variant, thresholds, certificate thresholds) and the soundness figure.
std::string EvaluationTable(const Evaluation& evaluation);
// Everything as one JSON document (settings, rows with summaries, per-sample
// results of the rows on all clouds); non-finite numbers are written as null.
std::string EvaluationJson(const Evaluation& evaluation);

}  // namespace c3po
