#pragma once
// Shared helpers for the libFuzzer targets (built only with -DC3PO_FUZZ=ON).
// InputError is the expected outcome for bad bytes; anything else escaping a
// reader (another exception, a crash, a sanitizer report) is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

namespace c3po_fuzz {

inline std::string Bytes(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// A per-process scratch folder under /tmp (parallel fuzzers do not collide).
inline std::string ScratchDir() {
  static const std::string dir = [] {
    std::string d = "/tmp/c3po_fuzz_" + std::to_string(::getpid());
    std::string cmd = "mkdir -p '" + d + "'";
    if (std::system(cmd.c_str()) != 0) std::abort();
    return d;
  }();
  return dir;
}

inline std::string WriteScratch(const std::string& name, const std::string& bytes) {
  const std::string path = ScratchDir() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) std::abort();
  return path;
}

}  // namespace c3po_fuzz
