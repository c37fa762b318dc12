#pragma once
// Small helpers shared by subcommands: terminal progress bar, threshold
// options, printing JSON lines. No maths.
#include <chrono>
#include <cstddef>
#include <string>

namespace c3po::cli {

// A progress bar on stderr when it is a terminal; silent otherwise (a final
// summary line is the caller's job).
class ProgressBar {
 public:
  ProgressBar(std::string label, std::size_t total);
  ~ProgressBar();
  void Update(std::size_t done);   // thread-safe, rate-limited redraw
  void Finish();
  static bool StderrIsTerminal();

 private:
  std::string label_;
  std::size_t total_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  bool finished_ = false;
};

// Installs SIGINT/SIGTERM handlers that request a cooperative interrupt
// (c3po::RequestInterrupt); a second signal exits at once with status 130.
void InstallInterruptHandlers();

}  // namespace c3po::cli
