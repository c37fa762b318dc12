// Shared command-line options (options.hpp).
#include "options.hpp"

#include "c3po/base/error.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/plugins/registry.hpp"

namespace c3po::cli {

void AddThresholdOptions(CLI::App& command, ThresholdFlags* flags, AutoEpsOc auto_eps_oc) {
  flags->auto_mode = auto_eps_oc;
  command.add_option("--eps-oc", flags->eps_oc,
                     auto_eps_oc == AutoEpsOc::kAllowed
                         ? "Observable-correctness threshold: distance, fraction of d (3%d) or auto (estimated from "
                           "the clouds; default: the object's)"
                         : "Observable-correctness threshold: distance or fraction of d (3%d) (default: the object's)");
  command.add_option("--delta-nd", flags->delta_nd,
                     "Non-degeneracy threshold: distance or fraction of d (default: the object's)");
}

CertificateOptions ResolveThresholds(const ThresholdFlags& flags, const ObjectModel& object) {
  CertificateOptions options = CertificateOptions::FromObject(object.spec());
  if (flags.auto_eps_oc() && flags.auto_mode == AutoEpsOc::kRefused) {
    throw InputError("--eps-oc", "'auto' is not available here (give a distance, e.g. 0.01 or 3%d)");
  }
  if (!flags.eps_oc.empty() && !flags.auto_eps_oc()) {
    options.eps_oc = ParseThreshold(flags.eps_oc, object.diameter(), "--eps-oc");
  }
  if (!flags.delta_nd.empty()) options.delta_nd = ParseThreshold(flags.delta_nd, object.diameter(), "--delta-nd");
  return options;
}

void AddCorrectorOptions(CLI::App& command, CorrectorFlags* flags) {
  command.add_option("--solver", flags->solver, "Corrector solver: fast (default) or gd (the reference's)");
  AddLossOption(command, &flags->loss);
}

void AddLossOption(CLI::App& command, std::string* loss) {
  command.add_option("--loss", *loss, "Point-cloud loss: mean (paper, default) or max (reference code)");
}

void ResolveCorrector(const CorrectorFlags& flags, CorrectorOptions* options) {
  options->solver = ParseCorrectorSolver(flags.solver);
  options->loss = ParsePointCloudLoss(flags.loss);
}

void AddDetectorOptions(CLI::App& command, DetectorFlags* flags, DetectorCount count) {
  const bool many = count == DetectorCount::kMany;
  CLI::Option* model = command.add_option(
      "--model", flags->models,
      many ? "Trained detector model file (row label = file stem); repeatable" : "Trained detector model file");
  CLI::Option* detector = command.add_option(
      "--detector", flags->detectors,
      std::string("Detector without a model file (svd, fpfh, manifest = the manifest's detected_keypoints, or a "
                  "plugin's)") + (many ? "; repeatable" : ""));
  CLI::Option* plugin =
      command.add_option("--plugin", flags->plugins, "Load a detector plugin (shared library); repeatable");
  // Each occurrence takes one value, so a positional after it stays positional.
  for (CLI::Option* option : {model, detector, plugin}) option->allow_extra_args(false);
}

void LoadPlugins(const DetectorFlags& flags) {
  for (const std::string& plugin : flags.plugins) LoadPlugin(plugin);
}

std::unique_ptr<Detector> MakeDetector(const std::string& model, const std::string& detector,
                                       const ObjectModel& object) {
  if (!model.empty()) return LoadDetectorModel(model, object);
  if (detector == kManifestDetector) return nullptr;
  return CreateDetector(detector, object);
}

void AddSeedOption(CLI::App& command, std::uint64_t* seed, const std::string& what) {
  command.add_option("--seed", *seed, "Seed (" + what + ")");
}

void AddThreadsOption(CLI::App& command, int* threads, const std::string& what) {
  command.add_option("--threads", *threads, "Worker threads (" + what + ")");
}

}  // namespace c3po::cli
