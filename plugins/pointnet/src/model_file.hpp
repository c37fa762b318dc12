#pragma once
// The c3po model file container: one line of JSON (the header), then a binary
// block whose size and FNV-1a 64 checksum the header records. The pointnet
// detector defines the header's fields (see pointnet.hpp).
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace c3po::pointnet {

inline constexpr const char* kModelMagic = "c3po-model";
inline constexpr int kModelFormatVersion = 1;

std::uint64_t Fnv1a64(const std::string& bytes);

// Header (magic and format version added here) + "\n" + binary; the header
// gets "binary": {"bytes": B, "fnv1a64": "..."}.
std::string ComposeModelFile(nlohmann::json header, const std::string& binary);

struct ModelFile {
  nlohmann::json header;
  std::string binary;
};
// Reads and checks the container (magic, version, size, checksum). Throws
// InputError("path: ...") for anything unreadable, truncated or corrupt.
ModelFile ReadModelFile(const std::string& path);

// Appends / reads little-endian values of the binary block.
class BinaryWriter {
 public:
  void Floats(const std::vector<float>& values);
  void Raw(const std::string& bytes) { bytes_ += bytes; }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

class BinaryReader {
 public:
  BinaryReader(const std::string& bytes, std::string path) : bytes_(bytes), path_(std::move(path)) {}
  // Throws InputError(path: "truncated ...") when fewer values remain.
  std::vector<float> Floats(std::size_t count, const char* what);
  std::string Raw(std::size_t count, const char* what);
  std::size_t remaining() const { return bytes_.size() - offset_; }

 private:
  const std::string& bytes_;
  std::string path_;
  std::size_t offset_ = 0;
};

}  // namespace c3po::pointnet
