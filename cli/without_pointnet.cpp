// The commands that need the pointnet detector, in a c3po built with
// C3PO_WITH_POINTNET=OFF (cli/CMakeLists.txt compiles this file instead of
// train.cpp, selftrain.cpp and bench_pointnet.cpp): each accepts any
// arguments and exits with status 2 saying why.
#include <functional>
#include <string>

#include "bench_registry.hpp"
#include "c3po/base/error.hpp"
#include "command.hpp"

namespace c3po::cli {
namespace {

constexpr const char* kWithoutPointNet =
    "needs the pointnet detector, and this c3po was built without it (C3PO_WITH_POINTNET=OFF)";

RunFunction Unavailable(CLI::App& command) {
  command.allow_extras();
  command.positionals_at_end(false);
  return []() -> int { throw InputError(kWithoutPointNet); };
}

}  // namespace

RunFunction SetupTrain(CLI::App& command) { return Unavailable(command); }
RunFunction SetupSelftrain(CLI::App& command) { return Unavailable(command); }

void SetupPointNetBench(CLI::App& parent, std::function<int()>* run) {
  CLI::App* sub = parent.add_subcommand("pointnet", "PointNet training and inference speed (not in this build)");
  sub->allow_extras();
  sub->callback([run]() { *run = []() -> int { throw InputError(std::string("pointnet ") + kWithoutPointNet); }; });
}

}  // namespace c3po::cli
