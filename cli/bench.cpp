// c3po bench: speed and accuracy figures of components, printed as tables
// (and JSON with --json FILE). Benchmarks are commands, never timed tests.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bench_registry.hpp"
#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/json.hpp"
#include "c3po/eval/corrector_benchmark.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/object/object_io.hpp"
#include "command.hpp"
#include "options.hpp"
#include "progress_bar.hpp"

namespace c3po::cli {
namespace {

struct CorrectorBenchCommand {
  std::string object_path;
  std::string data_dir;
  std::string sigmas = "0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9,1.0";
  double fraction = 0.8;
  std::string solvers = "fast";
  CorrectorFlags corrector;    // --loss (the solvers are --solvers)
  ThresholdFlags thresholds;
  std::uint64_t seed = 0;
  int threads = 1;
  int max_clouds = 0;
  std::string json_path;
  std::string cases_path;
  std::string stray = "0";
  std::string correct = "0.02";
  RobustFlags robust;
};


// JSON lines: a header (model sample B̂, keypoints b, corrector options, the
// clouds' paths), then one line per case, for reruns by other implementations.
std::string CasesJsonLines(const ObjectModel& object, const Dataset& dataset,
                           const CorrectorBenchmarkOptions& options,
                           const std::vector<CorrectorBenchmarkCase>& cases) {
  nlohmann::json clouds = nlohmann::json::array();
  for (std::size_t i = 0; i < dataset.entries.size(); ++i) clouds.push_back(dataset.CloudPath(i));
  const CorrectorOptions& c = options.corrector;
  nlohmann::json header = {{"object", object.name()}, {"diameter", object.diameter()},
                           {"eps_oc", options.certificate.eps_oc}, {"clouds", clouds},
                           {"model_keypoints", PointsToJson(object.keypoints())},
                           {"model_sample", PointsToJson(object.sample())},
                           {"corrector", {{"kappa", c.kappa}, {"theta", c.theta}, {"loss", ToString(c.loss)},
                                          {"gd_step", c.gd_step}, {"gd_max_iterations", c.gd_max_iterations},
                                          {"gd_tolerance", c.gd_tolerance}}}};
  std::string text = header.dump() + "\n";
  for (const auto& one : cases) {
    const nlohmann::json line = {{"sigma", one.sigma}, {"method", one.method}, {"cloud", one.cloud},
                                 {"detected_keypoints", PointsToJson(one.detected_keypoints)},
                                 {"rotation_deg", one.rotation_deg}, {"oc", one.oc},
                                 {"iterations", one.iterations}, {"cost_before", one.cost_before},
                                 {"cost_after", one.cost_after}, {"corrector_ms", one.corrector_ms},
                                 {"corrector_cpu_ms", one.corrector_cpu_ms}};
    text += line.dump() + "\n";
  }
  return text;
}

std::vector<double> ParseNumberList(const std::string& text, const std::string& what) {
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0') throw InputError(what, "'" + item + "' is not a number");
    values.push_back(value);
  }
  if (values.empty()) throw InputError(what, "empty list");
  return values;
}

CorrectorBenchmarkOptions CorrectorBenchOptions(const CorrectorBenchCommand& cmd, const ObjectModel& object) {
  CorrectorBenchmarkOptions options;
  options.sigmas = ParseNumberList(cmd.sigmas, "--sigma");
  options.fraction = cmd.fraction;
  options.solvers.clear();
  std::stringstream solver_list(cmd.solvers);
  for (std::string name; std::getline(solver_list, name, ',');) options.solvers.push_back(ParseCorrectorSolver(name));
  options.corrector.loss = ParsePointCloudLoss(cmd.corrector.loss);
  options.certificate = ResolveThresholds(cmd.thresholds, object);
  ResolveRobust(cmd.robust, InputKind::kClouds, object, &options.certificate, &options.corrector);
  {
    const OutlierBudget stray = ParseOutlierBudget(cmd.stray);   // the same "P%" syntax
    if (stray.count > 0) throw InputError("--stray", "give a percentage of each cloud's points (5%)");
    options.stray_fraction = stray.fraction;
  }
  options.correct_hausdorff = ParseThreshold(cmd.correct, object.diameter(), "--correct");
  options.seed = cmd.seed;
  options.threads = cmd.threads;
  options.max_clouds = cmd.max_clouds;
  try {
    options.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError("corrector", e.what());
  }
  return options;
}

void PrintCorrectorBenchHeader(const ObjectModel& object, const CorrectorBenchmarkOptions& options,
                               const std::vector<CorrectorBenchmarkRow>& rows) {
  std::printf("corrector analysis: %s, %d clouds, %.0f%% of keypoints perturbed by U[-sigma d/2, sigma d/2], "
              "d = %.4g, eps_oc = %.4g, loss = %s, %s, %d thread(s)\n",
              object.name().c_str(), rows.empty() ? 0 : rows[0].clouds, 100 * options.fraction,
              object.diameter(), options.certificate.eps_oc, ToString(options.corrector.loss),
              DescribeRobust(options.certificate, options.corrector).c_str(), options.threads);
  std::printf("times per cloud, medians in ms: corr = correction alone (registration: T(y~) only), "
              "corr cpu = its thread CPU time, cert = certificates, total = corr + cert\n");
  std::printf("certificates: %.1f%% stray points per cloud; correct = Hausdorff(T*·B̂, T̂·B̂) <= %.4g; "
              "%%cert = certified (oc_m and nd_m), %%c.cert = certified among the correct, false = certified and "
              "not correct, nd q05 = 5%% quantile of the local nd eigenvalue over correct poses\n",
              100.0 * options.stray_fraction, options.correct_hausdorff);
  std::printf("%6s  %-18s %9s %9s %9s %9s %9s %7s %8s %8s %8s %8s %7s %7s %7s %7s %6s %8s\n", "sigma", "method", "rot med", "rot mean",
              "t/d med", "t/d mean", "ADD-S/d", "% oc", "corr", "corr cpu", "cert", "total", "iters",
              "%corr", "%cert", "%c.cert", "false", "nd q05");
}

// Where each row's time goes: mean ms per cloud of each stage and its share.
void PrintStageShares(const std::vector<CorrectorBenchmarkRow>& rows) {
  std::printf("stages, mean ms per cloud (share of the row's time):\n");
  for (const auto& row : rows) {
    const StageTimes& t = row.mean_stages;
    const double total = std::max(t.Total(), 1e-300);
    auto share = [total](double ms) { return 100.0 * ms / total; };
    std::printf("%6.2f  %-18s corrector %.3f (%.0f%%), certificate %.3f (%.0f%%), weak motion %.3f (%.0f%%), "
                "rival search %.3f (%.0f%%)\n",
                row.sigma, row.method.c_str(), t.corrector, share(t.corrector), t.certificate, share(t.certificate),
                t.weak_motion, share(t.weak_motion), t.rival_search, share(t.rival_search));
  }
}

// Prints each row under the header and returns them as the --json document.
nlohmann::json PrintCorrectorBenchRows(const std::vector<CorrectorBenchmarkRow>& rows) {
  nlohmann::json json = nlohmann::json::array();
  for (const auto& row : rows) {
    std::printf("%6.2f  %-18s %8.2f° %8.2f° %9.4f %9.4f %9.4f %7.1f %8.3f %8.3f %8.3f %8.3f %7.1f %7.1f %7.1f %7.1f %6d %8.4f\n", row.sigma,
                row.method.c_str(), row.median_rotation_deg, row.mean_rotation_deg,
                row.median_translation_over_d, row.mean_translation_over_d, row.median_adds_over_d,
                row.percent_oc, row.median_corrector_ms, row.median_corrector_cpu_ms, row.median_certify_ms,
                row.median_ms, row.mean_iterations, row.percent_correct, row.percent_certified,
                row.percent_correct_certified, row.false_certificates, row.q05_nd_eigenvalue_correct);
    json.push_back({{"sigma", row.sigma}, {"method", row.method}, {"clouds", row.clouds},
                    {"median_rotation_deg", row.median_rotation_deg}, {"mean_rotation_deg", row.mean_rotation_deg},
                    {"median_translation_over_d", row.median_translation_over_d},
                    {"mean_translation_over_d", row.mean_translation_over_d},
                    {"median_adds_over_d", row.median_adds_over_d}, {"percent_oc", row.percent_oc},
                    {"median_ms", row.median_ms}, {"mean_ms", row.mean_ms},
                    {"median_corrector_ms", row.median_corrector_ms}, {"mean_corrector_ms", row.mean_corrector_ms},
                    {"median_corrector_cpu_ms", row.median_corrector_cpu_ms},
                    {"median_certify_ms", row.median_certify_ms},
                    {"mean_iterations", row.mean_iterations},
                    {"percent_correct", row.percent_correct}, {"percent_certified", row.percent_certified},
                    {"percent_correct_certified", row.percent_correct_certified},
                    {"false_certificates", row.false_certificates},
                    {"max_certified_hausdorff", row.max_certified_hausdorff},
                    {"median_hausdorff", row.median_hausdorff},
                    {"q05_nd_eigenvalue_correct", row.q05_nd_eigenvalue_correct},
                    {"percent_nd_local", row.percent_nd_local},
                    {"mean_ms_stages", {{"corrector", row.mean_stages.corrector},
                                        {"certificate", row.mean_stages.certificate},
                                        {"free_space", row.mean_stages.free_space},
                                        {"weak_motion", row.mean_stages.weak_motion},
                                        {"rival_search", row.mean_stages.rival_search}}}});
  }
  PrintStageShares(rows);
  return json;
}

int RunCorrectorBench(const CorrectorBenchCommand& cmd) {
  const ObjectModel object = LoadObject(cmd.object_path);
  const Dataset dataset = ReadDataset(cmd.data_dir);
  const CorrectorBenchmarkOptions options = CorrectorBenchOptions(cmd, object);
  ProgressBar progress("corrector", 1);
  std::vector<CorrectorBenchmarkCase> cases;
  const auto rows = RunCorrectorBenchmark(object, dataset, options, [&](std::size_t done, std::size_t total) {
    progress.Update(done * 1000 / std::max<std::size_t>(total, 1) / 1000);
  }, cmd.cases_path.empty() ? nullptr : &cases);
  progress.Finish();
  PrintCorrectorBenchHeader(object, options, rows);
  const nlohmann::json json = PrintCorrectorBenchRows(rows);
  if (!cmd.json_path.empty()) WriteFileAtomically(cmd.json_path, json.dump(2) + "\n");
  if (!cmd.cases_path.empty()) WriteFileAtomically(cmd.cases_path, CasesJsonLines(object, dataset, options, cases));
  return 0;
}

void SetupCorrectorBench(CLI::App& parent, std::function<int()>* run) {
  auto cmd = std::make_shared<CorrectorBenchCommand>();
  CLI::App* sub = parent.add_subcommand("corrector", "The paper's corrector analysis on a depth dataset");
  sub->add_option("object", cmd->object_path, "Object JSON")->required();
  sub->add_option("--data", cmd->data_dir, "Dataset with ground truth (c3po synth)")->required();
  sub->add_option("--sigma", cmd->sigmas, "Comma-separated noise levels sigma (fraction of d)");
  sub->add_option("--fraction", cmd->fraction, "Probability that a keypoint is perturbed");
  sub->add_option("--solvers", cmd->solvers, "Corrector solvers to compare: fast,gd");
  AddLossOption(*sub, &cmd->corrector.loss);
  AddThresholdOptions(*sub, &cmd->thresholds, AutoEpsOc::kRefused);
  AddSeedOption(*sub, &cmd->seed, "of the perturbations");
  AddRobustOptions(*sub, &cmd->robust);
  sub->add_option("--stray", cmd->stray, "Add stray points to every cloud: a percentage of its points (5%; "
                                         "half background, half flying pixels; seeded by --seed)");
  sub->add_option("--correct", cmd->correct, "A pose is correct when Hausdorff(T*·B̂, T̂·B̂) is at most this "
                                             "(distance or fraction of d; default 0.02)");
  AddThreadsOption(*sub, &cmd->threads, "1 gives honest per-cloud times");
  sub->add_option("--max-clouds", cmd->max_clouds, "Use at most this many clouds (0 = all)");
  sub->add_option("--json", cmd->json_path, "Also write the rows as JSON to this file")->check(WritableFile());
  sub->add_option("--cases", cmd->cases_path,
                  "Also write every case (input keypoints, result) and the model sample as JSON lines "
                  "(input of libc3po/eval/bench/pytorch_corrector_gd.py)")->check(WritableFile());
  sub->footer("Example:\n  c3po bench corrector drill.json --data data/drill_depth --sigma 0.1,0.3,0.5 --solvers fast,gd");
  sub->callback([cmd, run]() { *run = [cmd]() { return RunCorrectorBench(*cmd); }; });
}

}  // namespace

RunFunction SetupBench(CLI::App& command) {
  auto run = std::make_shared<std::function<int()>>();
  command.require_subcommand(1);
  SetupCorrectorBench(command, run.get());
  for (const auto& entry : BenchEntries()) entry.setup(command, run.get());
  return [run]() {
    if (!*run) throw InputError("choose a benchmark");
    return (*run)();
  };
}

}  // namespace c3po::cli
