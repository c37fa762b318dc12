// c3po indicators: list, edit, check (--coverage) or learn (--auto) the
// object's indicator sets (paper eq. 21).
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "c3po/authoring/indicators.hpp"
#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/object/object_io.hpp"
#include "command.hpp"
#include "options.hpp"
#include "progress_bar.hpp"

namespace c3po::cli {
namespace {

struct IndicatorsCommand {
  std::string object_path;
  std::vector<std::string> add_sets;
  std::vector<int> remove_sets;
  bool clear = false;
  std::string output_path;
  std::string coverage_dir;
  std::string eps_oc_text;
  std::string delta_nd_text;
  bool automatic = false;
  bool write = false;
  AutoIndicatorOptions auto_options;
  double noise_text = -1.0;
};

void ListSets(const ObjectSpec& spec) {
  std::printf("%s: %d keypoints, %zu indicator set%s%s\n", spec.name.c_str(), spec.num_keypoints(),
              spec.indicator_sets.size(), spec.indicator_sets.size() == 1 ? "" : "s",
              spec.indicator_sets.empty() ? " (nd = 1 always)" : "");
  for (std::size_t k = 0; k < spec.indicator_sets.size(); ++k) {
    std::printf("  set %zu: %s\n", k, DescribeIndicatorSet(spec, spec.indicator_sets[k]).c_str());
  }
}

// -o OUT, or in place after copying the original to OBJECT.json.bak.
std::string WriteSpec(const IndicatorsCommand& cmd, const ObjectSpec& spec) {
  std::string target = cmd.output_path;
  if (target.empty()) {
    target = cmd.object_path;
    WriteFileAtomically(cmd.object_path + ".bak", ReadFileToString(cmd.object_path));
    std::printf("backup: %s.bak\n", cmd.object_path.c_str());
  }
  WriteObjectSpec(spec, target);
  std::printf("wrote %s\n", target.c_str());
  return target;
}

double Threshold(const std::string& text, double object_value, double diameter, const char* what) {
  return text.empty() ? object_value : ParseThreshold(text, diameter, what);
}

void ReportCoverage(const ObjectModel& object, const std::string& dir, double delta_nd) {
  const Dataset dataset = ReadDataset(dir);
  ProgressBar bar("coverage", dataset.entries.size());
  const IndicatorCoverage coverage =
      MeasureIndicatorCoverage(object, dataset, delta_nd, [&](std::size_t done, std::size_t) { bar.Update(done); });
  bar.Finish();
  const ObjectSpec& spec = object.spec();
  const double views = std::max<double>(1.0, static_cast<double>(coverage.views));
  std::printf("coverage on %s: %zu views, delta_nd = %.6g (object units)\n", dir.c_str(), coverage.views, delta_nd);
  for (std::size_t k = 0; k < spec.indicator_sets.size(); ++k) {
    std::printf("  set %zu %s: all seen in %zu views (%.1f %%)\n", k,
                DescribeIndicatorSet(spec, spec.indicator_sets[k]).c_str(), coverage.set_seen[k],
                100.0 * coverage.set_seen[k] / views);
  }
  std::printf("  keypoints seen:");
  for (int i = 0; i < spec.num_keypoints(); ++i) {
    std::printf(" %s %.0f%%", spec.KeypointName(i).c_str(), 100.0 * coverage.keypoint_seen[i] / views);
  }
  std::printf("\n  nd = 1 in %zu of %zu views (%.1f %%)%s\n", coverage.nd_passed, coverage.views,
              100.0 * coverage.nd_passed / views, spec.indicator_sets.empty() ? " (no sets: always)" : "");
}

void PrintScore(const char* label, const SetScore& s) {
  std::printf("  %s: %d views (%d degenerate): accepted %d, false accepts %d, precision %.3f, recall %.3f\n",
              label, s.views, s.degenerate, s.accepted, s.false_accepts, s.precision, s.recall);
}

// Puts the evidence under extra.indicator_sets_auto, keeping other extras.
std::string MergeExtra(const std::string& extra_json, const std::string& evidence_json) {
  nlohmann::json extra = extra_json.empty() ? nlohmann::json::object() : nlohmann::json::parse(extra_json);
  if (!extra.is_object()) extra = nlohmann::json{{"previous_extra", extra}};
  extra["indicator_sets_auto"] = nlohmann::json::parse(evidence_json);
  return extra.dump();
}

int RunAuto(const IndicatorsCommand& cmd, ObjectModel& object) {
  AutoIndicatorOptions options = cmd.auto_options;
  options.training.noise_sigma = cmd.noise_text;
  options.degeneracy.eps_oc = Threshold(cmd.eps_oc_text, object.spec().eps_oc, object.diameter(), "--eps-oc");
  options.degeneracy.delta_nd = Threshold(cmd.delta_nd_text, object.spec().delta_nd, object.diameter(), "--delta-nd");
  options.Check();   // before the first line of output
  const int deliberate = static_cast<int>(DeliberateViews(object, options.deliberate_views).size());
  const int total =
      deliberate + options.training.views + (options.test_views > 0 ? options.test_views : options.training.views);
  std::fprintf(stderr, "indicators --auto: labelling %d rendered views (%d deliberate; training seed %llu) ...\n", total,
               deliberate, static_cast<unsigned long long>(options.training.seed));
  ProgressBar bar("views", static_cast<std::size_t>(total));
  const AutoIndicatorResult result =
      LearnIndicatorSetsFromViews(object, options, [&](std::size_t done, std::size_t) { bar.Update(done); });
  bar.Finish();

  const ObjectSpec& spec = object.spec();
  std::printf("%s: automatic indicator sets (eps_oc = %.6g, delta_nd = %.6g, depth noise sigma = %.6g, object units; d = %.6g)\n",
              spec.name.c_str(), result.eps_oc, result.delta_nd, result.noise_sigma, object.diameter());
  std::printf("  %d + %d views labelled in %.1f s; unusable (true pose misfits): %d + %d; %d candidates, %d admissible\n",
              static_cast<int>(result.training_views.size()), static_cast<int>(result.test_views.size()),
              result.seconds, result.unusable_training_views, result.unusable_test_views,
              result.learned.candidates, result.learned.admissible);
  if (result.learned.accept_all) {
    std::printf("  no degenerate training view: no sets needed (nd = 1 always)\n");
  } else if (result.learned.sets.empty()) {
    std::printf("  no admissible set accepts enough views: every small keypoint subset is seen in some degenerate view\n");
  }
  for (std::size_t k = 0; k < result.learned.sets.size(); ++k) {
    std::printf("  set %zu: %s (accepts %d more training views)\n", k,
                DescribeIndicatorSet(spec, result.learned.sets[k]).c_str(), result.learned.accepted_per_set[k]);
  }
  std::printf("  deliberate views (face-on, edge-on, corner, half occluded): %zu, %s; unusable: %d\n",
              result.deliberate_views.size(), result.deliberate_trained ? "training views" : "scored only (--no-deliberate)",
              result.unusable_deliberate_views);
  PrintScore("deliberate", result.deliberate_score);
  PrintScore("training", result.training_score);
  PrintScore("test    ", result.test_score);
  PrintScore(spec.indicator_sets.empty() ? "test, the object's sets (none: nd = 1 always)" : "test, the object's current sets",
             result.current_test_score);
  std::printf("  (test views: seed %llu, separate from the training views)\n",
              static_cast<unsigned long long>(result.test_seed));
  if (!cmd.write) return 0;
  if (result.learned.sets.empty() && !result.learned.accept_all) {
    throw InputError(cmd.object_path, "--write refused: no indicator sets were found, and an empty list would mean nd = 1 always");
  }
  ObjectSpec updated = spec;
  updated.indicator_sets = result.learned.sets;
  updated.extra_json = MergeExtra(spec.extra_json, result.EvidenceJson());
  WriteSpec(cmd, updated);
  return 0;
}

int Run(const IndicatorsCommand& cmd) {
  ObjectSpec spec = ReadObjectSpec(cmd.object_path);
  const bool edits = cmd.clear || !cmd.remove_sets.empty() || !cmd.add_sets.empty();
  if (cmd.automatic && edits) throw InputError("--auto cannot be combined with --set/--remove/--clear");
  if (cmd.write && !cmd.automatic) throw InputError("--write only applies to --auto (edits are always written)");
  if (edits) {
    IndicatorEdit edit;
    edit.clear = cmd.clear;
    edit.remove = cmd.remove_sets;
    for (const auto& text : cmd.add_sets) edit.add.push_back(ParseIndicatorSet(text, "--set"));
    spec.indicator_sets = ApplyIndicatorEdit(spec.indicator_sets, edit, spec.num_keypoints(), cmd.object_path);
  } else {
    ValidateIndicatorSets(spec.indicator_sets, spec.num_keypoints(), cmd.object_path);
  }
  if (!cmd.automatic) ListSets(spec);
  if (edits) WriteSpec(cmd, spec);
  if (cmd.coverage_dir.empty() && !cmd.automatic) return 0;

  ObjectModel object = LoadObject(cmd.object_path);
  object.mutable_spec().indicator_sets = spec.indicator_sets;
  if (!cmd.coverage_dir.empty()) {
    ReportCoverage(object, cmd.coverage_dir,
                   Threshold(cmd.delta_nd_text, spec.delta_nd, object.diameter(), "--delta-nd"));
  }
  return cmd.automatic ? RunAuto(cmd, object) : 0;
}

}  // namespace

RunFunction SetupIndicators(CLI::App& command) {
  auto cmd = std::make_shared<IndicatorsCommand>();
  AutoIndicatorOptions& a = cmd->auto_options;
  command.add_option("object", cmd->object_path, "Object JSON")->required();
  command.add_option("--set", cmd->add_sets, "Add a set of keypoint indices, e.g. 0,1,3 (repeatable)");
  command.add_option("--remove", cmd->remove_sets, "Remove set K (index as listed; repeatable)");
  command.add_flag("--clear", cmd->clear, "Remove every set (before --set)");
  command.add_option("-o,--output", cmd->output_path,
                     "Write the object here (default: in place, keeping OBJECT.json.bak)")
      ->check(WritableFile());
  command.add_option("--coverage", cmd->coverage_dir, "Dataset with ground-truth poses: how often each set is seen");
  command.add_option("--delta-nd", cmd->delta_nd_text, "'Seen' threshold: distance or fraction of d (1.5%d); default: the object's");
  command.add_option("--eps-oc", cmd->eps_oc_text, "--auto: fit threshold of the degeneracy search; default: the object's");
  command.add_flag("--auto", cmd->automatic, "Learn sets from rendered depth views (prints them; --write to save)");
  command.add_flag("--write", cmd->write, "--auto: write the learned sets and their precision/recall into the object");
  command.add_option("--views", a.training.views, "--auto: random training views (test views: as many, another seed)")->capture_default_str();
  command.add_flag("!--no-deliberate", a.deliberate,
                   "--auto: do not train on the deliberate views (face-on, edge-on, corner and half-occluded views "
                   "from the principal axes and large planar patches; still labelled and scored)");
  command.add_option("--test-views", a.test_views, "--auto: test views (default: as many as --views)");
  command.add_option("--seed", a.training.seed, "--auto: seed of the training views")->capture_default_str();
  command.add_option("--test-seed", a.test_seed, "--auto: seed of the test views (default: seed + 1000003)");
  command.add_option("--points", a.training.points, "--auto: points per rendered cloud")->capture_default_str();
  command.add_option("--noise", cmd->noise_text, "--auto: depth noise sigma (object units; default eps_oc / 8)");
  command.add_option("--tolerance", a.degeneracy.tolerance_factor,
                     "--auto: degenerate when a fitting pose is farther (Hausdorff) than this times eps_oc")->capture_default_str();
  command.add_option("--near-factor", a.degeneracy.near_factor,
                     "--auto: a degenerate view blocks every set whose keypoints all lie within this times delta_nd "
                     "of its cloud (a denser view could support them)")
      ->capture_default_str();
  command.add_option("--max-set-size", a.learning.max_set_size, "--auto: largest candidate set")->capture_default_str();
  command.add_option("--min-support", a.learning.min_support, "--auto: views a set must newly accept")->capture_default_str();
  command.add_option("--borderline", a.learning.borderline_factor,
                     "--auto: views with a fitting pose beyond this fraction of the tolerance also block sets (1 = off)")->capture_default_str();
  return [cmd]() { return Run(*cmd); };
}

}  // namespace c3po::cli
