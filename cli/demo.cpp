// c3po demo
#include "command.hpp"

namespace c3po::cli {

RunFunction SetupDemo(CLI::App& command) { return NotBuiltYet(command, "Evaluation, baselines, reports and the end-to-end demo"); }

}  // namespace c3po::cli
