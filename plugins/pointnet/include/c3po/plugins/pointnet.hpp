#pragma once
// The `pointnet` keypoint detector: a PointNet regressor (Qi et al. 2017) from a
// partial point cloud X to the N semantic keypoints of one object (the
// detector of C-3PO, paper Section VI-A and docs/method.md "Pipeline" step 1).
//
// Network (tiny-dnn, with a custom Eigen-backed point encoder layer):
//   input  : n points of X minus its centroid, divided by a fixed scale s
//            (the object's diameter d), so the weights are unit-free;
//   encoder: shared per-point MLP 3 -> 64 -> 128 -> 256 (ReLU), max over points;
//   head   : fully connected 256 -> 256 -> 128 -> 3N (ReLU between);
//   output : keypoints relative to the centroid, times s, plus the centroid.
// Fixed n: a larger cloud is subsampled without replacement (deterministic per
// call: seeded by the cloud's size), a smaller one repeats its points
// cyclically (a max-pool network is invariant to repeated points). Never
// zero-padding. Non-finite points are dropped first.
//
// Threading: Detect / DetectBatch are safe to call concurrently (each call takes
// an inference copy of the network from a pool); Fit / TrainStep / SetWeights /
// Load* must not run concurrently with anything else on the same object.
// Training is deterministic for a given seed and does not depend on the thread
// count: weight gradients are kept per sample and summed in sample order.
//
// Model file (Save / Load): one line of JSON, then a binary block:
//   {"magic":"c3po-model","format_version":1,"detector":"pointnet",
//    "kind":"model"|"checkpoint","object":NAME,"keypoint_hash":HASH,
//    "num_keypoints":N,"num_points":n,"scale":s,"point_mlp":[...],"head":[...],
//    "weights":{"count":W,"dtype":"float32-le"},"training":{...},
//    "binary":{"bytes":B,"fnv1a64":"<hex>"}, ...header extras}\n
//   then W float32 weights (order: WeightBlocks()). A checkpoint adds
//   "optimizer":{kind, lr, momentum, state_bytes}, "progress":{epochs_done,
//   best_epoch, best_val_loss, best_weights, history}, "state":"<caller's
//   JSON>" and, after the weights, the optimiser state and the best weights.
// Loading checks every field, the sizes (before allocating anything) and the
// checksum, and that the file was trained for the given object (name and
// keypoint hash): anything else is a c3po::InputError naming the file.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "c3po/method/detector.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

// The network's shape (stored in the model file).
struct PointNetArchitecture {
  int num_points = 512;                      // n, points fed to the network
  std::vector<int> point_mlp = {64, 128, 256};
  std::vector<int> head = {256, 128};        // hidden widths; the output is 3N
  void Check() const;                        // throws std::invalid_argument
};

// What a model is for: it only loads for the object with the same name and
// keypoint hash.
struct PointNetIdentity {
  std::string object_name;
  std::string keypoint_hash;                 // ObjectModel::KeypointHash()
  int num_keypoints = 0;
  double scale = 1.0;                        // input/output normalisation (object units)
  static PointNetIdentity ForObject(const ObjectModel& object);   // scale = diameter
  void Check() const;                        // throws std::invalid_argument
};

struct PointNetTrainOptions {
  int epochs = 10;
  int batch = 32;
  double lr = 1e-3;
  std::string optimizer = "adam";            // "adam" or "sgd" (with momentum)
  double momentum = 0.9;                     // sgd only
  // Used by Fit when `validation` is empty: this fraction of `train` is held
  // out (chosen with `seed`).
  double validation_fraction = 0.1;
  std::uint64_t seed = 0;                    // shuffling, augmentation
  // Augmentation (training only; each sample, each epoch):
  double rotate_about_camera_deg = 0.0;      // rotation about the sensor z axis, uniform in +-deg
  double point_dropout = 0.0;                // fraction of points dropped, uniform in [0, this]
  double noise_sigma = 0.0;                  // Gaussian noise per coordinate (object units)
  // Must equal the architecture's num_points (kept here for the CLI's flag).
  int num_points = 512;
  // When non-empty, Fit writes a checkpoint there (atomically) after every
  // epoch; LoadCheckpoint + Fit with resume = true continues the run and gives
  // the same weights as an uninterrupted run with the same options and data.
  std::string checkpoint_path;
  bool resume = false;
  // Fine-tuning (train --init): Fit first evaluates the weights it starts
  // from as "epoch 0" (train loss on the training part without augmentation,
  // validation loss and keypoint error), logs it and keeps those weights
  // unless an epoch beats them on validation.
  bool validate_initial = false;
  void Check() const;                        // throws std::invalid_argument
};

struct EpochLog {
  int epoch = 0;                             // 1-based (0 = the starting weights, with validate_initial)
  double train_loss = 0.0;                   // mean squared keypoint error, object units^2
  double val_loss = 0.0;                     // same on the validation set (NaN if none)
  double val_keypoint_error = 0.0;           // mean keypoint distance, object units (NaN if none)
  double seconds = 0.0;                      // wall time of the epoch
  int labellings_switched = 0;               // samples trained on a symmetric labelling, not `keypoints`
  bool best = false;                         // best validation loss so far (weights kept)
};

struct PointNetFitResult {
  std::vector<EpochLog> epochs;              // including epochs before a resume
  int best_epoch = 0;                        // whose weights the detector now holds
  double best_val_loss = 0.0;
  std::size_t train_samples = 0;
  std::size_t validation_samples = 0;
};

using PointNetEpochCallback = std::function<void(const EpochLog&)>;

class PointNetDetector : public TrainableDetector {
 public:
  // A freshly initialised network (weights drawn from `seed`).
  explicit PointNetDetector(const ObjectModel& object, const PointNetArchitecture& architecture = {},
                            std::uint64_t seed = 0);
  PointNetDetector(const PointNetIdentity& identity, const PointNetArchitecture& architecture,
                   std::uint64_t seed = 0);
  ~PointNetDetector() override;
  PointNetDetector(PointNetDetector&&) noexcept;
  PointNetDetector& operator=(PointNetDetector&&) noexcept;

  std::string name() const override { return "pointnet"; }
  int num_keypoints() const override;
  // Keypoints (3 x N) in the cloud's frame. Throws InputError when the cloud
  // has no finite point.
  PointSet Detect(const PointSet& cloud) const override;
  // Batched forward pass (chunks of 64 clouds, both cores); same results as Detect.
  std::vector<PointSet> DetectBatch(const std::vector<PointSet>& clouds) const override;

  // Supervised training on (cloud, posed keypoints) pairs: loss = mean squared
  // keypoint error. Keeps the weights of the epoch with the lowest validation
  // loss (the last epoch when there is no validation data). The callback runs
  // after each epoch (it may throw, e.g. c3po::Interrupted, to stop; with a
  // checkpoint_path the last finished epoch is saved). Between batches Fit
  // calls ThrowIfInterrupted().
  PointNetFitResult Fit(const std::vector<TrainingSample>& train,
                        const std::vector<TrainingSample>& validation,
                        const PointNetTrainOptions& options,
                        const PointNetEpochCallback& on_epoch = {});

  // One optimisation step on a batch (self-training: regress onto the
  // corrected keypoints of certified samples). Clouds are prepared as in
  // Detect (no augmentation). The optimiser (options.optimizer, lr, momentum)
  // persists across calls; it is rebuilt when those options change. Returns
  // the batch's mean squared keypoint error before the step (object units^2).
  double TrainStep(const std::vector<PointSet>& clouds, const std::vector<PointSet>& keypoints,
                   const PointNetTrainOptions& options);
  // TrainableDetector: the same with the options of SetTrainOptions (default:
  // PointNetTrainOptions{} with the network's num_points).
  double TrainStep(const std::vector<PointSet>& clouds, const std::vector<PointSet>& targets) override;
  void SetTrainOptions(const PointNetTrainOptions& options);   // calls options.Check()
  const PointNetTrainOptions& train_options() const;
  // Mean squared keypoint error and mean keypoint distance on a set, no training.
  struct Evaluation {
    double loss = 0.0;
    double keypoint_error = 0.0;
  };
  Evaluation Evaluate(const std::vector<TrainingSample>& samples) const;

  // Model file (atomic write; format above). `header_extra_json` (a JSON
  // object or "") is merged into the header; it may not redefine the keys
  // above (std::invalid_argument). Load throws InputError("path: ...") for
  // unreadable, truncated, corrupt or foreign files.
  void Save(const std::string& path, const std::string& header_extra_json = "") const override;
  static std::unique_ptr<PointNetDetector> Load(const std::string& path, const ObjectModel& object);
  static std::unique_ptr<PointNetDetector> Load(const std::string& path,
                                                const PointNetIdentity& expected);
  // Checkpoint = model + optimiser state + Fit's progress (finished epochs,
  // history, best weights) + the caller's `state_json` (stored verbatim).
  void SaveCheckpoint(const std::string& path, const std::string& state_json = "") const override;
  // Restores weights, optimiser and progress in place from a checkpoint of
  // this object and architecture (else InputError naming the file); returns
  // the state_json saved with it.
  std::string LoadCheckpoint(const std::string& path) override;

  const PointNetIdentity& identity() const;
  const PointNetArchitecture& architecture() const;
  // JSON object stored in the model file's "training" field (Fit fills it;
  // callers may add keys, e.g. self-training statistics).
  std::string training_info_json() const;
  void set_training_info_json(const std::string& json);   // throws std::invalid_argument if not an object

  // Flat weights (float32) and their layout, for tests and tools. Blocks in
  // order: "point_mlp.<l>.weight", "point_mlp.<l>.bias" per MLP stage, then
  // "head.<h>.weight", "head.<h>.bias" per hidden head layer, then
  // "output.weight", "output.bias". Every weight is C_out x C_in,
  // column-major (entry (o, i) at o + i * C_out; also tiny-dnn's fully
  // connected layout). Outputs are keypoint after keypoint (x, y, z).
  struct WeightBlock {
    std::string name;
    std::size_t offset = 0;
    std::size_t size = 0;
  };
  std::vector<WeightBlock> WeightBlocks() const;
  std::vector<float> GetWeights() const override;
  void SetWeights(const std::vector<float>& weights) override;   // std::invalid_argument on size mismatch
  // Loss (normalised units, as trained) and its gradient with respect to the
  // flat weights, on clouds prepared as in Detect; for gradient checks.
  double LossAndGradient(const std::vector<PointSet>& clouds, const std::vector<PointSet>& keypoints,
                         std::vector<double>* gradient);

  struct Impl;

 private:
  explicit PointNetDetector(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Speed of the network on random data (for `c3po bench pointnet` and the
// c3po_bench_pointnet executable). Runs a few warm-up steps first.
struct PointNetBenchmarkOptions {
  int num_points = 512;
  int batch = 32;
  int num_keypoints = 10;
  int inference_batch = 64;
  double seconds = 3.0;                      // per measurement
  int threads = 0;                           // 0: c3po::DefaultThreadCount()
  void Check() const;
};

struct PointNetBenchmarkResult {
  double train_samples_per_second = 0.0;
  double inference_clouds_per_second = 0.0;        // DetectBatch, including input preparation
  double train_samples_per_cpu_second = 0.0;       // the same per CPU-second used by the process
  double inference_clouds_per_cpu_second = 0.0;
  int threads = 0;
  std::size_t parameters = 0;
};

PointNetBenchmarkResult RunPointNetBenchmark(const PointNetBenchmarkOptions& options);

}  // namespace c3po
