// c3po eval
#include "command.hpp"

namespace c3po::cli {

RunFunction SetupEval(CLI::App& command) { return NotBuiltYet(command, "Evaluation, baselines, reports and the end-to-end demo"); }

}  // namespace c3po::cli
