// c3po selftrain
#include "command.hpp"

namespace c3po::cli {

RunFunction SetupSelftrain(CLI::App& command) { return NotBuiltYet(command, "Detector plugins and training"); }

}  // namespace c3po::cli
