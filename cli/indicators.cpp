// c3po indicators
#include "command.hpp"

namespace c3po::cli {

RunFunction SetupIndicators(CLI::App& command) { return NotBuiltYet(command, "Corrector, certificates, certify and indicators"); }

}  // namespace c3po::cli
