// c3po certify: detect -> correct -> certify every cloud (CertifyBatch): point
// clouds, dataset entries, a depth frame + mask or BOP instances; JSON
// lines or a human table; exit 0 all certified, 1 some not certified, 2 input
// error. Formatting only: the loop, `--eps-oc auto` and the JSON-lines schema
// are the library's (c3po/method/certify_batch.hpp).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/io/bop.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/io/shard.hpp"
#include "c3po/method/certify_batch.hpp"
#include "c3po/method/image_sources.hpp"
#include "c3po/object/object_io.hpp"
#include "command.hpp"
#include "options.hpp"
#include "progress_bar.hpp"

namespace c3po::cli {
namespace {

struct CertifyCommand {
  std::string object_path;
  DetectorFlags detector;
  std::vector<std::string> clouds;
  std::string data_dir;
  bool json = false;
  std::string output_path;
  ThresholdFlags thresholds;
  CorrectorFlags corrector;
  RobustFlags robust;
  bool no_correct = false;
  // Images (one frame) and BOP datasets (docs/camera_inputs.md).
  FrameFlags frame;
  BopFlags bop;
  SegmentOptions segment;
  std::string bop_csv_path;
  std::string shard;
};

std::string HumanLine(const std::string& cloud, const CloudOutcome& outcome) {
  if (!outcome.processed()) return cloud + "  ERROR  " + outcome.error;
  const PoseEstimate& e = outcome.estimate;
  char text[512];
  if (!e.ok()) {
    std::snprintf(text, sizeof text, "%s  not certified  (registration failed: %s)", cloud.c_str(),
                  ToString(e.correction.registration));
    return text;
  }
  const Eigen::AngleAxisd rotation(e.scene_from_model.R);
  std::snprintf(text, sizeof text,
                "%s  %s  oc=%d (%.4g; %d/%d outliers)  nd=%d (set %d, local %.3g)  t=[%.4f %.4f %.4f]  "
                "angle=%.1f deg  %d it  %.1f ms",
                cloud.c_str(), e.certified() ? "CERTIFIED" : "not certified", e.certificate.oc.passed,
                e.certificate.oc.max_point_distance, e.certificate.oc.outlier_count,
                e.certificate.oc.max_outliers, e.certificate.nd.passed, e.certificate.nd.passing_set,
                e.certificate.nd.local.min_eigenvalue, e.scene_from_model.t(0), e.scene_from_model.t(1),
                e.scene_from_model.t(2), rotation.angle() * 180.0 / M_PI, e.correction.iterations,
                e.milliseconds);
  return text;
}

int Run(const CertifyCommand& cmd) {
  if (cmd.detector.models.size() + cmd.detector.detectors.size() != 1) {
    throw InputError("c3po certify", "give exactly one of --model FILE or --detector NAME");
  }
  const ObjectModel object = LoadObject(cmd.object_path);
  CertifyBatchOptions options;
  options.pipeline.correct = !cmd.no_correct;
  ResolveCorrector(cmd.corrector, &options.pipeline.corrector);
  options.pipeline.certificate = ResolveThresholds(cmd.thresholds, object);
  ResolveRobust(cmd.robust, &options.pipeline.certificate, &options.pipeline.corrector);
  options.auto_eps_oc = cmd.thresholds.auto_eps_oc();
  if (options.auto_eps_oc && !cmd.shard.empty()) {
    throw InputError("--eps-oc", "auto estimates the threshold from all clouds of a run; with --shard give a value");
  }
  CheckSegmentOptions(cmd.segment, "c3po certify");
  const std::optional<Shard> shard = cmd.shard.empty() ? std::nullopt : std::optional<Shard>(ParseShard(cmd.shard));

  std::vector<CloudSource> sources = CloudFileSources(cmd.clouds);
  const auto append = [&sources](const std::vector<CloudSource>& more) {
    sources.insert(sources.end(), more.begin(), more.end());
  };
  // certify does not use ground truth: the manifest's is not even parsed.
  if (!cmd.data_dir.empty()) append(DatasetSources(ReadDataset(cmd.data_dir, /*ground_truth=*/false)));
  if (cmd.frame.given()) append(FrameSources(ResolveFrame(cmd.frame, "c3po certify"), cmd.segment));
  if (!cmd.bop.dir.empty()) {
    const BopInstances listed = ListBopInstances(cmd.bop.dir, cmd.bop.options);
    if (listed.instances.empty()) {
      throw InputError(cmd.bop.dir, "no instances of obj_id " + std::to_string(cmd.bop.options.obj_id) +
                                        (cmd.bop.options.detections_path.empty() ? "" : " in the detections") +
                                        (cmd.bop.options.targets_path.empty() ? "" : " among the targets"));
    }
    append(BopSources(listed, cmd.segment));
  }
  if (sources.empty()) {
    throw InputError("c3po certify", "no clouds given (CLOUD..., --data DIR, --depth/--mask or --bop DIR)");
  }
  if (shard) sources = ShardSources(sources, *shard);
  LoadPlugins(cmd.detector);
  const std::unique_ptr<Detector> detector =
      MakeDetector(cmd.detector.models.empty() ? "" : cmd.detector.models.front(),
                   cmd.detector.detectors.empty() ? "" : cmd.detector.detectors.front(), object);

  ProgressBar progress("certify", sources.size());
  const CertifyBatchResult result = CertifyBatch(object, sources, detector.get(), options,
                                                 [&](std::size_t done, std::size_t) { progress.Update(done); });
  progress.Finish();
  if (result.auto_eps_oc) {
    const AutoEpsOcResult& chosen = *result.auto_eps_oc;
    std::fprintf(stderr, "c3po certify: --eps-oc auto = %.6g (%s; eps_w = %.4g, eps_s = %.4g); evidence %s\n",
                 chosen.eps_oc, chosen.rule.c_str(), chosen.noise.eps_w, chosen.sampling.eps_s,
                 chosen.ToJson().c_str());
  }

  std::ostringstream json_lines;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const CloudOutcome& outcome = result.outcomes[i];
    const std::string& name = sources[i].name;
    if (!outcome.processed()) {
      std::cerr << "c3po certify: " << outcome.error << "\n";
      if (cmd.json || !cmd.output_path.empty()) json_lines << CertifyJsonLine(sources[i], outcome) << "\n";
      continue;
    }
    if (cmd.json || !cmd.output_path.empty()) json_lines << CertifyJsonLine(sources[i], outcome) << "\n";
    if (!cmd.json) std::cout << HumanLine(name, outcome) << "\n";
  }
  if (!cmd.bop_csv_path.empty()) WriteFileAtomically(cmd.bop_csv_path, BopCsv(BopResultRows(sources, result)));
  if (!cmd.output_path.empty()) {
    WriteFileAtomically(cmd.output_path, json_lines.str());
  } else if (cmd.json) {
    std::cout << json_lines.str();
  }
  if (!cmd.json) {
    std::printf("certified %d/%zu (oc %d, nd %d, errors %d); eps_oc = %.6g, delta_nd = %.6g (object units; d = %.6g); "
                "%s\n",
                result.certified, sources.size(), result.oc, result.nd, result.errors, result.certificate.eps_oc,
                result.certificate.delta_nd, object.diameter(),
                DescribeRobust(result.certificate, options.pipeline.corrector).c_str());
  }
  if (result.errors > 0) return 2;
  return result.certified == static_cast<int>(sources.size()) ? 0 : 1;
}

}  // namespace

RunFunction SetupCertify(CLI::App& command) {
  auto cmd = std::make_shared<CertifyCommand>();
  command.add_option("object", cmd->object_path, "Object JSON")->required();
  command.add_option("clouds", cmd->clouds, "Point clouds (PLY, PCD, XYZ)");
  command.add_option("--data", cmd->data_dir, "Dataset folder (manifest.jsonl + clouds)");
  AddDetectorOptions(command, &cmd->detector, DetectorCount::kOne);
  command.add_flag("--json", cmd->json, "One JSON object per cloud on stdout");
  command.add_option("-o,--output", cmd->output_path, "Write the JSON lines to this file (atomically)");
  AddThresholdOptions(command, &cmd->thresholds, AutoEpsOc::kAllowed);
  command.add_flag("--no-correct", cmd->no_correct, "Certify the plain registration of the detected keypoints");
  AddCorrectorOptions(command, &cmd->corrector);
  AddRobustOptions(command, &cmd->robust);
  AddFrameOptions(command, &cmd->frame);
  AddBopOptions(command, &cmd->bop, BopDetections::kAllowed);
  AddSegmentOptions(command, &cmd->segment);
  command.add_option("--bop-csv", cmd->bop_csv_path,
                     "Write BOP results CSV (scene_id,im_id,obj_id,score,R,t,time; t in mm)");
  AddShardOption(command, &cmd->shard, "clouds (by image for --bop, by cloud or manifest line otherwise)");
  return [cmd]() { return Run(*cmd); };
}

}  // namespace c3po::cli
