#pragma once
// Signals of the c3po executable.

namespace c3po::cli {

// Installs SIGINT/SIGTERM handlers that request a cooperative interrupt
// (c3po::RequestInterrupt); a second signal exits at once with status 130.
void InstallInterruptHandlers();

}  // namespace c3po::cli
