// c3po selftrain: certificate-gated self-training of a trained detector on
// unlabelled clouds (paper Section VI-C): only observably correct outputs
// teach the detector, with their corrected keypoints as targets.
#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>

#include "c3po/base/error.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/method/auto_threshold.hpp"
#include "c3po/method/image_sources.hpp"
#include "c3po/method/selftrain.hpp"
#include "c3po/method/selftrain_inputs.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/plugins/pointnet.hpp"
#include "command.hpp"
#include "options.hpp"
#include "progress_bar.hpp"
#include "training_common.hpp"

namespace c3po::cli {
namespace {

struct SelftrainCommand {
  std::string object_path;
  std::string model_path;
  std::string data_dir;
  std::string output_path;
  SelfTrainOptions options;
  double lr = 1e-3;
  std::string optimizer = "adam";
  ThresholdFlags thresholds;
  CorrectorFlags corrector;
  RobustFlags robust;
  bool resume = false;
  std::string symmetry_tolerance;   // distance or fraction of d; "" = eps_oc / 4
  // Camera inputs (docs/camera_inputs.md) and the paper's augmentation.
  CameraCloudFlags camera;
};

// The unlabelled clouds: a dataset (as stored; augmented only with --copies
// > 1) and/or camera inputs (--copies augmented copies per real instance,
// each dropping --dropout of its points and adding --noise; 0 = the
// instances as read), each with its validation group (a dataset cloud, or
// an image).
UnlabelledClouds LoadClouds(SelftrainCommand& cmd, const ObjectModel& object) {
  UnlabelledClouds camera = LoadCameraClouds(&cmd.camera, object, cmd.options.seed, "c3po selftrain");
  UnlabelledClouds data;
  if (!cmd.data_dir.empty()) {
    const Dataset dataset = ReadDataset(cmd.data_dir);
    data.clouds = LoadDatasetClouds(dataset, "loading");
    for (std::size_t i = 0; i < dataset.entries.size(); ++i) {
      data.groups.push_back(static_cast<int>(i));
      data.truth.push_back(dataset.entries[i].pose);
      data.names.push_back(dataset.entries[i].cloud);
      data.labels.push_back(dataset.entries[i].object.value_or(""));
    }
    if (cmd.camera.augment.copies > 1) data = Augment(data, cmd.camera.augment);
  }
  if (cmd.data_dir.empty() && !cmd.camera.given()) {
    throw InputError("no clouds given (--data DIR, --depth/--mask or --bop DIR)");
  }
  char own_label[32];
  std::snprintf(own_label, sizeof own_label, "obj_%06d", cmd.camera.bop.options.obj_id);
  if (!camera.clouds.empty()) {
    // Camera groups come after the dataset's: no two inputs share a group.
    const int offset = data.groups.empty() ? 0 : *std::max_element(data.groups.begin(), data.groups.end()) + 1;
    // The dataset's clouds have no frame; each camera cloud keeps its own
    // (the free-space test of its certificates).
    data.frames.resize(data.clouds.size());
    for (std::size_t i = 0; i < camera.clouds.size(); ++i) {
      data.clouds.push_back(std::move(camera.clouds[i]));
      data.frames.push_back(camera.frames.empty() ? DepthView{} : camera.frames[i]);
      data.groups.push_back(camera.groups[i] + offset);
      data.truth.push_back(camera.truth[i]);
      data.names.push_back(camera.names[i]);
      // --obj-id names this object's instances, whatever the object file
      // calls it; --add-obj-id instances keep their BOP label (obj_0000KK).
      data.labels.push_back(camera.labels[i].empty() || camera.labels[i] == own_label ? object.name()
                                                                                        : camera.labels[i]);
    }
  }
  return data;
}

nlohmann::json EpochJson(const SelfTrainEpochLog& e) {
  nlohmann::json j = nlohmann::json::parse(ToJson(e));
  j["phase"] = "selftrain";
  // The ground-truth columns only when the data had ground truth.
  if (e.validation_rotation_error_median < 0) j.erase("validation_rotation_error_median");
  if (e.validation_hausdorff_median < 0) j.erase("validation_hausdorff_median");
  return j;
}

// The sim-trained detector with the command's learning rate and optimizer.
std::unique_ptr<PointNetDetector> LoadDetector(const SelftrainCommand& cmd, const ObjectModel& object) {
  std::unique_ptr<PointNetDetector> detector = PointNetDetector::Load(cmd.model_path, object);
  PointNetTrainOptions train_options = detector->train_options();
  train_options.lr = cmd.lr;
  train_options.optimizer = cmd.optimizer;
  train_options.num_points = detector->architecture().num_points;
  try {
    detector->SetTrainOptions(train_options);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  return detector;
}

// The flags bound into cmd->options (corrector, thresholds, the input's
// robust defaults, symmetry tolerance, checkpoint), checked.
void ResolveOptions(const ObjectModel& object, SelftrainCommand* cmd) {
  SelfTrainOptions& options = cmd->options;
  ResolveCorrector(cmd->corrector, &options.pipeline.corrector);
  options.pipeline.certificate = ResolveThresholds(cmd->thresholds, object);
  // Camera clouds are certified with their frames (free space), as certify
  // does; with --data as well, the dataset's clouds have none.
  const InputKind input = !cmd->camera.given()    ? InputKind::kClouds
                          : cmd->data_dir.empty() ? InputKind::kCameraFrames
                                                  : InputKind::kCameraSegments;
  // Re-estimation stays opt-in here: every round certifies every instance again.
  cmd->robust.reestimate_camera_frames = false;
  ResolveRobust(cmd->robust, input, object, &options.pipeline.certificate, &options.pipeline.corrector);
  if (!cmd->symmetry_tolerance.empty()) {
    options.pseudo_labels.symmetry_tolerance =
        ParseThreshold(cmd->symmetry_tolerance, object.diameter(), "--symmetry-tolerance");
  }
  options.checkpoint_path = cmd->output_path + ".ckpt";
  try {
    options.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  if (cmd->resume && !std::filesystem::exists(options.checkpoint_path)) {
    throw InputError(options.checkpoint_path, "no checkpoint to resume from");
  }
}

// The object's symmetries: labellings T̂·S·b of every certified sample (the
// symmetry-aware loss) and reported rotation errors to the nearest symmetric
// truth.
std::vector<Pose> FindSymmetries(const SelftrainCommand& cmd, const ObjectModel& object) {
  std::vector<Pose> symmetries;
  const bool aware = cmd.options.pseudo_labels.symmetry_aware;
  for (const ModelSymmetry& s : ObjectSymmetries(SymmetryFlags{true, cmd.symmetry_tolerance}, object,
                                                 aware ? "every certified sample trained on its nearest labelling"
                                                       : "reported rotation errors only (--no-symmetry-aware-loss)")) {
    symmetries.push_back(s.model_from_model);
  }
  return symmetries;
}

// Another object's truth is not this object's: a mixed set has no reporting columns.
bool IsMixed(const UnlabelledClouds& data, const ObjectModel& object) {
  return std::any_of(data.labels.begin(), data.labels.end(),
                     [&](const std::string& label) { return !label.empty() && label != object.name(); });
}

// --eps-oc auto (CertifyBatch decides it): from the unlabelled clouds and the
// oc distances of the sim-trained detector + corrector on them. Sets the
// pipeline's eps_oc and returns the evidence (JSON).
std::string ResolveAutoEpsOc(const ObjectModel& object, const UnlabelledClouds& data, const Detector& detector,
                             const std::vector<DepthView>* frames, SelfTrainOptions* options) {
  const CertifiedFraction initial =
      MeasureCertified(object, data.clouds, detector, options->pipeline, /*auto_eps_oc=*/true, frames);
  const AutoEpsOcResult& chosen = *initial.auto_eps_oc;
  options->pipeline.certificate.eps_oc = chosen.eps_oc;
  std::fprintf(stderr, "c3po selftrain: --eps-oc auto = %.6g (%s; eps_w = %.4g, eps_s = %.4g)\n", chosen.eps_oc,
               chosen.rule.c_str(), chosen.noise.eps_w, chosen.sampling.eps_s);
  return chosen.ToJson();
}

void PrintEpoch(const SelfTrainEpochLog& e) {
  std::fprintf(stderr, "epoch %3d  train oc %5.1f%% (%d ambiguous skipped, %d symmetric)  val oc %5.1f%%  "
               "identified %5.1f%%  residual q50 %.3g q90 %.3g  loss %.3e%s%s  %.1fs\n",
               e.epoch, e.train_percent_oc, e.ambiguous_skipped, e.symmetric_trained, e.validation_percent_oc,
               e.validation_percent_identified, e.validation_residual_q50, e.validation_residual_q90, e.loss,
               e.rolled_back ? "  ROLLED BACK" : "",
               e.validation_hausdorff_median >= 0
                   ? (" [truth: rot " + std::to_string(e.validation_rotation_error_median) + " deg, hausdorff " +
                      std::to_string(e.validation_hausdorff_median) + "]").c_str()
                   : "",
               e.seconds);
}

// Once, when most certified samples were ambiguous: how far the second
// basins are from a symmetry. Returns whether it printed.
bool PrintAmbiguityHint(const SelfTrainEpochLog& e, const SelfTrainOptions& options) {
  if (e.ambiguous_surface_q50 < 0 || 2 * e.ambiguous_skipped < e.certified_samples) return false;
  std::fprintf(stderr, "c3po selftrain: %d of %d certified samples were ambiguous; their second basins lie a "
               "median %.3g from the chosen pose on the surface (symmetry tolerance %.3g): if the object is "
               "symmetric within that, --symmetry-tolerance declares it (docs/method.md, \"Symmetric "
               "labellings\")\n",
               e.ambiguous_skipped, e.certified_samples, e.ambiguous_surface_q50,
               options.pseudo_labels.SymmetryTolerance(options.pipeline.certificate.eps_oc));
  return true;
}

// The model file's "selftrain" record.
nlohmann::json SelftrainRecord(const SelftrainCommand& cmd, const SelfTrainResult& result,
                               const std::string& eps_oc_evidence) {
  const CertificateOptions& certificate = cmd.options.pipeline.certificate;
  nlohmann::json record = {{"source_model", std::filesystem::path(cmd.model_path).filename().string()},
                           {"eps_oc", certificate.eps_oc},
                           {"delta_nd", certificate.delta_nd},
                           {"best_epoch", result.best_epoch},
                           {"initial_validation_percent_oc", result.initial_validation_percent_oc},
                           {"best_validation_percent_oc", result.best_validation_percent_oc},
                           {"initial_validation_percent_identified", result.initial.percent_identified},
                           {"best_validation_percent_identified", result.best.percent_identified},
                           {"initial_validation_residual_q50", result.initial.residual_q50},
                           {"best_validation_residual_q50", result.best.residual_q50},
                           {"stopped_early", result.stopped_early}};
  if (!eps_oc_evidence.empty()) record["eps_oc_auto"] = nlohmann::json::parse(eps_oc_evidence);
  return record;
}

// Per object label of a mixed set: clouds, clouds whose pseudo-label was
// trained on, training uses (printed, and returned for the model file).
nlohmann::json PseudoLabelsByObject(const UnlabelledClouds& data, const SelfTrainResult& result,
                                    const ObjectModel& object) {
  std::map<std::string, std::array<long, 3>> by_label;
  for (std::size_t i = 0; i < data.clouds.size(); ++i) {
    auto& counts = by_label[data.labels[i].empty() ? "(unlabelled)" : data.labels[i]];
    counts[0] += 1;
    counts[1] += result.pseudo_label_uses[i] > 0;
    counts[2] += result.pseudo_label_uses[i];
  }
  nlohmann::json table = nlohmann::json::object();
  for (const auto& [label, counts] : by_label) {
    table[label] = {{"clouds", counts[0]}, {"trained_on", counts[1]}, {"uses", counts[2]}};
    std::printf("pseudo-labels from %s clouds%s: %ld of %ld clouds trained on (%ld uses)\n", label.c_str(),
                label == object.name() ? " (this object)" : "", counts[1], counts[0], counts[2]);
  }
  return table;
}

int Run(SelftrainCommand cmd) {
  const ObjectModel object = LoadObject(cmd.object_path);
  std::unique_ptr<PointNetDetector> detector = LoadDetector(cmd, object);
  ResolveOptions(object, &cmd);
  SelfTrainOptions& options = cmd.options;
  const UnlabelledClouds data = LoadClouds(cmd, object);
  const std::vector<PointSet>& clouds = data.clouds;
  if (clouds.size() < 2) throw InputError("need at least 2 clouds to self-train");
  const bool mixed = IsMixed(data, object);
  const std::vector<Pose> symmetries = FindSymmetries(cmd, object);
  if (options.pseudo_labels.symmetry_aware) options.pseudo_labels.model_symmetries = symmetries;
  // Ground truth, when every cloud has it, only feeds the log's reporting
  // columns (rotation error, Hausdorff distance); selection never reads it.
  std::optional<SelfTrainReference> reference;
  if (data.AllHaveTruth() && !mixed) {
    reference.emplace();
    for (const auto& truth : data.truth) reference->scene_from_model.push_back(*truth);
    reference->symmetries = symmetries;
  }
  // One frame per cloud when camera inputs are among them (free space), else none.
  const std::vector<DepthView>* frames = data.frames.size() == clouds.size() ? &data.frames : nullptr;
  const std::string eps_oc_evidence =
      cmd.thresholds.auto_eps_oc() ? ResolveAutoEpsOc(object, data, *detector, frames, &options) : "";

  EpochLogFile log(cmd.output_path);
  if (cmd.resume) log.LoadExisting();
  std::fprintf(stderr, "self-training on %zu unlabelled clouds of %s: eps_oc = %.6g, delta_nd = %.6g (d = %.6g), "
               "%s, %d epochs, batch %d, %s lr %g\n",
               clouds.size(), object.name().c_str(), options.pipeline.certificate.eps_oc,
               options.pipeline.certificate.delta_nd, object.diameter(),
               DescribeRobust(options.pipeline.certificate, options.pipeline.corrector).c_str(), options.epochs,
               options.batch,
               cmd.optimizer.c_str(), cmd.lr);
  ProgressBar progress("selftrain", 1);
  bool hinted = false;
  const SelfTrainResult result = SelfTrain(
      object, clouds, *detector, options,
      [&](const SelfTrainEpochLog& e) {
        progress.Finish();
        log.Record(e.epoch, EpochJson(e).dump());
        PrintEpoch(e);
        hinted = hinted || PrintAmbiguityHint(e, options);
        progress = ProgressBar("selftrain", 1);
      },
      [&](std::size_t done, std::size_t total) { progress.Update(total ? done / total : 0); }, cmd.resume,
      reference ? &*reference : nullptr, &data.groups, frames);
  progress.Finish();
  nlohmann::json extra = {{"selftrained", true}, {"selftrain", SelftrainRecord(cmd, result, eps_oc_evidence)}};
  if (mixed) extra["selftrain"]["pseudo_labels_by_object"] = PseudoLabelsByObject(data, result, object);
  detector->Save(cmd.output_path, extra.dump());
  std::printf("wrote %s: validation %% oc %.1f -> %.1f, %% identified %.1f -> %.1f, residual q50 %.3g -> %.3g "
              "(best epoch %d%s); eps_oc = %.6g; log %s\n",
              cmd.output_path.c_str(), result.initial_validation_percent_oc, result.best_validation_percent_oc,
              result.initial.percent_identified, result.best.percent_identified, result.initial.residual_q50,
              result.best.residual_q50,
              result.best_epoch, result.stopped_early ? ", stopped early" : "",
              options.pipeline.certificate.eps_oc, log.path().c_str());
  return 0;
}

}  // namespace

RunFunction SetupSelftrain(CLI::App& command) {
  auto cmd = std::make_shared<SelftrainCommand>();
  SelfTrainOptions& o = cmd->options;
  command.add_option("object", cmd->object_path, "Object JSON")->required();
  command.add_option("--model", cmd->model_path, "Trained model (e.g. from c3po train on sim data)")->required();
  command.add_option("--data", cmd->data_dir, "Unlabelled dataset (ground truth, if any, is only reported)");
  command.add_option("-o,--output", cmd->output_path, "Self-trained model file to write")
      ->check(WritableFile())->required();
  command.add_option("--epochs", o.epochs, "Maximum epochs");
  command.add_option("--batch", o.batch, "Batch size");
  command.add_option("--lr", cmd->lr, "Learning rate");
  command.add_option("--optimizer", cmd->optimizer, "adam or sgd");
  command.add_option("--val-fraction", o.validation_fraction, "Held-out fraction of the unlabelled clouds");
  command.add_option("--stop-at", o.stop_at_percent_oc,
                     "Stop when this % of the held-out clouds is identified (observably correct, not ambiguous)");
  command.add_option("--patience", o.patience, "Stop after this many epochs without a new best (0 = never)");
  command.add_option("--residual-tolerance", o.residual_tolerance,
                     "An epoch whose median held-out fit residual rises by more than this fraction is rolled back");
  command.add_option("--ambiguity-ratio", o.pseudo_labels.residual_ratio,
                     "A second basin fitting within this factor of the chosen fit's residual makes a sample ambiguous");
  command.add_flag("!--no-ambiguity-check", o.pseudo_labels.check_ambiguity,
                   "Train on every certified sample, ambiguous or not (reproduces the flip regression)");
  command.add_flag("!--no-symmetry-aware-loss", o.pseudo_labels.symmetry_aware,
                   "Refuse samples with symmetric labellings as ambiguous instead of training on the labelling "
                   "nearest the detection");
  command.add_option("--symmetry-tolerance", cmd->symmetry_tolerance,
                     "A second basin whose posed model is within this Hausdorff distance of the chosen one is a "
                     "symmetric labelling (a distance, or e.g. 0.5%d of the diameter; default eps_oc/4)");
  AddThresholdOptions(command, &cmd->thresholds, AutoEpsOc::kAllowed);
  AddCorrectorOptions(command, &cmd->corrector);
  AddRobustOptions(command, &cmd->robust);
  AddSeedOption(command, &o.seed, "split, shuffling");
  command.add_flag("--resume", cmd->resume, "Continue from OUTPUT.ckpt");
  command.add_option("--add-obj-id", cmd->camera.other_obj_ids,
                     "With --bop: also read the instances of this BOP object as unlabelled clouds (repeatable; a "
                     "mixed set: their label is only reported, per object, with the pseudo-labels used)");
  AddCameraCloudOptions(command, &cmd->camera, "",
                        "Augmented copies per real instance (camera inputs; 0 = the instances as read; with --data: "
                        "per cloud when more than 1)");
  return [cmd]() { return Run(*cmd); };
}

}  // namespace c3po::cli
