// c3po train
#include "command.hpp"

namespace c3po::cli {

RunFunction SetupTrain(CLI::App& command) { return NotBuiltYet(command, "Detector plugins and training"); }

}  // namespace c3po::cli
