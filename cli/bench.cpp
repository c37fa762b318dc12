// c3po bench
#include "command.hpp"

namespace c3po::cli {

RunFunction SetupBench(CLI::App& command) { return NotBuiltYet(command, "Objects and data"); }

}  // namespace c3po::cli
