#pragma once
// Certificate-gated self-training (paper Section VI-C, Algorithm 1; docs/method.md
// "Self-supervised"): each batch runs detector -> corrector -> certificates
// and only observably correct samples contribute, regressed onto their
// corrected keypoints. In the reference the corrector's backward rule
// (∂Δy*/∂ỹ = -I) cancels the Chamfer term, so the detector's only signal is
// "move the detected keypoints toward the fixed corrected keypoints" on
// certified samples: exactly this regression onto pseudo-labels.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "c3po/method/auto_threshold.hpp"
#include "c3po/method/certify_batch.hpp"
#include "c3po/method/detector.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/method/pseudo_label.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct SelfTrainOptions {
  int epochs = 20;
  int batch = 32;                     // clouds certified together, and pseudo-labels per regression step
  double validation_fraction = 0.1;   // held-out part of the unlabelled clouds
  double stop_at_percent_oc = 99.0;   // early stop on validation % identified (oc and unambiguous)
  // Label-free epoch selection (method.md "Self-training"): an epoch is
  // worse than the best one when its validation % identified drops, its
  // median fit residual rises by more than residual_tolerance (relative), or
  // the RMS distance between detected and corrected keypoints exceeds 1.5x
  // the best's + eps_oc/10; a worse epoch is rolled back (the best weights restored). Training stops
  // after `patience` epochs in a row without a new best (0 = never).
  double residual_tolerance = 0.05;
  int patience = 3;
  PseudoLabelOptions pseudo_labels;   // refuse ambiguous pseudo-labels (pseudo_label.hpp)
  PipelineOptions pipeline;           // corrector + certificate thresholds
  std::uint64_t seed = 0;
  std::string checkpoint_path;        // written atomically after every epoch ("" = none)
  void Check() const;
};

struct SelfTrainEpochLog {
  int epoch = 0;                      // 1-based
  double train_percent_oc = 0.0;      // % of the training clouds passing oc (and their frame's free space: FitsObservation), before the steps
  double validation_percent_oc = 0.0;
  double validation_percent_certified = 0.0;   // oc and nd
  double validation_detection_error = 0.0;     // RMS ||ỹ - y*|| on certified validation clouds
  double loss = 0.0;                  // mean regression loss on certified samples
  double mean_corrector_iterations = 0.0;
  int certified_samples = 0;
  int ambiguous_skipped = 0;          // certified training samples refused as ambiguous
  int symmetric_trained = 0;          // trained samples with symmetric labellings (symmetry-aware loss)
  int labelling_switched = 0;         // ... whose target was a labelling other than y* (nearer the detection)
  // Median PosedSurfaceHausdorff between the chosen pose and the second basin
  // of the ambiguous training samples (-1: none ambiguous); with
  // symmetry_tolerance it tells a near-symmetry (all samples ambiguous a few
  // mm away) from real ambiguity.
  double ambiguous_surface_q50 = -1.0;
  // Label-free validation criteria.
  double validation_percent_identified = 0.0;  // oc and not ambiguous
  int validation_ambiguous = 0;
  double validation_residual_q50 = 0.0;        // RMS fit residual quantiles over the validation clouds that fit the observation (oc, free space)
  double validation_residual_q90 = 0.0;
  bool rolled_back = false;                    // worse than the best: the best weights were restored
  // Reporting only, when ground truth was given (never used for selection);
  // -1 = none. Rotation error in degrees; Hausdorff distance (PosedSurfaceHausdorff) between the model
  // posed at the truth and at the estimate (object units).
  double validation_rotation_error_median = -1.0;
  double validation_hausdorff_median = -1.0;
  double seconds = 0.0;
};

// The label-free validation evaluation (also of the initial model).
struct ValidationFit {
  double percent_oc = 0.0;
  double percent_certified = 0.0;
  double percent_identified = 0.0;
  int ambiguous = 0;
  double detection_error = 0.0;
  double residual_q50 = 0.0;
  double residual_q90 = 0.0;
  double rotation_error_median = -1.0;
  double hausdorff_median = -1.0;
};

struct SelfTrainResult {
  std::vector<SelfTrainEpochLog> epochs;
  int best_epoch = 0;                 // 0 = the initial model was best
  double best_validation_percent_oc = 0.0;
  double best_validation_detection_error = 0.0;
  double initial_validation_percent_oc = 0.0;
  ValidationFit initial;              // the model before self-training
  ValidationFit best;                 // the kept model
  bool stopped_early = false;
  // Per cloud (input order): how many training steps used its pseudo-label
  // (0 for held-out clouds and for clouds never certified unambiguously):
  // the evidence that, in mixed data, another object's clouds taught nothing.
  std::vector<int> pseudo_label_uses;
};

// Optional ground truth for reporting (same length as the clouds); selection
// never reads it.
struct SelfTrainReference {
  std::vector<Pose> scene_from_model;
  // The object's symmetries (model_from_model): the reported rotation error
  // is to the nearest symmetric truth (NearestSymmetricTruth).
  std::vector<Pose> symmetries;
};

// One JSON object with every field of the log (the CLI's epoch-log line).
std::string ToJson(const SelfTrainEpochLog& log);

using EpochCallback = std::function<void(const SelfTrainEpochLog&)>;

// Self-trains `detector` in place; on return it holds the best weights.
// Throws InputError when no sample certifies in the first epoch (nothing to
// learn from). With options.checkpoint_path, `resume` continues from it.
// `frames` (nullptr, or one per cloud; an invalid view = none): the depth
// frame each cloud came from. Where one is known, a pseudo-label must also
// pass the free-space test, and a second basin the frame refutes is no
// second explanation (pseudo_label.hpp), as in `certify`.
// `groups` (same length as the clouds, e.g. the image of each real instance
// and its augmented copies, selftrain_inputs.hpp): the validation split takes
// whole groups (InputError with fewer than 2 groups); nullptr = every cloud
// its own group.
SelfTrainResult SelfTrain(const ObjectModel& object, const std::vector<PointSet>& clouds,
                          TrainableDetector& detector, const SelfTrainOptions& options,
                          const EpochCallback& on_epoch = {}, const ProgressCallback& progress = {},
                          bool resume = false, const SelfTrainReference* reference = nullptr,
                          const std::vector<int>* groups = nullptr, const std::vector<DepthView>* frames = nullptr);

// The validation criteria of `detector` on `clouds` (truth optional, for the
// reporting fields).
ValidationFit MeasureValidationFit(const ObjectModel& object, const std::vector<PointSet>& clouds,
                                   const Detector& detector, const PipelineOptions& pipeline,
                                   const PseudoLabelOptions& pseudo_labels,
                                   const std::vector<Pose>* truth = nullptr,
                                   const std::vector<Pose>& symmetries = {},
                                   const std::vector<DepthView>* frames = nullptr);

// % of clouds whose detector + corrector output is observably correct, and %
// certified (oc and nd); optionally the mean corrector iterations.
struct CertifiedFraction {
  double percent_oc = 0.0;
  double percent_certified = 0.0;
  double mean_iterations = 0.0;
  // RMS distance between detected and corrected keypoints over the observably
  // correct clouds: the detector's error against its own pseudo-labels
  // (ties in % oc are broken by it when keeping the best epoch).
  double detection_error = 0.0;
  std::vector<PoseEstimate> estimates;
  std::optional<AutoEpsOcResult> auto_eps_oc;   // with auto_eps_oc: the decision (estimates re-decided with it)
};
// Detects on all clouds at once (DetectBatch) and certifies them through
// CertifyBatch (certify_batch.hpp). `auto_eps_oc`: the `--eps-oc auto`
// decision of CertifyBatch on these clouds (self-training takes eps_oc from
// the clouds and the sim-trained detector before it starts).
// `frames`: as SelfTrain's (the certificates run the free-space test where known).
CertifiedFraction MeasureCertified(const ObjectModel& object, const std::vector<PointSet>& clouds,
                                   const Detector& detector, const PipelineOptions& options,
                                   bool auto_eps_oc = false, const std::vector<DepthView>* frames = nullptr);

// Observably correct and, where the cloud's frame is known, consistent with
// its free space: what a pseudo-label (and an identified validation cloud)
// needs from the certificate.
bool FitsObservation(const PoseEstimate& estimate);

}  // namespace c3po
