// c3po train: supervised training of a keypoint detector on labelled clouds:
// a dataset with keypoints (sim data from `c3po synth`), and/or real camera
// frames labelled by their ground truth (--bop: the object's keypoints posed
// at scene_gt's pose, augmented with --copies as selftrain does); from fresh
// weights or fine-tuned from a model (--init).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "c3po/base/error.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/method/selftrain_inputs.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/plugins/pointnet.hpp"
#include "command.hpp"
#include "options.hpp"
#include "progress_bar.hpp"
#include "training_common.hpp"

namespace c3po::cli {
namespace {

struct TrainCommand {
  std::string object_path;
  std::string data_dir;
  std::string validation_dir;
  std::string output_path;
  std::string detector = "pointnet";
  PointNetTrainOptions options;
  std::vector<int> point_mlp = {64, 128, 256};
  std::vector<int> head = {256, 128};
  bool resume = false;
  std::string init_path;                  // --init MODEL: fine-tune from its weights
  CameraCloudFlags camera;                // --bop / --depth,--mask (with ground truth)
  SymmetryFlags symmetry;                 // train symmetric objects against min over labellings
  // Options whose value the architecture of --init fixes (given = refused if different).
  CLI::Option* points_flag = nullptr;
  CLI::Option* point_mlp_flag = nullptr;
  CLI::Option* head_flag = nullptr;
};

std::string Join(const std::vector<int>& values) {
  std::string text;
  for (int v : values) text += (text.empty() ? "" : ",") + std::to_string(v);
  return text;
}

// --init: the architecture is the model's; a flag that says otherwise is refused.
void CheckInitArchitecture(const TrainCommand& cmd, const PointNetArchitecture& model) {
  const auto refuse = [&](const std::string& flag, const std::string& given, const std::string& stored) {
    throw InputError(cmd.init_path, flag + " " + given + " differs from the model's " + stored +
                                        " (with --init the architecture comes from the model file)");
  };
  if (cmd.points_flag->count() > 0 && cmd.options.num_points != model.num_points) {
    refuse("--points", std::to_string(cmd.options.num_points), std::to_string(model.num_points));
  }
  if (cmd.point_mlp_flag->count() > 0 && cmd.point_mlp != model.point_mlp) {
    refuse("--point-mlp", Join(cmd.point_mlp), Join(model.point_mlp));
  }
  if (cmd.head_flag->count() > 0 && cmd.head != model.head) refuse("--head", Join(cmd.head), Join(model.head));
}

std::vector<TrainingSample> Samples(const Dataset& dataset, const std::vector<PointSet>& clouds) {
  std::vector<TrainingSample> samples;
  for (std::size_t i = 0; i < clouds.size(); ++i) samples.push_back({clouds[i], *dataset.entries[i].keypoints, {}});
  return samples;
}

Dataset ReadLabelled(const std::string& dir, int num_keypoints) {
  Dataset dataset = ReadDataset(dir);
  if (dataset.entries.empty()) throw InputError(dir, "dataset is empty");
  for (const auto& entry : dataset.entries) {
    if (!entry.keypoints) throw InputError(dir + "/manifest.jsonl", entry.cloud + ": no ground-truth \"keypoints\" (train needs labelled data)");
    if (entry.keypoints->cols() != num_keypoints) {
      throw InputError(dir + "/manifest.jsonl", entry.cloud + ": " + std::to_string(entry.keypoints->cols()) +
                                                     " keypoints, the object has " + std::to_string(num_keypoints));
    }
  }
  return dataset;
}

// The architecture: the --init model's (loaded into *init, fine-tuned and
// validated before its first epoch) or the flags'; options completed and checked.
PointNetArchitecture ResolveArchitecture(const ObjectModel& object, TrainCommand* cmd,
                                         std::unique_ptr<PointNetDetector>* init) {
  PointNetArchitecture architecture;
  if (!cmd->init_path.empty()) {
    *init = PointNetDetector::Load(cmd->init_path, object);   // InputError: foreign or corrupt model
    architecture = (*init)->architecture();
    CheckInitArchitecture(*cmd, architecture);
    cmd->options.num_points = architecture.num_points;
    cmd->options.validate_initial = true;
  } else {
    architecture.num_points = cmd->options.num_points;
    architecture.point_mlp = cmd->point_mlp;
    architecture.head = cmd->head;
  }
  cmd->options.checkpoint_path = cmd->output_path + ".ckpt";
  cmd->options.resume = cmd->resume;
  try {
    architecture.Check();
    cmd->options.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  return architecture;
}

struct LabelledSamples {
  std::vector<TrainingSample> train;
  std::vector<TrainingSample> validation;
  std::size_t camera_clouds = 0;   // of which from camera inputs (augmented copies included)
};

// The labelled clouds: a dataset and/or camera inputs labelled by their
// ground truth (augmented like selftrain's), and the held-out ones: --val-data,
// or for camera inputs whole images (SplitValidation).
LabelledSamples LoadLabelled(const ObjectModel& object, TrainCommand* cmd) {
  LabelledSamples samples;
  std::vector<int> groups;   // validation unit of each sample: a dataset cloud, or an image
  if (!cmd->data_dir.empty()) {
    const Dataset dataset = ReadLabelled(cmd->data_dir, object.num_keypoints());
    samples.train = Samples(dataset, LoadDatasetClouds(dataset, "loading"));
    for (std::size_t i = 0; i < samples.train.size(); ++i) groups.push_back(static_cast<int>(i));
  }
  UnlabelledClouds camera =
      LoadCameraClouds(&cmd->camera, object, cmd->options.seed, "c3po train", /*need_truth=*/true);
  camera.frames.clear();   // supervised training certifies nothing: the depth images are not kept
  if (cmd->camera.given() && camera.clouds.empty()) {
    throw InputError(cmd->camera.bop.dir.empty() ? cmd->camera.frame.mask_path : cmd->camera.bop.dir,
                     "no instance could be read");
  }
  const int offset = static_cast<int>(groups.size());
  for (TrainingSample& sample : LabelWithTruth(camera, object, "--bop")) samples.train.push_back(std::move(sample));
  for (int group : camera.groups) groups.push_back(group + offset);
  samples.camera_clouds = camera.clouds.size();

  if (!cmd->validation_dir.empty()) {
    const Dataset held_out = ReadLabelled(cmd->validation_dir, object.num_keypoints());
    samples.validation = Samples(held_out, LoadDatasetClouds(held_out, "loading validation"));
  } else if (!camera.clouds.empty() && cmd->options.validation_fraction > 0) {
    std::vector<TrainingSample>& train = samples.train;
    if (train.size() < 2) {
      throw InputError("--val-fraction", "need at least 2 labelled clouds to hold some out (or --val-fraction 0)");
    }
    const ValidationSplit split =
        SplitValidation(train.size(), &groups, cmd->options.validation_fraction, cmd->options.seed, "--val-fraction");
    std::vector<TrainingSample> kept;
    for (int i : split.validation) samples.validation.push_back(train[static_cast<std::size_t>(i)]);
    for (int i : split.train) kept.push_back(std::move(train[static_cast<std::size_t>(i)]));
    train = std::move(kept);
  }
  return samples;
}

// The object's symmetries, and each sample's symmetric labellings (trained
// against the nearest of them).
std::vector<ModelSymmetry> AddSymmetricLabellings(const TrainCommand& cmd, const ObjectModel& object,
                                                  LabelledSamples* samples) {
  const std::vector<ModelSymmetry> symmetries =
      ObjectSymmetries(cmd.symmetry, object, "trained against the nearest of the symmetric labellings");
  std::size_t labelled = 0, total = 0;
  for (auto* set : {&samples->train, &samples->validation}) {
    for (TrainingSample& sample : *set) {
      sample.symmetric_keypoints = SymmetricLabellings(object, symmetries, sample.keypoints);
      labelled += !sample.symmetric_keypoints.empty();
      ++total;
    }
  }
  if (!symmetries.empty() && labelled < total) {
    // Labels that are not a rigid copy of the object's keypoints have no pose
    // to turn: those samples keep the plain loss.
    std::fprintf(stderr, "c3po train: %zu of %zu clouds have symmetric labellings (the others' keypoints are not "
                 "a rigid copy of the object's: plain loss)\n", labelled, total);
  }
  return symmetries;
}

// One epoch: a log line (JSON) and a progress line.
void RecordEpoch(const EpochLog& epoch, EpochLogFile* log) {
  const nlohmann::json line = {{"phase", "train"}, {"epoch", epoch.epoch}, {"train_loss", epoch.train_loss},
                               {"val_loss", epoch.val_loss}, {"val_keypoint_error", epoch.val_keypoint_error},
                               {"seconds", epoch.seconds}, {"labellings_switched", epoch.labellings_switched},
                               {"best", epoch.best}};
  log->Record(epoch.epoch, line.dump());
  std::fprintf(stderr, "epoch %3d  train loss %.3e  val loss %.3e  val keypoint error %.4g  %.1fs%s\n",
               epoch.epoch, epoch.train_loss, epoch.val_loss, epoch.val_keypoint_error, epoch.seconds,
               epoch.best ? "  (best)" : "");
}

// The model file's extra record ("" when there is nothing to say).
std::string ModelRecord(const TrainCommand& cmd, std::size_t num_symmetries, std::size_t camera_clouds) {
  nlohmann::json extra = nlohmann::json::object();
  extra["symmetries"] = num_symmetries;
  if (!cmd.init_path.empty()) extra["init_model"] = std::filesystem::path(cmd.init_path).filename().string();
  if (camera_clouds > 0) {
    extra["camera_instances"] = camera_clouds / static_cast<std::size_t>(std::max(1, cmd.camera.augment.copies));
    extra["camera_copies"] = cmd.camera.augment.copies;
  }
  return extra.empty() ? "" : extra.dump();
}

int Run(TrainCommand cmd) {
  if (cmd.detector != "pointnet") {
    throw InputError("--detector", "'" + cmd.detector + "' is not trainable (trainable: pointnet)");
  }
  if (cmd.data_dir.empty() && !cmd.camera.given()) {
    throw InputError("no labelled clouds given (--data DIR, --bop DIR --obj-id K, or --depth/--mask)");
  }
  const ObjectModel object = LoadObject(cmd.object_path);
  std::unique_ptr<PointNetDetector> detector;
  const PointNetArchitecture architecture = ResolveArchitecture(object, &cmd, &detector);
  LabelledSamples samples = LoadLabelled(object, &cmd);
  const std::vector<ModelSymmetry> symmetries = AddSymmetricLabellings(cmd, object, &samples);
  if (!detector) detector = std::make_unique<PointNetDetector>(object, architecture, cmd.options.seed);
  EpochLogFile log(cmd.output_path);
  if (cmd.resume) {
    if (!std::filesystem::exists(cmd.options.checkpoint_path)) {
      throw InputError(cmd.options.checkpoint_path, "no checkpoint to resume from");
    }
    detector->LoadCheckpoint(cmd.options.checkpoint_path);
    log.LoadExisting();
  }
  std::fprintf(stderr, "training %s on %zu clouds of %s (%d epochs, batch %d, %s lr %g, n = %d%s%s)\n",
               cmd.detector.c_str(), samples.train.size(), object.name().c_str(), cmd.options.epochs,
               cmd.options.batch, cmd.options.optimizer.c_str(), cmd.options.lr, cmd.options.num_points,
               cmd.init_path.empty() ? "" : ", from ", cmd.init_path.c_str());
  const PointNetFitResult result = detector->Fit(samples.train, samples.validation, cmd.options,
                                                 [&](const EpochLog& epoch) { RecordEpoch(epoch, &log); });
  detector->Save(cmd.output_path, ModelRecord(cmd, symmetries.size(), samples.camera_clouds));
  std::printf("wrote %s (best epoch %d, validation loss %.3e, %zu train / %zu validation clouds); log %s\n",
              cmd.output_path.c_str(), result.best_epoch, result.best_val_loss, result.train_samples,
              result.validation_samples, log.path().c_str());
  return 0;
}

}  // namespace

RunFunction SetupTrain(CLI::App& command) {
  auto cmd = std::make_shared<TrainCommand>();
  PointNetTrainOptions& o = cmd->options;
  command.add_option("object", cmd->object_path, "Object JSON")->required();
  command.add_option("--data", cmd->data_dir, "Labelled dataset (manifest with keypoints)");
  command.add_option("-o,--output", cmd->output_path, "Model file to write")->check(WritableFile())->required();
  command.add_option("--validation", cmd->validation_dir, "Labelled validation dataset (default: hold out --val-fraction)");
  command.add_option("--detector", cmd->detector, "Trainable detector (pointnet)");
  command.add_option("--epochs", o.epochs, "Epochs");
  command.add_option("--batch", o.batch, "Batch size");
  command.add_option("--lr", o.lr, "Learning rate");
  command.add_option("--optimizer", o.optimizer, "adam or sgd (with momentum)");
  command.add_option("--momentum", o.momentum, "SGD momentum");
  command.add_option("--val-fraction", o.validation_fraction, "Held-out fraction when --validation is not given");
  command.add_option("--seed", o.seed, "Seed (initial weights, shuffling, augmentation)");
  cmd->points_flag = command.add_option("--points", o.num_points, "Points fed to the network (subsampled or repeated)");
  command.add_option("--rotate-deg", o.rotate_about_camera_deg, "Augmentation: random rotation about the camera axis (degrees)");
  command.add_option("--dropout", o.point_dropout, "Augmentation: drop up to this fraction of points");
  command.add_option("--noise", o.noise_sigma, "Augmentation: Gaussian noise sigma (object units)");
  cmd->point_mlp_flag = command.add_option("--point-mlp", cmd->point_mlp, "Widths of the shared point MLP")->delimiter(',');
  cmd->head_flag = command.add_option("--head", cmd->head, "Widths of the hidden head layers")->delimiter(',');
  AddSymmetryOptions(command, &cmd->symmetry, "--no-symmetry-aware-loss",
                     "Plain mean squared error even for a symmetric object (default: the object's rotational "
                     "symmetries are found and each cloud is trained against the nearest of its labellings)");
  command.add_flag("--resume", cmd->resume, "Continue from OUTPUT.ckpt (same result as an uninterrupted run)");
  command.add_option("--init", cmd->init_path,
                     "Fine-tune from this model's weights (its architecture; epoch 0 = the model, kept unless beaten)");
  // Real frames labelled by their ground truth (scene_gt.json), the same
  // sources and augmentation as selftrain; --copy-dropout / --copy-noise
  // because --dropout / --noise are the per-epoch augmentation above.
  AddCameraCloudOptions(command, &cmd->camera, "copy-",
                        "Augmented copies per real instance (camera inputs; 0 = the instances as read)");
  return [cmd]() { return Run(*cmd); };
}

}  // namespace c3po::cli
