// c3po train: supervised training of a keypoint detector on labelled clouds
// (sim data from `c3po synth`, or real labelled data).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "c3po/base/error.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/plugins/pointnet.hpp"
#include "command.hpp"
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
};

std::vector<TrainingSample> Samples(const Dataset& dataset, const std::vector<PointSet>& clouds) {
  std::vector<TrainingSample> samples;
  for (std::size_t i = 0; i < clouds.size(); ++i) samples.push_back({clouds[i], *dataset.entries[i].keypoints});
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

int Run(TrainCommand cmd) {
  if (cmd.detector != "pointnet") {
    throw InputError("--detector", "'" + cmd.detector + "' is not trainable (trainable: pointnet)");
  }
  const ObjectModel object = LoadObject(cmd.object_path);
  PointNetArchitecture architecture;
  architecture.num_points = cmd.options.num_points;
  architecture.point_mlp = cmd.point_mlp;
  architecture.head = cmd.head;
  cmd.options.checkpoint_path = cmd.output_path + ".ckpt";
  cmd.options.resume = cmd.resume;
  try {
    architecture.Check();
    cmd.options.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError("c3po train", e.what());
  }
  const Dataset dataset = ReadLabelled(cmd.data_dir, object.num_keypoints());
  const std::vector<TrainingSample> train = Samples(dataset, LoadDatasetClouds(dataset, "loading"));
  std::vector<TrainingSample> validation;
  if (!cmd.validation_dir.empty()) {
    const Dataset held_out = ReadLabelled(cmd.validation_dir, object.num_keypoints());
    validation = Samples(held_out, LoadDatasetClouds(held_out, "loading validation"));
  }

  PointNetDetector detector(object, architecture, cmd.options.seed);
  EpochLogFile log(cmd.output_path);
  if (cmd.resume) {
    if (!std::filesystem::exists(cmd.options.checkpoint_path)) {
      throw InputError(cmd.options.checkpoint_path, "no checkpoint to resume from");
    }
    detector.LoadCheckpoint(cmd.options.checkpoint_path);
    log.LoadExisting();
  }
  std::fprintf(stderr, "training %s on %zu clouds of %s (%d epochs, batch %d, %s lr %g, n = %d)\n",
               cmd.detector.c_str(), train.size(), object.name().c_str(), cmd.options.epochs, cmd.options.batch,
               cmd.options.optimizer.c_str(), cmd.options.lr, cmd.options.num_points);
  const PointNetFitResult result = detector.Fit(train, validation, cmd.options, [&](const EpochLog& epoch) {
    const nlohmann::json line = {{"phase", "train"}, {"epoch", epoch.epoch}, {"train_loss", epoch.train_loss},
                                 {"val_loss", epoch.val_loss}, {"val_keypoint_error", epoch.val_keypoint_error},
                                 {"seconds", epoch.seconds}, {"best", epoch.best}};
    log.Record(epoch.epoch, line.dump());
    std::fprintf(stderr, "epoch %3d  train loss %.3e  val loss %.3e  val keypoint error %.4g  %.1fs%s\n",
                 epoch.epoch, epoch.train_loss, epoch.val_loss, epoch.val_keypoint_error, epoch.seconds,
                 epoch.best ? "  (best)" : "");
  });
  detector.Save(cmd.output_path);
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
  command.add_option("--data", cmd->data_dir, "Labelled dataset (manifest with keypoints)")->required();
  command.add_option("-o,--output", cmd->output_path, "Model file to write")->required();
  command.add_option("--validation", cmd->validation_dir, "Labelled validation dataset (default: hold out --val-fraction)");
  command.add_option("--detector", cmd->detector, "Trainable detector (pointnet)");
  command.add_option("--epochs", o.epochs, "Epochs");
  command.add_option("--batch", o.batch, "Batch size");
  command.add_option("--lr", o.lr, "Learning rate");
  command.add_option("--optimizer", o.optimizer, "adam or sgd (with momentum)");
  command.add_option("--momentum", o.momentum, "SGD momentum");
  command.add_option("--val-fraction", o.validation_fraction, "Held-out fraction when --validation is not given");
  command.add_option("--seed", o.seed, "Seed (initial weights, shuffling, augmentation)");
  command.add_option("--points", o.num_points, "Points fed to the network (subsampled or repeated)");
  command.add_option("--rotate-deg", o.rotate_about_camera_deg, "Augmentation: random rotation about the camera axis (degrees)");
  command.add_option("--dropout", o.point_dropout, "Augmentation: drop up to this fraction of points");
  command.add_option("--noise", o.noise_sigma, "Augmentation: Gaussian noise sigma (object units)");
  command.add_option("--point-mlp", cmd->point_mlp, "Widths of the shared point MLP")->delimiter(',');
  command.add_option("--head", cmd->head, "Widths of the hidden head layers")->delimiter(',');
  command.add_flag("--resume", cmd->resume, "Continue from OUTPUT.ckpt (same result as an uninterrupted run)");
  return [cmd]() { return Run(*cmd); };
}

}  // namespace c3po::cli
