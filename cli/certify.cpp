// c3po certify: detect -> correct -> certify every cloud; JSON lines or a
// human table; exit 0 all certified, 1 some not certified, 2 input error.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <map>
#include <optional>
#include <sstream>

#include "c3po/base/atomic_file.hpp"
#include "c3po/method/auto_threshold.hpp"
#include "c3po/io/bop.hpp"
#include "c3po/io/camera_io.hpp"
#include "c3po/io/cloud_io.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/io/segment.hpp"
#include "c3po/io/shard.hpp"
#include "c3po/plugins/registry.hpp"
#include "command.hpp"
#include "common.hpp"

namespace c3po::cli {
namespace {

struct CertifyCommand {
  std::string object_path;
  std::string model_path;
  std::string detector_name;
  std::vector<std::string> plugins;
  std::vector<std::string> clouds;
  std::string data_dir;
  bool json = false;
  std::string output_path;
  std::string eps_oc_text;
  std::string delta_nd_text;
  bool no_correct = false;
  std::string solver = "fast";
  std::string loss = "mean";
  // Images (one frame) and BOP datasets (issue 15).
  std::string depth_path;
  std::string mask_path;
  std::string camera_path;
  std::string intrinsics;
  std::optional<double> depth_scale;
  int label_id = -1;
  std::string bop_dir;
  int obj_id = -1;
  std::string targets_path;
  std::string detections_path;
  double min_score = 0.0;
  SegmentOptions segment;
  std::string bop_csv_path;
  std::string shard_text;
};

// One cloud to process: from the command line, a dataset manifest, one
// depth image + mask, or a BOP instance.
struct CloudJob {
  std::string name;
  std::string path;
  std::optional<PointSet> manifest_keypoints;   // --detector manifest
  std::optional<FrameInput> frame;              // --depth/--mask
  std::optional<BopInstance> bop;               // --bop
  std::int64_t group = 0;                       // --shard groups (a BOP image)
  std::optional<SegmentCloud> preloaded;        // the --depth/--mask frame, read up front
};

struct CloudOutcome {
  std::string error;            // non-empty: the cloud could not be processed
  PoseEstimate estimate;
  std::optional<SegmentCloud> segment;   // image inputs: counts (cloud dropped)
  double seconds = 0.0;                  // reading + preprocessing + estimate
};

// Shared by the jobs of a --bop run (detections the instances point into).
struct Sources {
  BopInstances bop;
  std::vector<CloudJob> jobs;
};

CameraInfo CommandCamera(const CertifyCommand& cmd) {
  if (!cmd.camera_path.empty() && !cmd.intrinsics.empty()) {
    throw InputError("c3po certify", "give --camera FILE or --intrinsics fx,fy,cx,cy, not both");
  }
  if (!cmd.camera_path.empty()) return ReadCameraJson(cmd.camera_path, cmd.depth_scale);
  if (cmd.intrinsics.empty()) throw InputError("c3po certify", "--depth needs --camera FILE or --intrinsics fx,fy,cx,cy");
  if (!cmd.depth_scale) throw InputError("c3po certify", "--intrinsics needs --depth-scale S (mm per depth unit)");
  return CameraFromIntrinsics(cmd.intrinsics, *cmd.depth_scale);
}

std::string InstanceName(const BopInstance& instance) {
  char text[96];
  std::snprintf(text, sizeof text, "%06d/%06d_%06d", instance.scene_id, instance.im_id, instance.gt_id);
  return text;
}

void CollectJobs(const CertifyCommand& cmd, Sources* sources) {
  std::vector<CloudJob>& jobs = sources->jobs;
  auto job_named = [](const std::string& name, const std::string& path) {
    CloudJob job;
    job.name = name;
    job.path = path;
    return job;
  };
  for (const auto& path : cmd.clouds) jobs.push_back(job_named(path, path));
  if (!cmd.data_dir.empty()) {
    const Dataset dataset = ReadDataset(cmd.data_dir, /*ground_truth=*/false);
    for (std::size_t i = 0; i < dataset.entries.size(); ++i) {
      const DatasetEntry& entry = dataset.entries[i];
      CloudJob job = job_named(entry.cloud, dataset.CloudPath(i));
      job.manifest_keypoints = entry.detected_keypoints;
      jobs.push_back(std::move(job));
    }
  }
  if (!cmd.depth_path.empty() || !cmd.mask_path.empty()) {
    if (cmd.depth_path.empty() || cmd.mask_path.empty()) throw InputError("c3po certify", "--depth and --mask go together");
    // Read now: a bad depth, mask or camera stops the run before any output.
    FrameInput frame{cmd.depth_path, cmd.mask_path, cmd.label_id, CommandCamera(cmd)};
    CloudJob job = job_named(cmd.mask_path, cmd.mask_path);
    job.frame = frame;
    job.preloaded = LoadFrameSegment(frame, cmd.segment);
    jobs.push_back(std::move(job));
  }
  if (!cmd.bop_dir.empty()) {
    BopOptions options;
    options.obj_id = cmd.obj_id;
    options.targets_path = cmd.targets_path;
    options.detections_path = cmd.detections_path;
    options.min_score = cmd.min_score;
    sources->bop = ListBopInstances(cmd.bop_dir, options);
    for (const BopInstance& instance : sources->bop.instances) {
      const std::string name = InstanceName(instance);
      CloudJob job = job_named(name, name);
      job.bop = instance;
      job.group = static_cast<std::int64_t>(instance.scene_id) * 1000000000LL + instance.im_id;
      jobs.push_back(std::move(job));
    }
    if (sources->bop.instances.empty()) {
      throw InputError(cmd.bop_dir, "no instances of obj_id " + std::to_string(cmd.obj_id) +
                                        (cmd.detections_path.empty() ? "" : " in the detections") +
                                        (cmd.targets_path.empty() ? "" : " among the targets"));
    }
  }
  if (jobs.empty()) throw InputError("c3po certify", "no clouds given (CLOUD..., --data DIR, --depth/--mask or --bop DIR)");
  // Groups: a cloud or manifest line alone, a BOP image's instances together.
  std::int64_t next_group = -1;
  for (CloudJob& job : jobs) {
    if (!job.bop) job.group = next_group--;
  }
  if (!cmd.shard_text.empty()) {
    const Shard shard = ParseShard(cmd.shard_text);
    std::vector<std::int64_t> keys;
    for (const CloudJob& job : jobs) keys.push_back(job.group);
    std::vector<CloudJob> part;
    for (std::size_t i : ShardJobs(keys, shard)) part.push_back(jobs[i]);
    jobs = std::move(part);
  }
  if (cmd.detector_name == "manifest") {
    for (const auto& job : jobs) {
      if (!job.manifest_keypoints) {
        throw InputError(job.path, "--detector manifest needs \"detected_keypoints\" in the manifest line");
      }
    }
  }
}

std::unique_ptr<Detector> MakeDetector(const CertifyCommand& cmd, const ObjectModel& object) {
  for (const auto& plugin : cmd.plugins) LoadPlugin(plugin);
  if (!cmd.model_path.empty()) return LoadDetectorModel(cmd.model_path, object);
  if (cmd.detector_name == "manifest") return nullptr;
  return CreateDetector(cmd.detector_name, object);
}

nlohmann::json PointsJson(const PointSet& points) {
  nlohmann::json list = nlohmann::json::array();
  for (Eigen::Index i = 0; i < points.cols(); ++i) list.push_back({points(0, i), points(1, i), points(2, i)});
  return list;
}

// Provenance keys of image inputs: BOP ids, then the segment's counts.
void AddProvenance(const CloudJob& job, const CloudOutcome& outcome, nlohmann::ordered_json* line) {
  if (job.bop) {
    const BopInstance& b = *job.bop;
    (*line)["scene_id"] = b.scene_id;
    (*line)["im_id"] = b.im_id;
    (*line)["gt_id"] = b.gt_id;
    (*line)["obj_id"] = b.obj_id;
    if (b.detection) (*line)["detection_score"] = b.score;
  }
  if (outcome.segment) {
    const SegmentCloud& s = *outcome.segment;
    (*line)["pixels"] = s.mask_pixels;
    (*line)["no_depth"] = s.no_depth;
    (*line)["removed_erosion"] = s.removed_by_erosion;
    (*line)["removed_discontinuity"] = s.removed_by_discontinuity;
    (*line)["removed_subsampling"] = s.removed_by_subsampling;
    (*line)["points"] = s.pixels.size();
  }
  if (job.bop && job.bop->ground_truth) {
    const Pose& G = *job.bop->ground_truth;
    (*line)["gt_R"] = {{G.R(0, 0), G.R(0, 1), G.R(0, 2)}, {G.R(1, 0), G.R(1, 1), G.R(1, 2)}, {G.R(2, 0), G.R(2, 1), G.R(2, 2)}};
    (*line)["gt_t"] = {G.t(0), G.t(1), G.t(2)};
  }
}

nlohmann::ordered_json EstimateJson(const CloudJob& job, const CloudOutcome& outcome) {
  const PoseEstimate& e = outcome.estimate;
  const Pose& T = e.scene_from_model;
  nlohmann::ordered_json line;  // keys in the documented order, "cloud" first
  line["cloud"] = job.name;
  AddProvenance(job, outcome, &line);
  line["R"] = {{T.R(0, 0), T.R(0, 1), T.R(0, 2)}, {T.R(1, 0), T.R(1, 1), T.R(1, 2)}, {T.R(2, 0), T.R(2, 1), T.R(2, 2)}};
  line["t"] = {T.t(0), T.t(1), T.t(2)};
  line["keypoints"] = PointsJson(e.keypoints);
  line["oc"] = e.certificate.oc.passed;
  line["nd"] = e.certificate.nd.passed;
  line["certified"] = e.certified();
  const double oc_distance = e.certificate.oc.max_point_distance;
  line["oc_distance"] = std::isfinite(oc_distance) ? nlohmann::ordered_json(oc_distance) : nlohmann::ordered_json(nullptr);
  line["keypoint_distance"] = e.certificate.oc.max_keypoint_distance;
  line["nd_set"] = e.certificate.nd.passing_set;
  line["nd_set_distances"] = e.certificate.nd.set_worst_distance;
  line["eps_oc"] = e.certificate.oc.eps_oc;
  line["delta_nd"] = e.certificate.nd.delta_nd;
  line["iterations"] = e.correction.iterations;
  line["cost_before"] = std::isfinite(e.correction.cost_before) ? nlohmann::ordered_json(e.correction.cost_before) : nlohmann::ordered_json(nullptr);
  line["cost_after"] = std::isfinite(e.correction.cost_after) ? nlohmann::ordered_json(e.correction.cost_after) : nlohmann::ordered_json(nullptr);
  line["status"] = ToString(e.correction.registration);
  line["ms"] = e.milliseconds;
  return line;
}

std::string HumanLine(const std::string& cloud, const CloudOutcome& outcome) {
  if (!outcome.error.empty()) return cloud + "  ERROR  " + outcome.error;
  const PoseEstimate& e = outcome.estimate;
  char text[512];
  if (!e.ok()) {
    std::snprintf(text, sizeof text, "%s  not certified  (registration failed: %s)", cloud.c_str(),
                  ToString(e.correction.registration));
    return text;
  }
  const Eigen::AngleAxisd rotation(e.scene_from_model.R);
  std::snprintf(text, sizeof text,
                "%s  %s  oc=%d (%.4g)  nd=%d (set %d)  t=[%.4f %.4f %.4f]  angle=%.1f deg  %d it  %.1f ms",
                cloud.c_str(), e.certified() ? "CERTIFIED" : "not certified", e.certificate.oc.passed,
                e.certificate.oc.max_point_distance, e.certificate.nd.passed,
                e.certificate.nd.passing_set, e.scene_from_model.t(0), e.scene_from_model.t(1),
                e.scene_from_model.t(2), rotation.angle() * 180.0 / M_PI, e.correction.iterations,
                e.milliseconds);
  return text;
}

// --eps-oc auto: estimate eps_oc from the clouds being certified and the oc
// distances just computed (they do not depend on eps_oc), then decide oc again.
double DecideAutoEpsOc(const ObjectModel& object, const std::vector<PointSet>& clouds,
                       bool check_keypoint_agreement, std::vector<CloudOutcome>* outcomes) {
  std::vector<PointSet> usable;
  std::vector<double> oc_distances;
  for (std::size_t i = 0; i < outcomes->size(); ++i) {
    const CloudOutcome& outcome = (*outcomes)[i];
    if (!outcome.error.empty()) continue;
    usable.push_back(clouds[i]);
    if (outcome.estimate.ok()) oc_distances.push_back(outcome.estimate.certificate.oc.max_point_distance);
  }
  const AutoEpsOcResult chosen = EstimateEpsOc(object, usable, AutoEpsOcOptions{}, &oc_distances);
  for (CloudOutcome& outcome : *outcomes) {
    if (outcome.error.empty()) RethresholdObservableCorrectness(&outcome.estimate.certificate.oc, chosen.eps_oc, check_keypoint_agreement);
  }
  std::fprintf(stderr, "c3po certify: --eps-oc auto = %.6g (%s; eps_w = %.4g, eps_s = %.4g); evidence %s\n",
               chosen.eps_oc, chosen.rule.c_str(), chosen.noise.eps_w, chosen.sampling.eps_s, chosen.ToJson().c_str());
  return chosen.eps_oc;
}

// BOP results: one row per BOP instance with a pose; time = the image's
// seconds (every instance of the image, errors included).
std::vector<BopResultRow> BopRows(const std::vector<CloudJob>& jobs, const std::vector<CloudOutcome>& outcomes,
                                  const PipelineOptions& options) {
  std::map<std::pair<int, int>, double> image_seconds;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    if (jobs[i].bop) image_seconds[{jobs[i].bop->scene_id, jobs[i].bop->im_id}] += outcomes[i].seconds;
  }
  std::vector<BopResultRow> rows;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    if (!jobs[i].bop || !outcomes[i].error.empty() || !outcomes[i].estimate.ok()) continue;
    const BopInstance& b = *jobs[i].bop;
    const PoseEstimate& e = outcomes[i].estimate;
    BopResultRow row;
    row.scene_id = b.scene_id;
    row.im_id = b.im_id;
    row.obj_id = b.obj_id;
    row.score = CertificateScore(e.certified(), e.certificate.oc.max_point_distance, options.certificate.eps_oc);
    row.camera_from_model = e.scene_from_model;
    row.time = image_seconds[{b.scene_id, b.im_id}];
    rows.push_back(row);
  }
  return rows;
}

int Run(const CertifyCommand& cmd) {
  if (cmd.model_path.empty() == cmd.detector_name.empty()) {
    throw InputError("c3po certify", "give exactly one of --model FILE or --detector NAME");
  }
  const ObjectModel object = LoadObject(cmd.object_path);
  PipelineOptions options;
  options.correct = !cmd.no_correct;
  options.corrector.solver = ParseCorrectorSolver(cmd.solver);
  options.corrector.loss = ParsePointCloudLoss(cmd.loss);
  options.certificate = CertificateOptions::FromObject(object.spec());
  const bool auto_eps_oc = cmd.eps_oc_text == "auto";
  if (!cmd.eps_oc_text.empty() && !auto_eps_oc) options.certificate.eps_oc = ParseThreshold(cmd.eps_oc_text, object.diameter(), "--eps-oc");
  if (!cmd.delta_nd_text.empty()) options.certificate.delta_nd = ParseThreshold(cmd.delta_nd_text, object.diameter(), "--delta-nd");
  if (auto_eps_oc && !cmd.shard_text.empty()) {
    throw InputError("--eps-oc", "auto estimates the threshold from all clouds of a run; with --shard give a value");
  }
  try {
    cmd.segment.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError("c3po certify", e.what());
  }
  Sources sources;
  CollectJobs(cmd, &sources);
  const std::vector<CloudJob>& jobs = sources.jobs;
  const std::unique_ptr<Detector> detector = MakeDetector(cmd, object);

  std::vector<CloudOutcome> outcomes(jobs.size());
  std::vector<PointSet> clouds(auto_eps_oc ? jobs.size() : 0);   // kept for --eps-oc auto
  ProgressBar progress("certify", jobs.size());
  std::atomic<std::size_t> done{0};
  ParallelFor(0, static_cast<int>(jobs.size()), [&](int i) {
    ThrowIfInterrupted();
    const CloudJob& job = jobs[i];
    const auto start = std::chrono::steady_clock::now();
    try {
      PointSet cloud;
      if (job.frame || job.bop) {
        SegmentCloud segment = job.preloaded ? *job.preloaded : LoadBopInstance(*job.bop, cmd.segment);
        cloud = std::move(segment.cloud);
        segment.cloud.resize(3, 0);   // the counts stay for the output
        outcomes[i].segment = std::move(segment);
        if (cloud.cols() < kMinSegmentPoints) {
          SegmentCloud counts = *outcomes[i].segment;
          counts.cloud = cloud;
          RequireUsableSegment(counts, job.name);   // throws the reason
        }
      } else {
        cloud = ReadCloud(job.path);
      }
      const PointSet detected = detector ? detector->Detect(cloud) : *job.manifest_keypoints;
      if (detected.cols() != object.num_keypoints()) {
        throw InputError(job.path, "detected " + std::to_string(detected.cols()) + " keypoints, object has " +
                                       std::to_string(object.num_keypoints()));
      }
      outcomes[i].estimate = EstimateAndCertify(object, cloud, detected, options);
      if (auto_eps_oc) clouds[i] = cloud;
    } catch (const InputError& e) {
      outcomes[i].error = e.what();
    }
    outcomes[i].seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    progress.Update(++done);
  });
  progress.Finish();

  if (auto_eps_oc) options.certificate.eps_oc = DecideAutoEpsOc(object, clouds, options.certificate.check_keypoint_agreement, &outcomes);

  std::ostringstream json_lines;
  int certified = 0, oc = 0, nd = 0, errors = 0;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const CloudOutcome& outcome = outcomes[i];
    if (!outcome.error.empty()) {
      ++errors;
      std::cerr << "c3po certify: " << outcome.error << "\n";
      if (cmd.json || !cmd.output_path.empty()) {
        nlohmann::ordered_json line;
        line["cloud"] = jobs[i].name;
        AddProvenance(jobs[i], outcome, &line);
        line["error"] = outcome.error;
        json_lines << line.dump() << "\n";
      }
      continue;
    }
    certified += outcome.estimate.certified();
    oc += outcome.estimate.certificate.oc.passed;
    nd += outcome.estimate.certificate.nd.passed;
    if (cmd.json || !cmd.output_path.empty()) json_lines << EstimateJson(jobs[i], outcome).dump() << "\n";
    if (!cmd.json) std::cout << HumanLine(jobs[i].name, outcome) << "\n";
  }
  if (!cmd.bop_csv_path.empty()) WriteFileAtomically(cmd.bop_csv_path, BopCsv(BopRows(jobs, outcomes, options)));
  if (!cmd.output_path.empty()) {
    WriteFileAtomically(cmd.output_path, json_lines.str());
  } else if (cmd.json) {
    std::cout << json_lines.str();
  }
  if (!cmd.json) {
    std::printf("certified %d/%zu (oc %d, nd %d, errors %d); eps_oc = %.6g, delta_nd = %.6g (object units; d = %.6g)\n",
                certified, jobs.size(), oc, nd, errors, options.certificate.eps_oc,
                options.certificate.delta_nd, object.diameter());
  }
  if (errors > 0) return 2;
  return certified == static_cast<int>(jobs.size()) ? 0 : 1;
}

}  // namespace

RunFunction SetupCertify(CLI::App& command) {
  auto cmd = std::make_shared<CertifyCommand>();
  command.add_option("object", cmd->object_path, "Object JSON")->required();
  command.add_option("clouds", cmd->clouds, "Point clouds (PLY, PCD, XYZ)");
  command.add_option("--data", cmd->data_dir, "Dataset folder (manifest.jsonl + clouds)");
  command.add_option("--model", cmd->model_path, "Trained detector model file");
  command.add_option("--detector", cmd->detector_name,
                     "Detector without a model file (svd, manifest = the manifest's detected_keypoints, or a plugin's)");
  command.add_option("--plugin", cmd->plugins, "Load a detector plugin (shared library); repeatable");
  command.add_flag("--json", cmd->json, "One JSON object per cloud on stdout");
  command.add_option("-o,--output", cmd->output_path, "Write the JSON lines to this file (atomically)");
  command.add_option("--eps-oc", cmd->eps_oc_text, "Observable-correctness threshold: distance, fraction of d (3%d) or auto (estimated from the clouds)");
  command.add_option("--delta-nd", cmd->delta_nd_text, "Non-degeneracy threshold: distance or fraction of d");
  command.add_flag("--no-correct", cmd->no_correct, "Certify the plain registration of the detected keypoints");
  command.add_option("--solver", cmd->solver, "Corrector solver: fast (default) or gd (the reference's)");
  command.add_option("--loss", cmd->loss, "Point-cloud loss: mean (paper, default) or max (reference code)");
  // Depth images and masks (docs/camera_inputs.md).
  command.add_option("--depth", cmd->depth_path, "Depth image: 16-bit PNG (value x depth_scale = mm) or .npy float metres");
  command.add_option("--mask", cmd->mask_path, "Mask PNG (8/16-bit; non-zero = object, or --label-id)");
  command.add_option("--label-id", cmd->label_id, "Mask is a label image: the object's pixels have this value");
  command.add_option("--camera", cmd->camera_path, "Camera JSON (cam_K row-major + depth_scale; BOP camera.json or scene_camera.json entry)");
  command.add_option("--intrinsics", cmd->intrinsics, "fx,fy,cx,cy (instead of --camera)");
  command.add_option("--depth-scale", cmd->depth_scale, "Millimetres per depth unit (overrides the camera file's)");
  command.add_option("--bop", cmd->bop_dir, "BOP scene folder or split folder of numbered scenes");
  command.add_option("--obj-id", cmd->obj_id, "BOP object id to certify (with --bop)");
  command.add_option("--targets", cmd->targets_path, "BOP targets JSON (test_targets_bop19.json): only these images");
  command.add_option("--detections", cmd->detections_path, "BOP/COCO detections JSON (RLE masks) instead of ground-truth masks");
  command.add_option("--min-score", cmd->min_score, "Skip detections scoring below this")->capture_default_str();
  command.add_option("--erode-mask", cmd->segment.erode_mask, "Erode masks by K pixels (0 = off)")->capture_default_str();
  command.add_option("--depth-edge", cmd->segment.max_relative_depth_step,
                     "Drop pixels whose depth differs from a neighbour's by more than this fraction of their depth (0 = off)")->capture_default_str();
  command.add_option("--max-points", cmd->segment.max_points, "At most this many points per image segment, evenly strided (0 = all)")->capture_default_str();
  command.add_option("--bop-csv", cmd->bop_csv_path, "Write BOP results CSV (scene_id,im_id,obj_id,score,R,t,time; t in mm)");
  command.add_option("--shard", cmd->shard_text, "Process part K of N (K/N, 1-based): disjoint, deterministic; merge with c3po merge");
  return [cmd]() { return Run(*cmd); };
}

}  // namespace c3po::cli
