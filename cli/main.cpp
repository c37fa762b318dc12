// c3po: certifiable object pose estimation from partial point clouds.
// A table of (name, summary, example, Setup) entries; each subcommand lives in
// its own file (cli/<name>.cpp).
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "c3po/base/error.hpp"
#include "c3po/base/version.hpp"
#include "c3po/plugins/registry.hpp"
#include "command.hpp"
#include "signal_handlers.hpp"

namespace {

using c3po::cli::RunFunction;

struct CommandEntry {
  const char* name;
  const char* summary;
  const char* example;
  RunFunction (*setup)(CLI::App&);
};

const std::vector<CommandEntry>& Commands() {
  static const std::vector<CommandEntry> commands = {
      {"annotate", "Make an object file: keypoints on a CAD mesh",
       "c3po annotate mug.obj --keypoint 0.04,0,0.09 --name rim -o mug.json",
       c3po::cli::SetupAnnotate},
      {"indicators", "List, edit or learn the object's indicator sets",
       "c3po indicators mug.json --set 9 -o mug.json", c3po::cli::SetupIndicators},
      {"synth", "Make simulated (sim) or rendered depth (depth) clouds with ground truth",
       "c3po synth mug.json -o data/mug_depth --kind depth --count 200 --seed 1",
       c3po::cli::SetupSynth},
      {"train", "Train a keypoint detector on labelled clouds",
       "c3po train mug.json --data data/mug_sim -o mug.model --epochs 10",
       c3po::cli::SetupTrain},
      {"selftrain", "Self-train a detector on unlabelled clouds from its certified outputs",
       "c3po selftrain mug.json --model mug.model --data data/mug_depth -o mug_self.model",
       c3po::cli::SetupSelftrain},
      {"certify", "Estimate poses and certify them (JSON lines, exit 0/1/2)",
       "c3po certify mug.json --model mug.model cloud.ply --json", c3po::cli::SetupCertify},
      {"eval", "Evaluate detectors, corrector and certificates against ground truth",
       "c3po eval mug.json --model mug.model --data data/mug_depth --report report.html",
       c3po::cli::SetupEval},
      {"bench", "Measure speed and accuracy of components (prints figures)",
       "c3po bench corrector mug.json --data data/mug_depth", c3po::cli::SetupBench},
      {"merge", "Join the outputs of --shard K/N runs (JSON lines or BOP CSV) in shard order",
       "c3po merge -o poses.jsonl part1.jsonl part2.jsonl", c3po::cli::SetupMerge},
      {"demo", "Run the whole method on a bundled object (README's first command)",
       "c3po demo --out demo_out", c3po::cli::SetupDemo},
  };
  return commands;
}

// The subcommands parsed below `app`, each after a space: " bench corrector" below the root.
std::string ParsedSubcommands(const CLI::App& app) {
  std::string names;
  for (const CLI::App* sub = &app;;) {
    const std::vector<CLI::App*> parsed = sub->get_subcommands();
    if (parsed.empty()) return names;
    sub = parsed.front();
    names += " " + sub->get_name();
  }
}

// A command-line error as one line, named like the run-time errors ("c3po certify: ..."); where the
// command line itself was wrong (not a value a check refused, e.g. an unwritable --report path),
// also where to look. Scripts read the first line of stderr.
std::string OneLineParseError(const CLI::App* app, const CLI::Error& error) {
  const std::string command = "c3po" + ParsedSubcommands(*app);
  const bool value_refused = dynamic_cast<const CLI::ValidationError*>(&error) != nullptr;
  return command + ": " + error.what() + (value_refused ? "" : " (" + command + " --help lists the options)") + "\n";
}

bool IsCommand(const std::string& name) {
  for (const auto& entry : Commands()) {
    if (name == entry.name) return true;
  }
  return false;
}

std::string DetectorList() {
  std::string text = "Detectors:\n";
  for (const auto& info : c3po::ListDetectors()) {
    text += "  " + info.name + (info.needs_model_file ? " (trained, --model FILE)" : "") +
            ": " + info.description + "\n";
  }
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  // Named "c3po" (not argv[0]): the help text is the same wherever c3po runs from.
  CLI::App app{"c3po: certifiable object pose estimation from partial point clouds (C-3PO)", "c3po"};
  app.set_version_flag("--version", std::string("c3po ") + C3PO_VERSION + " (plugin ABI " +
                                          std::to_string(C3PO_BUILD_PLUGIN_ABI_VERSION) + ")");
  app.require_subcommand(1);
  app.footer(DetectorList());
  app.failure_message(OneLineParseError);

  std::vector<std::pair<CLI::App*, RunFunction>> runners;
  for (const auto& entry : Commands()) {
    CLI::App* command = app.add_subcommand(entry.name, entry.summary);
    command->footer(std::string("Example:\n  ") + entry.example);
    runners.emplace_back(command, entry.setup(*command));
  }

  if (argc > 1 && argv[1][0] != '-' && !IsCommand(argv[1])) {
    std::cerr << "c3po: unknown command '" << argv[1] << "' (c3po --help lists the commands)\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);   // prints help / version / the error
    return code == 0 ? 0 : 2;
  }

  c3po::cli::InstallInterruptHandlers();
  for (auto& [command, run] : runners) {
    if (!command->parsed()) continue;
    const std::string prefix = "c3po " + command->get_name() + ParsedSubcommands(*command) + ": ";
    try {
      return run();
    } catch (const c3po::InputError& e) {
      std::cerr << prefix << e.what() << "\n";
      return 2;
    } catch (const c3po::Interrupted&) {
      std::cerr << prefix << "interrupted; completed outputs were kept\n";
      return 130;
    } catch (const std::bad_alloc&) {
      std::cerr << prefix << "out of memory\n";
      return 2;
    } catch (const std::exception& e) {
      std::cerr << prefix << e.what() << "\n";
      return 2;
    }
  }
  return 2;
}
