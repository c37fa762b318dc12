// c3po annotate
#include "command.hpp"

namespace c3po::cli {

RunFunction SetupAnnotate(CLI::App& command) { return NotBuiltYet(command, "annotate"); }

}  // namespace c3po::cli
