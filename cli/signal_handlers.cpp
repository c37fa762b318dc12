// SIGINT/SIGTERM -> cooperative interrupt (signal_handlers.hpp).
#include "signal_handlers.hpp"

#include <unistd.h>

#include <csignal>

#include "c3po/base/interrupt.hpp"

namespace c3po::cli {
namespace {

void HandleSignal(int) {
  if (InterruptRequested()) _exit(130);
  RequestInterrupt();
}

}  // namespace

void InstallInterruptHandlers() {
  struct sigaction action {};
  action.sa_handler = HandleSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

}  // namespace c3po::cli
