// c3po certify: detect -> correct -> certify every cloud; JSON lines or a
// human table; exit 0 all certified, 1 some not certified, 2 input error.
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "c3po/base/atomic_file.hpp"
#include "c3po/method/auto_threshold.hpp"
#include "c3po/io/cloud_io.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/plugins/registry.hpp"
#include "command.hpp"
#include "common.hpp"
#include "robust_options.hpp"

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
  RobustCliOptions robust;
};

// One cloud to process: from the command line or from a dataset manifest.
struct CloudJob {
  std::string name;
  std::string path;
  std::optional<PointSet> manifest_keypoints;   // --detector manifest
};

struct CloudOutcome {
  std::string error;            // non-empty: the cloud could not be processed
  PoseEstimate estimate;
};

std::vector<CloudJob> CollectJobs(const CertifyCommand& cmd) {
  std::vector<CloudJob> jobs;
  for (const auto& path : cmd.clouds) jobs.push_back({path, path, std::nullopt});
  if (!cmd.data_dir.empty()) {
    const Dataset dataset = ReadDataset(cmd.data_dir);
    for (std::size_t i = 0; i < dataset.entries.size(); ++i) {
      const DatasetEntry& entry = dataset.entries[i];
      jobs.push_back({entry.cloud, dataset.CloudPath(i), entry.detected_keypoints});
    }
  }
  if (jobs.empty()) throw InputError("c3po certify", "no clouds given (CLOUD... or --data DIR)");
  if (cmd.detector_name == "manifest") {
    for (const auto& job : jobs) {
      if (!job.manifest_keypoints) {
        throw InputError(job.path, "--detector manifest needs \"detected_keypoints\" in the manifest line");
      }
    }
  }
  return jobs;
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

// Outlier indices in the JSON line are capped (the count is always exact).
constexpr std::size_t kMaxListedOutliers = 100;

nlohmann::ordered_json EstimateJson(const std::string& cloud, const PoseEstimate& e) {
  const Pose& T = e.scene_from_model;
  nlohmann::ordered_json line;  // keys in the documented order, "cloud" first
  line["cloud"] = cloud;
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
  // Outlier-robust evidence (issue 16).
  const ObservableCorrectness& oc = e.certificate.oc;
  const NonDegeneracy& nd = e.certificate.nd;
  auto finite = [](double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr); };
  line["max_outliers"] = oc.max_outliers;
  line["outliers"] = oc.outlier_count;
  const std::size_t listed = std::min(oc.outlier_indices.size(), kMaxListedOutliers);
  line["outlier_indices"] = std::vector<int>(oc.outlier_indices.begin(), oc.outlier_indices.begin() + listed);
  line["outlier_indices_truncated"] = listed < oc.outlier_indices.size();
  line["distance_quantiles"] = {finite(oc.quantile50), finite(oc.quantile90), finite(oc.quantile99), finite(oc.max_point_distance)};
  line["max_inlier_distance"] = oc.max_inlier_distance;
  line["keypoint_support"] = nd.keypoint_support;
  line["nd_set_support"] = nd.set_min_support;
  line["nd_sets"] = nd.sets_passed;
  line["nd_local"] = nd.local_checked ? nlohmann::ordered_json(nd.local.passed) : nlohmann::ordered_json(nullptr);
  line["nd_local_eigenvalue"] = nd.local.min_eigenvalue;
  line["nd_local_motion"] = {nd.local.motion(0), nd.local.motion(1), nd.local.motion(2),
                             nd.local.motion(3), nd.local.motion(4), nd.local.motion(5)};
  line["nd_local_rank"] = nd.local.model_rank;
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
                "%s  %s  oc=%d (%.4g; %d/%d outliers)  nd=%d (set %d, local %.3g)  t=[%.4f %.4f %.4f]  angle=%.1f deg  %d it  %.1f ms",
                cloud.c_str(), e.certified() ? "CERTIFIED" : "not certified", e.certificate.oc.passed,
                e.certificate.oc.max_point_distance, e.certificate.oc.outlier_count, e.certificate.oc.max_outliers,
                e.certificate.nd.passed, e.certificate.nd.passing_set, e.certificate.nd.local.min_eigenvalue, e.scene_from_model.t(0), e.scene_from_model.t(1),
                e.scene_from_model.t(2), rotation.angle() * 180.0 / M_PI, e.correction.iterations,
                e.milliseconds);
  return text;
}

// --eps-oc auto: estimate eps_oc from the clouds being certified and the oc
// distances just computed (they do not depend on eps_oc), then decide oc again.
// With a budget m the distance used is each cloud's (m+1)-th largest point
// distance (robust: the m farthest points never set eps_oc), and both
// certificates are decided again (nd_m depends on the accepted points).
double DecideAutoEpsOc(const ObjectModel& object, const std::vector<PointSet>& clouds,
                       const CertificateOptions& certificate, std::vector<CloudOutcome>* outcomes) {
  std::vector<PointSet> usable;
  std::vector<double> oc_distances;
  for (std::size_t i = 0; i < outcomes->size(); ++i) {
    const CloudOutcome& outcome = (*outcomes)[i];
    if (!outcome.error.empty()) continue;
    usable.push_back(clouds[i]);
    if (outcome.estimate.ok()) oc_distances.push_back(outcome.estimate.certificate.oc.budget_distance);
  }
  const AutoEpsOcResult chosen = EstimateEpsOc(object, usable, AutoEpsOcOptions{}, &oc_distances);
  CertificateOptions decided = certificate;
  decided.eps_oc = chosen.eps_oc;
  for (std::size_t i = 0; i < outcomes->size(); ++i) {
    PoseEstimate& estimate = (*outcomes)[i].estimate;
    if (!(*outcomes)[i].error.empty() || !estimate.ok()) continue;
    estimate.certificate = Certify(object, clouds[i], estimate.scene_from_model, estimate.keypoints, decided);
  }
  std::fprintf(stderr, "c3po certify: --eps-oc auto = %.6g (%s; eps_w = %.4g, eps_s = %.4g); evidence %s\n",
               chosen.eps_oc, chosen.rule.c_str(), chosen.noise.eps_w, chosen.sampling.eps_s, chosen.ToJson().c_str());
  return chosen.eps_oc;
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
  ApplyRobustOptions(cmd.robust, &options);
  const bool auto_eps_oc = cmd.eps_oc_text == "auto";
  if (!cmd.eps_oc_text.empty() && !auto_eps_oc) options.certificate.eps_oc = ParseThreshold(cmd.eps_oc_text, object.diameter(), "--eps-oc");
  if (!cmd.delta_nd_text.empty()) options.certificate.delta_nd = ParseThreshold(cmd.delta_nd_text, object.diameter(), "--delta-nd");
  try {
    options.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError("c3po certify", e.what());
  }
  const std::vector<CloudJob> jobs = CollectJobs(cmd);
  const std::unique_ptr<Detector> detector = MakeDetector(cmd, object);

  std::vector<CloudOutcome> outcomes(jobs.size());
  std::vector<PointSet> clouds(auto_eps_oc ? jobs.size() : 0);   // kept for --eps-oc auto
  ProgressBar progress("certify", jobs.size());
  std::atomic<std::size_t> done{0};
  ParallelFor(0, static_cast<int>(jobs.size()), [&](int i) {
    ThrowIfInterrupted();
    const CloudJob& job = jobs[i];
    try {
      const PointSet cloud = ReadCloud(job.path);
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
    progress.Update(++done);
  });
  progress.Finish();

  if (auto_eps_oc) options.certificate.eps_oc = DecideAutoEpsOc(object, clouds, options.certificate, &outcomes);

  std::ostringstream json_lines;
  int certified = 0, oc = 0, nd = 0, errors = 0;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const CloudOutcome& outcome = outcomes[i];
    if (!outcome.error.empty()) {
      ++errors;
      std::cerr << "c3po certify: " << outcome.error << "\n";
      if (cmd.json) json_lines << nlohmann::json{{"cloud", jobs[i].name}, {"error", outcome.error}}.dump() << "\n";
      continue;
    }
    certified += outcome.estimate.certified();
    oc += outcome.estimate.certificate.oc.passed;
    nd += outcome.estimate.certificate.nd.passed;
    if (cmd.json || !cmd.output_path.empty()) json_lines << EstimateJson(jobs[i].name, outcome.estimate).dump() << "\n";
    if (!cmd.json) std::cout << HumanLine(jobs[i].name, outcome) << "\n";
  }
  if (!cmd.output_path.empty()) {
    WriteFileAtomically(cmd.output_path, json_lines.str());
  } else if (cmd.json) {
    std::cout << json_lines.str();
  }
  if (!cmd.json) {
    std::printf("certified %d/%zu (oc %d, nd %d, errors %d); eps_oc = %.6g, delta_nd = %.6g (object units; d = %.6g); %s\n",
                certified, jobs.size(), oc, nd, errors, options.certificate.eps_oc,
                options.certificate.delta_nd, object.diameter(), DescribeRobustOptions(options).c_str());
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
  AddRobustOptions(command, &cmd->robust);
  return [cmd]() { return Run(*cmd); };
}

}  // namespace c3po::cli
