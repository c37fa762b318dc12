#pragma once
// Helpers shared by unit tests: temporary folders, running the CLI, shared data.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "c3po/base/error.hpp"

namespace c3po::test {

inline std::string SharedData() { return C3PO_SHARED_DATA; }
inline std::string SourceDir() { return C3PO_SOURCE_DIR; }
inline std::string Executable() { return C3PO_EXECUTABLE; }
inline bool HaveSharedYcb() { return std::filesystem::exists(SharedData() + "/ycb"); }

// The message of the InputError that f() throws ("" when it throws none).
template <typename F>
std::string InputErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// A fresh empty folder under the test binary dir, removed on destruction.
// Unique per process: ctest runs the cases of one file as parallel processes.
class TempDir {
 public:
  explicit TempDir(const std::string& name) {
    path_ = std::string(C3PO_TEST_BINARY_DIR) + "/tmp/" + name + "." + std::to_string(::getpid());
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::error_code ec; std::filesystem::remove_all(path_, ec); }
  const std::string& path() const { return path_; }
  std::string operator/(const std::string& leaf) const { return path_ + "/" + leaf; }

 private:
  std::string path_;
};

struct CommandResult {
  int status = -1;
  std::string output;   // stdout + stderr
};

// Runs `c3po ARGS` through the shell, capturing stdout and stderr together.
inline CommandResult RunC3po(const std::string& args) {
  static int counter = 0;
  std::filesystem::create_directories(std::string(C3PO_TEST_BINARY_DIR) + "/tmp");
  const std::string out = std::string(C3PO_TEST_BINARY_DIR) + "/tmp/.cmd_output_" +
                          std::to_string(::getpid()) + "_" + std::to_string(counter++);
  const std::string command = Executable() + " " + args + " > " + out + " 2>&1";
  CommandResult result;
  const int raw = std::system(command.c_str());
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  FILE* f = std::fopen(out.c_str(), "rb");
  if (f) {
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) result.output.append(buf, n);
    std::fclose(f);
    std::remove(out.c_str());
  }
  return result;
}

}  // namespace c3po::test
