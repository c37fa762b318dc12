// c3po demo: the whole C-3PO method on a bundled object, with no other input.
// It runs the real subcommands one after another (re-executing this binary),
// printing each command line first, so users see exactly what to type:
//   synth sim -> train -> synth depth -> eval (KeyPo, + ICP, + corrector)
//   -> selftrain -> eval (C-3PO, with the HTML report) -> certify a few clouds.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "command.hpp"

extern char** environ;

namespace c3po::cli {
namespace {

namespace fs = std::filesystem;

struct DemoCommand {
  std::string object;           // default: the bundled mug
  std::string out = "demo_out";
  int sim_count = 4000;
  int depth_train_count = 800;
  int depth_test_count = 200;
  int train_epochs = 12;
  int selftrain_epochs = 10;
  int seed = 1;
  std::string pose = "easy";    // the paper's easy setting: rotation <= 0.8 rad
  bool quick = false;           // a smaller run (for tests)
};

std::string SelfExecutable() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw InputError("cannot locate the c3po executable: " + ec.message());
  // Rebuilt while running: the kernel reports the old inode as "PATH (deleted)";
  // the executable now at PATH is the same program.
  std::string path = self.string();
  const std::string deleted = " (deleted)";
  if (path.size() > deleted.size() && path.compare(path.size() - deleted.size(), deleted.size(), deleted) == 0) {
    path.resize(path.size() - deleted.size());
  }
  return path;
}

// The bundled objects: the working directory's annotations/ when run from the
// repository, else the ones next to this executable: <prefix>/share/c3po/
// annotations, found relative to the executable (no absolute path is built
// in, so an installed tree can be moved; the build tree has the same layout).
std::string DefaultObject() {
  const fs::path bundled =
      fs::path(SelfExecutable()).parent_path() / C3PO_DATADIR_FROM_BINDIR / "annotations/mug.json";
  for (const std::string& candidate :
       std::vector<std::string>{"annotations/mug.json", bundled.lexically_normal().string()}) {
    if (fs::exists(candidate)) return candidate;
  }
  throw InputError("bundled object annotations/mug.json not found (use --object FILE)");
}

// Prints "$ c3po ARGS" and runs it; a failing step stops the demo. Returns
// the step's wall-clock seconds.
double Step(const std::string& title, const std::vector<std::string>& args) {
  ThrowIfInterrupted();
  const auto start = std::chrono::steady_clock::now();
  std::string shown = "$ c3po";
  for (const auto& a : args) shown += " " + a;
  std::printf("\n== %s\n%s\n", title.c_str(), shown.c_str());
  std::fflush(stdout);
  const std::string exe = SelfExecutable();
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(exe.c_str()));
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, exe.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
    throw InputError("cannot start " + exe);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
  }
  ThrowIfInterrupted();
  // certify exits 1 when some cloud is not certified: that is a result.
  const bool certify = !args.empty() && args[0] == "certify";
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (code != 0 && !(certify && code == 1)) {
    throw InputError("step '" + title + "' failed with exit status " + std::to_string(code));
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("(took %.1f s)\n", seconds);
  return seconds;
}

int Run(DemoCommand cmd) {
#ifndef C3PO_HAVE_POINTNET
  throw InputError("needs the pointnet detector, and this c3po was built without it (C3PO_WITH_POINTNET=OFF)");
#endif
  const auto start = std::chrono::steady_clock::now();
  if (cmd.object.empty()) cmd.object = DefaultObject();
  if (cmd.quick) {
    cmd.sim_count = 600;
    cmd.depth_train_count = 120;
    cmd.depth_test_count = 40;
    cmd.train_epochs = 3;
    cmd.selftrain_epochs = 2;
  }
  fs::create_directories(cmd.out);
  const std::string o = cmd.out + "/";
  const std::string seed = std::to_string(cmd.seed);
  std::printf("c3po demo: C-3PO on %s, outputs in %s/\n", cmd.object.c_str(), cmd.out.c_str());

  Step("1. simulated training data: uniform surface samples, random poses",
       {"synth", cmd.object, "-o", o + "sim", "--kind", "sim", "--count", std::to_string(cmd.sim_count),
        "--points", "1000", "--pose", cmd.pose, "--seed", seed});
  const double train_seconds = Step("2. supervised training of the PointNet detector on sim data",
       {"train", cmd.object, "--data", o + "sim", "-o", o + "sim.model", "--epochs", std::to_string(cmd.train_epochs),
        "--batch", "32", "--lr", "0.001", "--seed", seed});
  Step("3. 'real' data: rendered depth clouds (1 mm noise, 10 % dropout); labels are never used for training",
       {"synth", cmd.object, "-o", o + "depth_train", "--kind", "depth", "--count",
        std::to_string(cmd.depth_train_count), "--pose", cmd.pose, "--noise", "1mm", "--dropout", "0.1", "--seed",
        std::to_string(cmd.seed + 1)});
  Step("4. held-out depth clouds with ground truth for evaluation",
       {"synth", cmd.object, "-o", o + "depth_test", "--kind", "depth", "--count", std::to_string(cmd.depth_test_count),
        "--pose", cmd.pose, "--noise", "1mm", "--dropout", "0.1", "--seed", std::to_string(cmd.seed + 2)});
  Step("5. KeyPo (sim) on depth clouds: detector + registration, + ICP, + corrector",
       {"eval", cmd.object, "--model", o + "sim.model", "--data", o + "depth_test"});
  const double selftrain_seconds = Step("6. self-training on the unlabelled depth clouds from certified outputs",
       {"selftrain", cmd.object, "--model", o + "sim.model", "--data", o + "depth_train", "-o", o + "self.model",
        "--epochs", std::to_string(cmd.selftrain_epochs), "--seed", seed});
  Step("7. the supervised bound (for comparison only): the same network trained on the labelled depth clouds",
       {"train", cmd.object, "--data", o + "depth_train", "-o", o + "supervised.model", "--epochs",
        std::to_string(cmd.train_epochs), "--batch", "32", "--lr", "0.001", "--seed", seed});
  Step("8. certify three clouds with the self-trained model (JSON lines)",
       {"certify", cmd.object, "--model", o + "self.model", o + "depth_test/000000.ply",
        o + "depth_test/000001.ply", o + "depth_test/000002.ply", "--json"});
  Step("9. the paper-style table: KeyPo (sim), + corrector, C-3PO, certified subsets, supervised bound; HTML report",
       {"eval", cmd.object, "--model", o + "sim.model", "--selftrained", o + "self.model", "--model",
        o + "supervised.model", "--data",
        o + "depth_test", "--report", o + "report.html", "--json", o + "eval.json"});
  const double minutes =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / 60.0;
  std::printf("\ntraining on sim data %.1f min + self-training %.1f min = %.1f min\n", train_seconds / 60.0,
              selftrain_seconds / 60.0, (train_seconds + selftrain_seconds) / 60.0);
  std::printf("demo finished in %.1f min. Report: %sreport.html  Models: %ssim.model, %sself.model\n", minutes,
              o.c_str(), o.c_str(), o.c_str());
  return 0;
}

}  // namespace

RunFunction SetupDemo(CLI::App& command) {
  auto cmd = std::make_shared<DemoCommand>();
  command.add_option("--object", cmd->object, "Object JSON (default: the bundled mug)");
  command.add_option("--out", cmd->out, "Output folder");
  command.add_option("--sim-count", cmd->sim_count, "Simulated training clouds");
  command.add_option("--depth-train", cmd->depth_train_count, "Unlabelled depth clouds for self-training");
  command.add_option("--depth-test", cmd->depth_test_count, "Labelled depth clouds for evaluation");
  command.add_option("--train-epochs", cmd->train_epochs, "Supervised epochs");
  command.add_option("--selftrain-epochs", cmd->selftrain_epochs, "Self-training epochs");
  command.add_option("--seed", cmd->seed, "Seed of every step");
  command.add_option("--pose", cmd->pose, "Pose difficulty of all data: easy (paper: <= 0.8 rad) or hard");
  command.add_flag("--quick", cmd->quick, "A small, fast run (smoke test)");
  return [cmd]() { return Run(*cmd); };
}

}  // namespace c3po::cli
