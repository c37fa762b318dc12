// c3po bench synth: cloud generation speed (sim and depth), no file output.
// Registered by bench_entries.cpp as {SetupSynthBench}.
#include <cstdio>
#include <functional>
#include <memory>
#include <string>

#include "c3po/base/error.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/io/mesh_io.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/synth/synth.hpp"
#include "command.hpp"

namespace c3po::cli {
namespace {

struct SynthBenchCommand {
  std::string object;   // object JSON, or
  std::string mesh;     // any mesh (keypoints: 8 surface samples)
  std::string kind = "both";
  int points = 1000;
  std::string pose = "hard";
  double noise = 0.001;
  double seconds = 3.0;
  int batch = 200;
};

void RunOne(const Mesh& mesh, const PointSet& keypoints, const std::string& label,
            CloudKind kind, const SynthBenchCommand& cmd) {
  SynthOptions options;
  options.kind = kind;
  options.count = cmd.batch;
  options.points = cmd.points;
  options.pose.mode = ParsePoseMode(cmd.pose);
  options.noise = cmd.noise;
  const SynthBenchmark result = BenchmarkSynth(mesh, keypoints, options, cmd.seconds);
  std::printf("synth %-5s %s (%ld triangles), n = %d, %dx%d, pose %s, %d thread(s): %zu clouds in "
              "%.2f s = %.1f clouds/s (%.3f ms per cloud per thread; %.1f points, %.2f views "
              "per cloud)\n",
              ToString(kind), label.c_str(), result.triangles, cmd.points, options.camera.width,
              options.camera.height, cmd.pose.c_str(), result.threads, result.clouds,
              result.seconds, result.clouds_per_second,
              1000.0 * result.seconds * result.threads / static_cast<double>(result.clouds),
              result.mean_points, result.mean_attempts);
}

int RunSynthBench(const SynthBenchCommand& cmd) {
  if (cmd.object.empty() == cmd.mesh.empty()) {
    throw InputError("synth", "give either OBJECT.json or --mesh FILE");
  }
  if (!(cmd.seconds > 0.0) || cmd.batch < 1) {
    throw InputError("synth", "--seconds and --batch must be positive");
  }
  Mesh mesh;
  PointSet keypoints;
  std::string label;
  if (!cmd.object.empty()) {
    const ObjectModel object = LoadObject(cmd.object);
    mesh = object.mesh();
    keypoints = object.keypoints();
    label = cmd.object;
  } else {
    mesh = LoadMesh(cmd.mesh);
    if (mesh.empty()) throw InputError(cmd.mesh, "the mesh has no triangles");
    keypoints = SampleSurface(mesh, 8, 1);
    label = cmd.mesh;
  }
  if (cmd.kind == "both" || cmd.kind == "depth") RunOne(mesh, keypoints, label, CloudKind::kDepth, cmd);
  if (cmd.kind == "both" || cmd.kind == "sim") RunOne(mesh, keypoints, label, CloudKind::kSim, cmd);
  if (cmd.kind != "both" && cmd.kind != "depth" && cmd.kind != "sim") {
    throw InputError("--kind", "expected sim, depth or both");
  }
  return 0;
}

}  // namespace

void SetupSynthBench(CLI::App& parent, std::function<int()>* run) {
  auto cmd = std::make_shared<SynthBenchCommand>();
  CLI::App* sub = parent.add_subcommand("synth", "Speed of sim and depth cloud generation");
  sub->add_option("object", cmd->object, "Object JSON");
  sub->add_option("--mesh", cmd->mesh, "Any mesh instead of an object (keypoints: 8 surface samples)");
  sub->add_option("--kind", cmd->kind, "sim, depth or both")->capture_default_str();
  sub->add_option("--points", cmd->points, "Points per cloud")->capture_default_str();
  sub->add_option("--pose", cmd->pose, "easy, hard or paper")->capture_default_str();
  sub->add_option("--noise", cmd->noise, "Noise sigma in metres")->capture_default_str();
  sub->add_option("--seconds", cmd->seconds, "Run at least this long per kind")->capture_default_str();
  sub->add_option("--batch", cmd->batch, "Clouds per parallel batch")->capture_default_str();
  sub->footer("Example:\n  c3po bench synth --mesh ../shared/data/ycb/035_power_drill/textured.obj");
  sub->callback([cmd, run]() { *run = [cmd]() { return RunSynthBench(*cmd); }; });
}

}  // namespace c3po::cli
