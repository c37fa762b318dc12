// c3po bench synth-bop: images/s of `synth --format bop` (rendering, artefacts,
// masks, PNG encoding; no file output). Registered by bench_entries.cpp.
#include <cstdio>
#include <functional>
#include <memory>
#include <string>

#include "c3po/base/error.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/io/mesh_io.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/synth/synth_bop.hpp"
#include "command.hpp"

namespace c3po::cli {
namespace {

struct SynthBopBenchCommand {
  std::string object;   // object JSON, or
  std::string mesh;     // any mesh (metres)
  std::string pose = "hard";
  std::string artefacts = "realistic";
  int distractors = 2;
  double seconds = 3.0;
  int batch = 16;
};

int RunSynthBopBench(const SynthBopBenchCommand& cmd) {
  if (cmd.object.empty() == cmd.mesh.empty()) {
    throw InputError("synth-bop", "give either OBJECT.json or --mesh FILE");
  }
  if (!(cmd.seconds > 0.0) || cmd.batch < 1) {
    throw InputError("synth-bop", "--seconds and --batch must be positive");
  }
  Mesh mesh;
  std::string label;
  BopSynthOptions options;
  if (!cmd.object.empty()) {
    const ObjectModel object = LoadObject(cmd.object);
    mesh = object.mesh();
    label = cmd.object;
  } else {
    mesh = LoadMesh(cmd.mesh);
    label = cmd.mesh;
  }
  options.count = cmd.batch;
  options.pose.mode = ParsePoseMode(cmd.pose);
  options.distractors = cmd.distractors;
  if (cmd.artefacts == "realistic") {
    options.artefacts = RealisticArtefacts();
  } else if (cmd.artefacts != "none") {
    throw InputError("--artefacts", "expected none or realistic");
  }
  const BopSceneGenerator generator({&mesh, 1}, {}, options, label);
  const BopSynthBenchmark result = BenchmarkBopSynth(generator, cmd.seconds);
  std::printf("synth bop %s (%ld triangles), %dx%d, %d distractor(s), artefacts %s, pose %s, %d "
              "thread(s): %zu images in %.2f s = %.2f images/s (%.1f ms per image per thread; "
              "%.2f draws per image, %.2f MB of PNG per image)\n",
              label.c_str(), static_cast<long>(mesh.triangles.cols()), options.camera.width,
              options.camera.height, cmd.distractors, cmd.artefacts.c_str(), cmd.pose.c_str(),
              result.threads, result.images, result.seconds, result.images_per_second,
              1000.0 * result.seconds * result.threads / static_cast<double>(result.images),
              result.mean_attempts, result.megabytes_per_image);
  return 0;
}

}  // namespace

void SetupSynthBopBench(CLI::App& parent, std::function<int()>* run) {
  auto cmd = std::make_shared<SynthBopBenchCommand>();
  CLI::App* sub = parent.add_subcommand("synth-bop", "Speed of synth --format bop (images/s)");
  sub->add_option("object", cmd->object, "Object JSON");
  sub->add_option("--mesh", cmd->mesh, "Any mesh in metres instead of an object");
  sub->add_option("--pose", cmd->pose, "easy or hard")->capture_default_str();
  sub->add_option("--artefacts", cmd->artefacts, "none or realistic")->capture_default_str();
  sub->add_option("--distractors", cmd->distractors, "Copies of the object besides the target")
      ->capture_default_str();
  sub->add_option("--seconds", cmd->seconds, "Run at least this long")->capture_default_str();
  sub->add_option("--batch", cmd->batch, "Images per parallel batch")->capture_default_str();
  sub->footer("Example:\n  c3po bench synth-bop annotations/drill.json");
  sub->callback([cmd, run]() { *run = [cmd]() { return RunSynthBopBench(*cmd); }; });
}

}  // namespace c3po::cli
