// c3po bench mesh: mesh loading speed (LoadMesh, every format), no output file.
// Registered by bench_entries.cpp as {SetupMeshBench}.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "c3po/base/error.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/io/mesh_io.hpp"
#include "command.hpp"

namespace c3po::cli {
namespace {

struct MeshBenchCommand {
  std::vector<std::string> meshes;
  double seconds = 1.0;
};

// Loads `path` repeatedly for at least `seconds` (and at least 3 times).
void BenchOne(const std::string& path, double seconds) {
  using Clock = std::chrono::steady_clock;
  Mesh mesh = LoadMesh(path);   // a bad file stops here, with its InputError
  const double megabytes = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  const auto start = Clock::now();
  int loads = 0;
  double elapsed = 0.0;
  do {
    mesh = LoadMesh(path);
    ++loads;
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  } while (elapsed < seconds || loads < 3);
  const double per_load = elapsed / loads;
  std::printf("mesh %s: %ld vertices, %ld triangles, %.2f MB; %d loads, %.2f ms per load = %.1f MB/s, "
              "%.2f M triangles/s\n",
              path.c_str(), static_cast<long>(mesh.vertices.cols()), static_cast<long>(mesh.triangles.cols()),
              megabytes, loads, 1000.0 * per_load, megabytes / per_load,
              static_cast<double>(mesh.triangles.cols()) / per_load / 1e6);
}

int RunMeshBench(const MeshBenchCommand& cmd) {
  if (!(cmd.seconds > 0.0)) throw InputError("mesh", "--seconds must be positive");
  for (const std::string& path : cmd.meshes) BenchOne(path, cmd.seconds);
  return 0;
}

}  // namespace

void SetupMeshBench(CLI::App& parent, std::function<int()>* run) {
  auto cmd = std::make_shared<MeshBenchCommand>();
  CLI::App* sub = parent.add_subcommand("mesh", "Speed of mesh loading (PLY, OBJ, OFF, STL, and assimp's formats)");
  sub->add_option("meshes", cmd->meshes, "Mesh files")->required();
  sub->add_option("--seconds", cmd->seconds, "Load each file for at least this long")->capture_default_str();
  sub->footer("Example:\n  c3po bench mesh ../shared/data/ycb/035_power_drill/textured.obj annotations/mug.obj");
  sub->callback([cmd, run]() { *run = [cmd]() { return RunMeshBench(*cmd); }; });
}

}  // namespace c3po::cli
