// c3po eval: the paper's table rows (KeyPo, + ICP, + corrector, C-3PO on the
// certified subsets) on a dataset with ground truth; terminal table, JSON and
// a self-contained HTML report.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>

#include <unistd.h>

#include "c3po/base/atomic_file.hpp"
#include "c3po/io/bop.hpp"
#include "c3po/io/bop_dataset.hpp"
#include "c3po/base/error.hpp"
#include "c3po/eval/evaluation.hpp"
#include "c3po/eval/evaluation_samples.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/io/shard.hpp"
#include "c3po/method/image_sources.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/plugins/registry.hpp"
#include "c3po/web/report.hpp"
#include "command.hpp"
#include "options.hpp"
#include "progress_bar.hpp"

namespace c3po::cli {
namespace {

namespace fs = std::filesystem;

struct EvalCommand {
  std::string object_path;
  std::string data_dir;
  DetectorFlags detector;                 // --model (repeatable), --detector, --plugin
  std::vector<std::string> selftrained;
  std::string adds_threshold = "5%d";
  std::string auc_max = "10%d";
  std::string adds_variant = "symmetric";
  ThresholdFlags thresholds;
  CorrectorFlags corrector;
  RobustFlags robust;
  SymmetryFlags symmetry;      // errors to the nearest symmetric truth
  bool no_icp = false;
  bool no_ransac = false;
  std::string ransac_threshold = "5%d";
  int ransac_iterations = 1000;
  std::uint64_t seed = 0;
  int icp_iterations = 30;
  std::string icp_max_distance;
  double icp_trim = 0.0;
  std::string json_path;
  std::string samples_path;   // --samples: per-sample rows for c3po merge --eval
  std::string shard;          // --shard K/N
  ReportFlags report;
  std::vector<std::string> training_logs;
  int worst = 5;
  // BOP input (issue 15): converted to a temporary dataset.
  BopFlags bop;
  std::string models_info_path;
  SegmentOptions segment;
  std::string evidence_erode_mask = "auto";   // resolved into segment by ResolveEvidence
};

// A temporary folder removed on destruction (the BOP instances as a dataset).
class ScratchFolder {
 public:
  ScratchFolder() : path_((fs::temp_directory_path() / ("c3po_eval_bop." + std::to_string(::getpid()))).string()) {}
  ~ScratchFolder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// models_info.json for --bop: the option, else DIR/../models or DIR/../../models.
std::string FindModelsInfo(const EvalCommand& cmd) {
  if (!cmd.models_info_path.empty()) return cmd.models_info_path;
  const fs::path dir = fs::absolute(cmd.bop.dir).lexically_normal();
  for (const fs::path& candidate : {dir.parent_path() / "models/models_info.json",
                                    dir.parent_path().parent_path() / "models/models_info.json"}) {
    if (fs::exists(candidate)) return candidate.string();
  }
  return "";
}

// A detector to evaluate, owning what it loaded.
struct LoadedDetector {
  std::string label;
  std::unique_ptr<Detector> detector;   // null: the manifest's detected_keypoints
  bool self_trained = false;
  std::string model_path;               // empty for named detectors
};

std::string UniqueLabel(std::string label, const std::vector<LoadedDetector>& existing) {
  const std::string base = label;
  for (int k = 2;; ++k) {
    const bool taken = std::any_of(existing.begin(), existing.end(),
                                   [&](const LoadedDetector& d) { return d.label == label; });
    if (!taken) return label;
    label = base + " #" + std::to_string(k);
  }
}

std::vector<LoadedDetector> LoadDetectors(const EvalCommand& cmd, const ObjectModel& object) {
  LoadPlugins(cmd.detector);
  std::vector<LoadedDetector> detectors;
  auto add_model = [&](const std::string& path, bool self_trained) {
    LoadedDetector d;
    d.detector = LoadDetectorModel(path, object);
    d.self_trained = self_trained || ReadModelHeader(path).self_trained;
    d.label = UniqueLabel(fs::path(path).stem().string(), detectors);
    d.model_path = path;
    detectors.push_back(std::move(d));
  };
  for (const auto& path : cmd.detector.models) add_model(path, false);
  for (const auto& path : cmd.selftrained) add_model(path, true);
  for (const auto& name : cmd.detector.detectors) {
    LoadedDetector d;
    d.detector = MakeDetector("", name, object);
    d.label = UniqueLabel(name, detectors);
    detectors.push_back(std::move(d));
  }
  if (detectors.empty()) {
    throw InputError("give at least one --model FILE, --selftrained FILE or --detector NAME");
  }
  return detectors;
}

EvaluationOptions MakeOptions(const EvalCommand& cmd, const ObjectModel& object, double d) {
  EvaluationOptions options = EvaluationOptions::Defaults(object);
  options.adds_threshold = ParseThreshold(cmd.adds_threshold, d, "--adds-threshold");
  options.auc_max = ParseThreshold(cmd.auc_max, d, "--auc-max");
  options.adds_variant = ParseAddSVariant(cmd.adds_variant);
  options.pipeline.certificate = ResolveThresholds(cmd.thresholds, object);
  if (!(options.pipeline.certificate.eps_oc > 0) || !(options.pipeline.certificate.delta_nd > 0)) {
    throw InputError(cmd.object_path, "the object has no eps_oc / delta_nd: give --eps-oc and --delta-nd");
  }
  ResolveCorrector(cmd.corrector, &options.pipeline.corrector);
  ResolveRobust(cmd.robust, cmd.bop.dir.empty() ? InputKind::kClouds : InputKind::kCameraFrames, object,
                &options.pipeline.certificate, &options.pipeline.corrector);
  options.run_icp = !cmd.no_icp;
  options.run_ransac = !cmd.no_ransac;
  options.ransac.inlier_threshold = ParseThreshold(cmd.ransac_threshold, d, "--ransac-threshold");
  options.ransac.max_iterations = cmd.ransac_iterations;
  options.ransac.seed = cmd.seed;
  options.icp.max_iterations = cmd.icp_iterations;
  options.icp.trim_fraction = cmd.icp_trim;
  if (!cmd.icp_max_distance.empty()) {
    options.icp.max_correspondence_distance = ParseThreshold(cmd.icp_max_distance, d, "--icp-max-distance");
  }
  options.worst_listed = cmd.worst;
  try {
    options.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  return options;
}

std::string LogLabel(const std::string& path) {
  std::string name = fs::path(path).filename().string();
  for (const char* suffix : {".log.jsonl", ".jsonl"}) {
    const std::string s = suffix;
    if (name.size() > s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0) {
      return name.substr(0, name.size() - s.size());
    }
  }
  return name;
}

// --training-log files, then MODEL.log.jsonl next to every model given.
std::vector<TrainingLog> ReadTrainingLogs(const EvalCommand& cmd, const std::vector<LoadedDetector>& detectors) {
  std::vector<TrainingLog> logs;
  std::vector<std::string> seen;
  auto read = [&](const std::string& path, const std::string& label) {
    const std::string canonical = fs::weakly_canonical(path).string();
    if (std::find(seen.begin(), seen.end(), canonical) != seen.end()) return;
    seen.push_back(canonical);
    logs.push_back(ReadTrainingLog(path, label));
  };
  for (const auto& path : cmd.training_logs) read(path, LogLabel(path));
  for (const auto& d : detectors) {
    if (d.model_path.empty()) continue;
    for (const std::string& candidate :
         {d.model_path + ".log.jsonl", (fs::path(d.model_path).replace_extension(".log.jsonl")).string()}) {
      if (fs::is_regular_file(candidate)) {
        read(candidate, d.label);
        break;
      }
    }
  }
  return logs;
}

std::string CommandLine(const EvalCommand& cmd) {
  std::string line = "c3po eval " + cmd.object_path;
  if (cmd.bop.dir.empty()) {
    line += " --data " + cmd.data_dir;
  } else {
    line += " --bop " + cmd.bop.dir + " --obj-id " + std::to_string(cmd.bop.options.obj_id);
    if (!cmd.bop.options.targets_path.empty()) line += " --targets " + cmd.bop.options.targets_path;
  }
  for (const auto& m : cmd.detector.models) line += " --model " + m;
  for (const auto& m : cmd.selftrained) line += " --selftrained " + m;
  for (const auto& d : cmd.detector.detectors) line += " --detector " + d;
  line += " --adds " + cmd.adds_variant + " --adds-threshold " + cmd.adds_threshold + " --auc-max " + cmd.auc_max;
  if (!cmd.thresholds.eps_oc.empty()) line += " --eps-oc " + cmd.thresholds.eps_oc;
  if (!cmd.thresholds.delta_nd.empty()) line += " --delta-nd " + cmd.thresholds.delta_nd;
  line += RobustCommandLine(cmd.robust);
  if (cmd.no_icp) line += " --no-icp";
  if (cmd.no_ransac) line += " --no-ransac";
  if (!cmd.no_icp && !cmd.no_ransac) {
    line += " --ransac-threshold " + cmd.ransac_threshold + " --seed " + std::to_string(cmd.seed);
  }
  return line;
}

// Fractions of d: the dataset's own diameter (models_info.json) when
// evaluating BOP data, else the object's bounding-box diagonal.
double EvaluationDiameter(const EvalCommand& cmd, const ObjectModel& object) {
  const std::string models_info = cmd.bop.dir.empty() ? "" : FindModelsInfo(cmd);
  if (models_info.empty()) return object.diameter();
  const auto info = ParseModelsInfo(ReadFileToString(models_info), models_info);
  const auto it = info.find(cmd.bop.options.obj_id);
  if (it == info.end()) return object.diameter();
  const double diameter = it->second.diameter_mm * kMetresPerMillimetre;
  std::cerr << "c3po eval: d = " << diameter << " (diameter of obj_id " << cmd.bop.options.obj_id << " in "
            << models_info << ")\n";
  return diameter;
}

// The clouds to evaluate: --data's dataset, or --bop's instances written as
// one into `scratch` (with each instance's depth frame, for the free-space
// test); this --shard part of either.
struct EvalData {
  Dataset dataset;
  DatasetFrames frames;
};
EvalData ReadEvalData(const EvalCommand& cmd, const SegmentOptions& segment, const ObjectModel& object,
                      const std::optional<Shard>& shard, const ScratchFolder& scratch) {
  const std::string empty_part = "this part holds no clouds (choose N at most the number of " +
                                 std::string(cmd.bop.dir.empty() ? "manifest lines)" : "images with usable instances)");
  EvalData data;
  std::string data_dir = cmd.data_dir;
  if (!cmd.bop.dir.empty()) {
    CheckSegmentOptions(segment, "c3po eval");
    auto listed_shared = std::make_shared<const BopInstances>(ListBopInstancesWarning(cmd.bop.dir, cmd.bop.options, "c3po eval"));
    const BopInstances& listed = *listed_shared;
    if (listed.instances.empty()) throw InputError(cmd.bop.dir, "no instances of obj_id " + std::to_string(cmd.bop.options.obj_id));
    // --shard by image, before the instances become a dataset.
    const std::vector<BopInstance> instances = shard ? ShardBopInstances(listed.instances, *shard) : listed.instances;
    if (instances.empty()) throw InputError("--shard " + cmd.shard, empty_part);
    data_dir = scratch.path() + "/dataset";
    const BopDatasetSummary summary = WriteDatasetFromBop(instances, object.keypoints(), segment, data_dir);
    data.frames = BopDatasetFrames(listed_shared, instances, segment);
    for (const std::string& reason : summary.skipped) std::cerr << "c3po eval: skipped " << reason << "\n";
    std::cerr << "c3po eval: " << summary.written << " BOP instances of obj_id " << cmd.bop.options.obj_id << " ("
              << summary.skipped.size() << " skipped)\n";
  }
  data.dataset = ReadDataset(data_dir);
  // --shard by manifest line (a BOP run was sharded above).
  if (shard && cmd.bop.dir.empty()) data.dataset = ShardDataset(data.dataset, *shard);
  if (shard && data.dataset.entries.empty()) throw InputError("--shard " + cmd.shard, empty_part);
  return data;
}

// The per-sample rows (--samples), the JSON document (--json) and the table.
void WriteEvalOutputs(const EvalCommand& cmd, const std::optional<Shard>& shard, const Evaluation& evaluation) {
  if (!cmd.samples_path.empty()) {
    WriteFileAtomically(cmd.samples_path, EvaluationSamplesJsonl(evaluation, shard ? cmd.shard : "1/1"));
    std::cerr << "wrote " << cmd.samples_path << "\n";
  }
  const bool json_to_stdout = cmd.json_path == "-";
  (json_to_stdout ? std::cerr : std::cout) << EvaluationTable(evaluation);
  if (json_to_stdout) {
    std::cout << EvaluationJson(evaluation);
  } else if (!cmd.json_path.empty()) {
    WriteFileAtomically(cmd.json_path, EvaluationJson(evaluation));
    std::cerr << "wrote " << cmd.json_path << "\n";
  }
}

void WriteEvalReport(const EvalCommand& cmd, const ObjectModel& object, const Dataset& dataset,
                     const EvaluationOptions& options, const Evaluation& evaluation, std::vector<TrainingLog> logs) {
  ReportInput report;
  report.evaluation = &evaluation;
  report.training = std::move(logs);
  report.command_line = CommandLine(cmd);
  ReportViewOptions view_options;
  view_options.certified = cmd.report.views;
  view_options.rejected = cmd.report.views;
  if (const EvaluationRow* row = evaluation.MainRow()) {
    report.views = SelectReportViews(object, dataset, *row, options.adds_threshold, view_options);
  }
  WriteReport(cmd.report.path, report);
  std::cerr << "wrote " << cmd.report.path << " (" << report.views.size() << " 3D examples, "
            << report.training.size() << " training logs)\n";
}

int Run(const EvalCommand& cmd) {
  const ObjectModel object = LoadObject(cmd.object_path);
  if (cmd.data_dir.empty() == cmd.bop.dir.empty()) throw InputError("give exactly one of --data DIR or --bop DIR");
  EvaluationOptions options = MakeOptions(cmd, object, EvaluationDiameter(cmd, object));
  cmd.report.Check();
  const std::optional<Shard> shard = cmd.shard.empty() ? std::nullopt : std::optional<Shard>(ParseShard(cmd.shard));
  ScratchFolder scratch;
  SegmentOptions segment = cmd.segment;
  ResolveEvidence(cmd.evidence_erode_mask, options.pipeline.certificate, &segment);
  if (!cmd.bop.dir.empty()) {
    const std::string evidence = DescribeEvidence(segment);
    if (!evidence.empty()) std::cerr << "c3po eval: " << evidence.substr(2) << " (the estimate: the eroded mask)\n";
  }
  const EvalData data = ReadEvalData(cmd, segment, object, shard, scratch);
  if (!cmd.samples_path.empty()) {   // sample files hold the object's rows, not a mixed set's per-object counts
    for (std::size_t i = 0; i < data.dataset.entries.size(); ++i) {
      if (!data.dataset.Shows(i, object.name())) {
        throw InputError(data.dataset.dir, "--samples: the dataset holds other objects' clouds (a mixed set); sample "
                                           "files do not carry its per-object acceptance, so evaluate a mixed set "
                                           "unsharded");
      }
    }
  }
  const std::vector<LoadedDetector> loaded = LoadDetectors(cmd, object);
  std::vector<EvaluatedDetector> detectors;
  for (const auto& d : loaded) detectors.push_back({d.label, d.detector.get(), d.self_trained});
  std::vector<TrainingLog> logs;
  if (!cmd.report.path.empty()) logs = ReadTrainingLogs(cmd, loaded);   // fail before the long work
  CheckEvaluationDataset(object, data.dataset, detectors);              // before the symmetry search
  for (const ModelSymmetry& symmetry :
       ObjectSymmetries(cmd.symmetry, object, "rotation and translation errors to the nearest symmetric truth")) {
    options.symmetries.push_back(symmetry.model_from_model);
  }

  ProgressBar progress("eval", data.dataset.entries.size());
  Evaluation evaluation = Evaluate(object, data.dataset, detectors, options,
                                   [&](std::size_t done, std::size_t) { progress.Update(done); }, data.frames);
  progress.Finish();
  // BOP input: name the BOP folder, not the temporary dataset it became.
  if (!cmd.bop.dir.empty()) evaluation.dataset_dir = cmd.bop.dir;
  WriteEvalOutputs(cmd, shard, evaluation);
  if (!cmd.report.path.empty()) WriteEvalReport(cmd, object, data.dataset, options, evaluation, std::move(logs));
  return 0;
}

}  // namespace

RunFunction SetupEval(CLI::App& command) {
  auto cmd = std::make_shared<EvalCommand>();
  command.add_option("object", cmd->object_path, "Object JSON")->required();
  command.add_option("--data", cmd->data_dir, "Dataset folder with ground truth (manifest.jsonl + clouds)");
  AddBopOptions(command, &cmd->bop, BopDetections::kRefused);
  command.add_option("--models-info", cmd->models_info_path,
                     "BOP models_info.json (default: DIR/../models or DIR/../../models): its diameter is d");
  AddSegmentOptions(command, &cmd->segment);
  AddEvidenceOption(command, &cmd->evidence_erode_mask);
  AddDetectorOptions(command, &cmd->detector, DetectorCount::kMany);
  command.add_option("--selftrained", cmd->selftrained,
                     "Self-trained model file: C-3PO rows (also when a model header says \"selftrained\": true); repeatable")->allow_extra_args(false);
  command.add_option("--adds", cmd->adds_variant, "ADD-S variant: symmetric (default; the paper's final tables) or one-sided");
  command.add_option("--adds-threshold", cmd->adds_threshold, "ADD-S score threshold: distance or fraction of d (default 5%d)");
  command.add_option("--auc-max", cmd->auc_max, "Upper end of the ADD-S AUC curve (default 10%d)");
  AddThresholdOptions(command, &cmd->thresholds, AutoEpsOc::kRefused);
  AddCorrectorOptions(command, &cmd->corrector);
  AddRobustOptions(command, &cmd->robust);
  AddSymmetryOptions(command, &cmd->symmetry, "--no-symmetric-errors",
                     "Rotation and translation errors to the truth alone, even for a symmetric object (default: "
                     "to the nearest of the truth and its symmetric poses)");
  command.add_flag("--no-icp", cmd->no_icp, "Skip the KeyPo + ICP and KeyPo + RANSAC + ICP rows");
  command.add_flag("--no-ransac", cmd->no_ransac, "Skip the KeyPo + RANSAC + ICP rows");
  command.add_option("--ransac-threshold", cmd->ransac_threshold,
                     "KeyPo + RANSAC: keypoint inlier distance, distance or fraction of d (default 5%d)");
  command.add_option("--ransac-iterations", cmd->ransac_iterations,
                     "KeyPo + RANSAC: random triples when there are more (else every triple; default 1000)");
  AddSeedOption(command, &cmd->seed, "of the KeyPo + RANSAC triples; default 0");
  command.add_option("--icp-iterations", cmd->icp_iterations, "ICP iterations (default 30)");
  command.add_option("--icp-max-distance", cmd->icp_max_distance, "ICP correspondence gate (default: none)");
  command.add_option("--icp-trim", cmd->icp_trim, "ICP: fraction of the farthest pairs dropped (default 0)");
  command.add_option("--json", cmd->json_path,
                     "Write everything as JSON to FILE (atomically); '-' = stdout (table on stderr)")
      ->check(WritableFile(true));
  command.add_option("--samples", cmd->samples_path,
                     "Write the per-sample rows as JSON lines (atomically), for c3po merge --eval of --shard parts")
      ->check(WritableFile());
  AddShardOption(command, &cmd->shard, "clouds (by manifest line for --data, by image for --bop)");
  AddReportOptions(command, &cmd->report, "the results table, soundness, ADD-S plots, training curves, 3D examples");
  command.add_option("--training-log", cmd->training_logs,
                     "Training log (JSON lines) for the report; MODEL.log.jsonl next to each model is found automatically")->allow_extra_args(false);
  command.add_option("--worst", cmd->worst, "False certificates listed per row (default 5)");
  return [cmd]() { return Run(*cmd); };
}

}  // namespace c3po::cli
