#pragma once
// The terminal progress bar of long subcommands. No maths.
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

}  // namespace c3po::cli
