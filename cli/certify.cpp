// c3po certify: detect -> correct -> certify every cloud (CertifyBatch): point
// clouds, dataset entries, a depth frame + mask or BOP instances; JSON
// lines or a human table; exit 0 all certified, 1 some not certified, 2 input
// error. Formatting only: the loop, `--eps-oc auto` and the JSON-lines schema
// are the library's (c3po/method/certify_batch.hpp).
#include <algorithm>
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
#include "c3po/io/pose_list.hpp"
#include "c3po/io/shard.hpp"
#include "c3po/method/certify_batch.hpp"
#include "c3po/method/given_poses.hpp"
#include "c3po/method/image_sources.hpp"
#include "c3po/method/refusal.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/web/certify_report.hpp"
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
  std::string evidence_erode_mask = "auto";   // resolved into segment by ResolveEvidence
  std::string bop_csv_path;
  std::string shard;
  std::string poses_path;   // certify given poses (docs/method.md "Certifying poses from any estimator")
  std::vector<std::string> other_object_paths;   // identity among known objects (identity_check.hpp)
  ReportFlags report;       // --report, --views: the certify report (web/certify_report.hpp)
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
  if (e.certified()) return text;
  return std::string(text) + "  refused by " + RefusalSummary(e.certificate);
}

// "eps_oc = ..., delta_nd = ... (object units; d = ...); m = 2%, robust loss = ...[; evidence: ...]
// [; other objects: J.json, ...]".
std::string Settings(const CertificateOptions& certificate, const CertifyBatchOptions& options,
                     const ObjectModel& object, const std::string& evidence) {
  char text[160];
  std::snprintf(text, sizeof text, "eps_oc = %.6g, delta_nd = %.6g (object units; d = %.6g); ", certificate.eps_oc,
                certificate.delta_nd, object.diameter());
  std::string identity;
  for (const KnownObject& other : options.other_objects) identity += (identity.empty() ? "" : ", ") + other.name;
  if (!identity.empty()) identity = "; other objects: " + identity;
  return text + DescribeRobust(certificate, options.pipeline.corrector) + evidence + identity;
}

// "; refused by nd_global 36, oc 10": every failed part counted once per
// refused pose (CountRefusals), in the order the certificate decides them;
// "" when none was refused.
std::string RefusalTally(const CertifyBatchResult& result) {
  std::string tally;
  for (const RefusalCount& count : CountRefusals(result.outcomes)) {
    if (count.failed == 0) continue;
    tally += (tally.empty() ? "; refused by " : ", ") + count.name + " " + std::to_string(count.failed);
  }
  return tally;
}

// What was certified, for the report: "BOP DIR, obj_id K", "dataset DIR", ...
std::string DescribeInputs(const CertifyCommand& cmd, std::size_t sources) {
  std::string inputs;
  if (!cmd.bop.dir.empty()) inputs = "BOP " + cmd.bop.dir + ", obj_id " + std::to_string(cmd.bop.options.obj_id);
  else if (!cmd.data_dir.empty()) inputs = "dataset " + cmd.data_dir;
  else if (cmd.frame.given()) inputs = "depth " + cmd.frame.depth_path + ", mask " + cmd.frame.mask_path;
  else inputs = std::to_string(sources) + " cloud file" + (sources == 1 ? "" : "s");
  if (!cmd.poses_path.empty()) inputs += ", poses " + cmd.poses_path;
  if (!cmd.shard.empty()) inputs += ", shard " + cmd.shard;
  return inputs;
}

// --report FILE: counts by refusing part and 3D examples (web/certify_report.hpp).
void WriteReportIfAsked(const CertifyCommand& cmd, const ObjectModel& object, const std::vector<CloudSource>& sources,
                        const CertifyBatchResult& result, const std::string& settings) {
  if (cmd.report.path.empty()) return;
  ReportViewOptions views;
  views.certified = views.rejected = cmd.report.views;
  CertifyReportInput input;
  input.object_name = object.spec().name;
  input.diameter = object.diameter();
  input.inputs = DescribeInputs(cmd, sources.size());
  input.settings = settings;
  input.result = &result;
  input.views = CertifyReportViews(object, sources, result, views);
  WriteCertifyReport(cmd.report.path, input);
  std::cerr << "wrote " << cmd.report.path << " (" << input.views.size() << " 3D examples)\n";
}

// The certify JSON line of a given pose (with the source's keys: a BOP
// instance's ids, segment counts and ground truth, as `certify --bop` writes
// them), with the hypothesis and the change the correction made appended
// (docs/method.md "Certifying poses from any estimator").
std::string GivenPoseJsonLine(const CloudSource& source, const CloudOutcome& outcome,
                              const PoseHypothesis& pose, bool chosen) {
  std::string line = CertifyJsonLine(source, outcome);
  line.pop_back();   // the closing brace
  const PoseChange change = ChangeBetween(pose.scene_from_model, outcome.estimate.scene_from_model);
  char extra[256];
  std::snprintf(extra, sizeof extra,
                ",\"pose_line\":%d,\"score\":%.17g,\"rotation_change_deg\":%.17g,\"translation_change\":%.17g,"
                "\"chosen\":%s}",
                pose.line, pose.score, change.rotation_degrees, change.translation, chosen ? "true" : "false");
  return line + extra;
}

// The hypotheses matched to this shard's clouds. With --shard, `clouds` is this shard's part of
// `all_clouds`: hypotheses that match only sources of other shards are theirs, not unmatched
// (counted in `other_shards`).
GivenPoseSources MatchThisShard(const ObjectModel& object, const std::vector<CloudSource>& clouds,
                                const std::vector<CloudSource>& all_clouds, const std::vector<PoseHypothesis>& poses,
                                std::size_t* other_shards) {
  GivenPoseSources matched = MatchGivenPoses(object, clouds, poses);
  *other_shards = 0;
  if (clouds.size() == all_clouds.size()) return matched;
  const std::vector<std::size_t> unmatched_anywhere = MatchGivenPoses(object, all_clouds, poses).unmatched;
  const std::vector<std::size_t> here = matched.unmatched;
  matched.unmatched.clear();
  for (std::size_t h : here) {
    if (std::find(unmatched_anywhere.begin(), unmatched_anywhere.end(), h) != unmatched_anywhere.end()) {
      matched.unmatched.push_back(h);
    } else {
      ++*other_shards;
    }
  }
  return matched;
}

// One stderr line per unmatched hypothesis, one for those of other objects and one for other shards'.
void ReportPosesNotCertified(const std::string& poses_path, const std::vector<PoseHypothesis>& poses,
                             const GivenPoseSources& matched, std::size_t other_shards) {
  for (std::size_t h : matched.unmatched) {
    const PoseHypothesis& pose = poses[h];
    const std::string of_object = pose.obj_id ? " of obj_id " + std::to_string(*pose.obj_id) : "";
    std::cerr << "c3po certify: " << poses_path << ": line " << pose.line << ": "
              << (pose.cloud.empty() ? "no BOP instance" + of_object + " in scene/image '" + PoseMatchKey(pose) + "'"
                                     : "no cloud named '" + pose.cloud + "'")
              << " (unmatched)\n";
  }
  if (!matched.other_object.empty()) {
    std::cerr << "c3po certify: " << poses_path << ": " << matched.other_object.size()
              << " line(s) for other obj_ids skipped (first: line " << poses[matched.other_object.front()].line
              << ", obj_id " << *poses[matched.other_object.front()].obj_id << ")\n";
  }
  if (other_shards > 0) {
    std::cerr << "c3po certify: " << poses_path << ": " << other_shards << " line(s) for other shards skipped\n";
  }
}

// Per matched hypothesis its JSON line (and human line without --json), then an error line per
// unmatched one; `errors` counts the hypotheses that could not be processed.
std::string GivenPoseLines(const CertifyCommand& cmd, const GivenPoseSources& matched,
                           const std::vector<PoseHypothesis>& poses, const CertifyBatchResult& result,
                           const std::vector<bool>& chosen, int* errors) {
  std::ostringstream json_lines;
  for (std::size_t s = 0; s < matched.sources.size(); ++s) {
    const CloudOutcome& outcome = result.outcomes[s];
    const PoseHypothesis& pose = poses[matched.hypothesis[s]];
    const std::string& name = matched.sources[s].name;
    if (!outcome.processed()) {
      ++*errors;
      std::cerr << "c3po certify: " << outcome.error << "\n";
      if (cmd.json) json_lines << CertifyErrorJsonLine(name, outcome.error) << "\n";
      continue;
    }
    if (cmd.json || !cmd.output_path.empty()) {
      json_lines << GivenPoseJsonLine(matched.sources[s], outcome, pose, chosen[s]) << "\n";
    }
    if (!cmd.json) {
      const PoseChange change = ChangeBetween(pose.scene_from_model, outcome.estimate.scene_from_model);
      std::printf("%s  change %.3g deg, %.4g%s\n", HumanLine(name, outcome).c_str(), change.rotation_degrees,
                  change.translation, chosen[s] ? "  CHOSEN" : "");
    }
  }
  for (std::size_t h : matched.unmatched) {
    if (cmd.json) {
      json_lines << CertifyErrorJsonLine(PoseMatchKey(poses[h]),
                                         cmd.poses_path + ": line " + std::to_string(poses[h].line) + ": unmatched")
                 << "\n";
    }
  }
  return json_lines.str();
}

// c3po certify --poses: every hypothesis matched to a cloud is certified; per
// instance the certified one with the best fit is chosen (given_poses.hpp).
int RunGivenPoses(const CertifyCommand& cmd, const ObjectModel& object, const CertifyBatchOptions& options,
                  const std::vector<CloudSource>& clouds, const std::vector<CloudSource>& all_clouds,
                  const std::string& evidence) {
  const std::vector<PoseHypothesis> poses = ReadPoseList(cmd.poses_path);
  std::size_t other_shards = 0;
  const GivenPoseSources matched = MatchThisShard(object, clouds, all_clouds, poses, &other_shards);
  ReportPosesNotCertified(cmd.poses_path, poses, matched, other_shards);
  ProgressBar progress("certify", matched.sources.size());
  const CertifyBatchResult result =
      matched.sources.empty() ? CertifyBatchResult{}
                              : CertifyBatch(object, matched.sources, nullptr, options,
                                             [&](std::size_t done, std::size_t) { progress.Update(done); });
  progress.Finish();
  const std::vector<InstanceVerdict> verdicts = ChooseCertified(matched, poses, result);
  std::vector<bool> chosen(matched.sources.size(), false);
  for (const auto& v : verdicts) {
    if (v.chosen) chosen[*v.chosen] = true;
  }
  int errors = static_cast<int>(matched.unmatched.size());
  const std::string json_lines = GivenPoseLines(cmd, matched, poses, result, chosen, &errors);
  if (!cmd.bop_csv_path.empty()) {
    std::vector<std::size_t> written;   // one row per instance: its chosen (else best-fitting) hypothesis
    for (const auto& v : verdicts) {
      if (v.best_fit) written.push_back(*v.best_fit);
    }
    WriteFileAtomically(cmd.bop_csv_path, BopCsv(BopResultRows(matched.sources, result, written)));
  }
  WriteReportIfAsked(cmd, object, matched.sources, result, Settings(result.certificate, options, object, evidence));
  if (!cmd.output_path.empty()) {
    WriteFileAtomically(cmd.output_path, json_lines);
  } else if (cmd.json) {
    std::cout << json_lines;
  }
  int instances_certified = 0;
  for (const auto& v : verdicts) instances_certified += v.chosen ? 1 : 0;
  if (!cmd.json) {
    for (const auto& v : verdicts) {
      const std::string verdict =
          v.chosen ? "certified hypothesis: line " + std::to_string(poses[matched.hypothesis[*v.chosen]].line)
                   : "no certified hypothesis";
      std::printf("%s: %s\n", clouds[v.instance].name.c_str(), verdict.c_str());
    }
    std::printf("instances with a certified pose %d/%zu (hypotheses %zu, unmatched %zu, errors %d; "
                "%zu of %zu sources had no hypothesis)\n",
                instances_certified, verdicts.size(), matched.sources.size(), matched.unmatched.size(),
                errors - static_cast<int>(matched.unmatched.size()), clouds.size() - verdicts.size(), clouds.size());
  }
  if (errors > 0) return 2;
  return instances_certified == static_cast<int>(verdicts.size()) && !verdicts.empty() ? 0 : 1;
}

// Depth frames (--depth/--mask, --bop) rather than ready-made clouds.
bool CameraInput(const CertifyCommand& cmd) { return cmd.frame.given() || !cmd.bop.dir.empty(); }

// The batch options from the flags: corrector, thresholds, and the measured
// defaults of camera inputs (options.hpp InputKind), printed in the summary
// and carried by every JSON line.
CertifyBatchOptions CertifyOptions(const CertifyCommand& cmd, const ObjectModel& object) {
  CertifyBatchOptions options;
  options.pipeline.correct = !cmd.no_correct;
  ResolveCorrector(cmd.corrector, &options.pipeline.corrector);
  options.pipeline.certificate = ResolveThresholds(cmd.thresholds, object);
  const InputKind input = CameraInput(cmd) ? InputKind::kCameraFrames : InputKind::kClouds;
  ResolveRobust(cmd.robust, input, object, &options.pipeline.certificate, &options.pipeline.corrector);
  options.auto_eps_oc = cmd.thresholds.auto_eps_oc();
  if (options.auto_eps_oc && !cmd.shard.empty()) {
    throw InputError("--eps-oc", "auto estimates the threshold from all clouds of a run; with --shard give a value");
  }
  CheckSegmentOptions(cmd.segment, "c3po certify");
  return options;
}

// --other-objects: each object's certifier as this command would run it on
// that object (its own eps_oc and delta_nd from the same flags, the
// training-free SVD detector), kept alive for the batch.
struct OtherObjects {
  std::vector<std::unique_ptr<ObjectModel>> objects;
  std::vector<std::unique_ptr<Detector>> detectors;
};

void AddOtherObjects(const CertifyCommand& cmd, const ObjectModel& object, OtherObjects* others,
                     CertifyBatchOptions* options) {
  if (cmd.other_object_paths.empty()) return;
  if (options->auto_eps_oc) {
    throw InputError("--other-objects", "each object's certifier needs an eps_oc given, not auto");
  }
  for (const std::string& path : cmd.other_object_paths) {
    others->objects.push_back(std::make_unique<ObjectModel>(LoadObject(path)));
    const ObjectModel& other = *others->objects.back();
    if (other.spec().name == object.spec().name && other.num_keypoints() == object.num_keypoints() &&
        other.diameter() == object.diameter()) {
      throw InputError(path, "is the object being certified, not another one");
    }
    others->detectors.push_back(MakeDetector("", "svd", other));
    KnownObject known;
    known.name = path;
    known.object = &other;
    known.detector = others->detectors.back().get();
    known.pipeline = CertifyOptions(cmd, other).pipeline;
    options->other_objects.push_back(std::move(known));
  }
}

// Every cloud given: cloud files, --data's dataset, a --depth/--mask frame,
// --bop's instances, in that order.
std::vector<CloudSource> CertifySources(const CertifyCommand& cmd, const SegmentOptions& segment) {
  std::vector<CloudSource> sources = CloudFileSources(cmd.clouds);
  const auto append = [&sources](const std::vector<CloudSource>& more) {
    sources.insert(sources.end(), more.begin(), more.end());
  };
  // certify does not use ground truth: the manifest's is not even parsed.
  if (!cmd.data_dir.empty()) append(DatasetSources(ReadDataset(cmd.data_dir, /*ground_truth=*/false)));
  if (cmd.frame.given()) append(FrameSources(ResolveFrame(cmd.frame, "c3po certify"), segment));
  if (!cmd.bop.dir.empty()) {
    const BopInstances listed = ListBopInstancesWarning(cmd.bop.dir, cmd.bop.options, "c3po certify");
    if (listed.instances.empty()) {
      throw InputError(cmd.bop.dir, "no instances of obj_id " + std::to_string(cmd.bop.options.obj_id) +
                                        (cmd.bop.options.detections_path.empty() ? "" : " in the detections") +
                                        (cmd.bop.options.targets_path.empty() ? "" : " among the targets"));
    }
    append(BopSources(listed, segment));
  }
  if (sources.empty()) {
    throw InputError("no clouds given (CLOUD..., --data DIR, --depth/--mask or --bop DIR)");
  }
  return sources;
}

// The human lines or JSON lines (stdout or -o), errors on stderr, --bop-csv.
void WriteCertifyResults(const CertifyCommand& cmd, const std::vector<CloudSource>& sources,
                         const CertifyBatchResult& result) {
  std::ostringstream json_lines;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const CloudOutcome& outcome = result.outcomes[i];
    if (!outcome.processed()) std::cerr << "c3po certify: " << outcome.error << "\n";
    if (cmd.json || !cmd.output_path.empty()) json_lines << CertifyJsonLine(sources[i], outcome) << "\n";
    if (outcome.processed() && !cmd.json) std::cout << HumanLine(sources[i].name, outcome) << "\n";
  }
  if (!cmd.bop_csv_path.empty()) WriteFileAtomically(cmd.bop_csv_path, BopCsv(BopResultRows(sources, result)));
  if (!cmd.output_path.empty()) {
    WriteFileAtomically(cmd.output_path, json_lines.str());
  } else if (cmd.json) {
    std::cout << json_lines.str();
  }
}

int Run(const CertifyCommand& cmd) {
  const std::size_t detectors = cmd.detector.models.size() + cmd.detector.detectors.size();
  if (!cmd.poses_path.empty() && detectors != 0) {
    throw InputError("--poses replaces the detector: give no --model / --detector with it");
  }
  if (cmd.poses_path.empty() && detectors != 1) {
    throw InputError("give exactly one of --model FILE, --detector NAME or --poses FILE");
  }
  cmd.report.Check();
  const ObjectModel object = LoadObject(cmd.object_path);
  CertifyBatchOptions options = CertifyOptions(cmd, object);
  OtherObjects others;
  AddOtherObjects(cmd, object, &others, &options);
  const std::optional<Shard> shard = cmd.shard.empty() ? std::nullopt : std::optional<Shard>(ParseShard(cmd.shard));
  SegmentOptions segment = cmd.segment;
  ResolveEvidence(cmd.evidence_erode_mask, options.pipeline.certificate, &segment);
  std::vector<CloudSource> sources = CertifySources(cmd, segment);
  const std::string evidence = CameraInput(cmd) ? DescribeEvidence(segment) : "";
  const std::vector<CloudSource> all_sources = shard && !cmd.poses_path.empty() ? sources : std::vector<CloudSource>{};
  if (shard) sources = ShardSources(sources, *shard);
  if (!cmd.poses_path.empty()) {
    return RunGivenPoses(cmd, object, options, sources, shard ? all_sources : sources, evidence);
  }
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
  WriteCertifyResults(cmd, sources, result);
  const std::string settings = Settings(result.certificate, options, object, evidence);
  if (!cmd.json) {
    std::printf("certified %d/%zu (oc %d, nd %d, errors %d); %s%s\n", result.certified, sources.size(), result.oc,
                result.nd, result.errors, settings.c_str(), RefusalTally(result).c_str());
  }
  WriteReportIfAsked(cmd, object, sources, result, settings);
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
  command.add_option("-o,--output", cmd->output_path, "Write the JSON lines to this file (atomically)")
      ->check(WritableFile());
  AddThresholdOptions(command, &cmd->thresholds, AutoEpsOc::kAllowed);
  command.add_flag("--no-correct", cmd->no_correct,
                   "Certify the plain registration of the detected keypoints (with --poses: the given pose as is)");
  command.add_option("--poses", cmd->poses_path,
                     "Certify these poses (BOP results CSV or JSON lines with cloud, R, t) instead of detecting; "
                     "matched to the clouds by name, BOP rows to every instance of their obj_id in their image (docs/method.md)");
  AddCorrectorOptions(command, &cmd->corrector);
  AddRobustOptions(command, &cmd->robust);
  AddFrameOptions(command, &cmd->frame);
  AddBopOptions(command, &cmd->bop, BopDetections::kAllowed);
  AddSegmentOptions(command, &cmd->segment);
  AddEvidenceOption(command, &cmd->evidence_erode_mask);
  command.add_option("--bop-csv", cmd->bop_csv_path,
                     "Write BOP results CSV (scene_id,im_id,obj_id,score,R,t,time; t in mm; score: certified first); "
                     "with --poses one row per instance: its chosen hypothesis, else its best fit")
      ->check(WritableFile());
  AddShardOption(command, &cmd->shard, "clouds (by image for --bop, by cloud or manifest line otherwise)");
  command
      .add_option("--other-objects", cmd->other_object_paths,
                  "Other known objects (object JSON, repeatable or comma-separated): a pose is certified only if none "
                  "of their certifiers (SVD detector, their own thresholds) certifies the cloud too "
                  "(refused_by identity; docs/method.md \"Identity among known objects\")")
      ->delimiter(',')
      ->allow_extra_args(false);
  AddReportOptions(command, &cmd->report,
                   "poses certified and refused by each certificate part, 3D examples with the reason and the "
                   "rival pose");
  return [cmd]() { return Run(*cmd); };
}

}  // namespace c3po::cli
