// c3po synth
#include "command.hpp"

namespace c3po::cli {

RunFunction SetupSynth(CLI::App& command) { return NotBuiltYet(command, "Objects and data"); }

}  // namespace c3po::cli
