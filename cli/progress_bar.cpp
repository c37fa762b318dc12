// A progress bar on stderr when it is a terminal (progress_bar.hpp).
#include "progress_bar.hpp"

#include <unistd.h>

#include <cstdio>
#include <mutex>

namespace c3po::cli {
namespace {

std::mutex g_progress_mutex;

}  // namespace

bool ProgressBar::StderrIsTerminal() { return isatty(STDERR_FILENO) == 1; }

ProgressBar::ProgressBar(std::string label, std::size_t total)
    : label_(std::move(label)), total_(total), start_(std::chrono::steady_clock::now()) {
  last_draw_ = start_ - std::chrono::seconds(1);
}

ProgressBar::~ProgressBar() { Finish(); }

void ProgressBar::Update(std::size_t done) {
  if (!StderrIsTerminal() || finished_) return;
  std::lock_guard<std::mutex> lock(g_progress_mutex);
  const auto now = std::chrono::steady_clock::now();
  if (done < total_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  const double fraction = total_ ? static_cast<double>(done) / total_ : 1.0;
  const int width = 30;
  const int filled = static_cast<int>(fraction * width);
  const double seconds = std::chrono::duration<double>(now - start_).count();
  const double eta = fraction > 0 ? seconds * (1 - fraction) / fraction : 0;
  std::fprintf(stderr, "\r%s [%s%s] %zu/%zu %5.1fs eta %5.1fs", label_.c_str(),
               std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), done,
               total_, seconds, eta);
  std::fflush(stderr);
}

void ProgressBar::Finish() {
  if (finished_) return;
  finished_ = true;
  if (StderrIsTerminal()) std::fprintf(stderr, "\r\033[K");
}

}  // namespace c3po::cli
