// c3po certify
#include "command.hpp"

namespace c3po::cli {

RunFunction SetupCertify(CLI::App& command) { return NotBuiltYet(command, "Corrector, certificates, certify and indicators"); }

}  // namespace c3po::cli
