#include "model_file.hpp"

#include <cstdio>
#include <cstring>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"

namespace c3po::pointnet {
namespace {

constexpr std::size_t kMaxHeaderBytes = 1 << 20;

std::string Hex(std::uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

}  // namespace

std::uint64_t Fnv1a64(const std::string& bytes) {
  std::uint64_t hash = 1469598103934665603ULL;
  for (unsigned char c : bytes) {
    hash ^= c;
    hash *= 1099511628211ULL;
  }
  return hash;
}

std::string ComposeModelFile(nlohmann::json header, const std::string& binary) {
  header["magic"] = kModelMagic;
  header["format_version"] = kModelFormatVersion;
  header["binary"] = {{"bytes", binary.size()}, {"fnv1a64", Hex(Fnv1a64(binary))}};
  return header.dump() + "\n" + binary;
}

ModelFile ReadModelFile(const std::string& path) {
  const std::string contents = ReadFileToString(path);
  const std::size_t newline = contents.find('\n');
  if (contents.compare(0, 2, "{\"") != 0 || newline == std::string::npos ||
      newline > kMaxHeaderBytes) {
    throw InputError(path, "not a c3po model file (no JSON header line)");
  }
  ModelFile file;
  try {
    file.header = nlohmann::json::parse(contents.substr(0, newline));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("corrupt model header: ") + e.what());
  }
  const auto& h = file.header;
  // json::value() throws type_error for a non-string "magic": test the type first.
  if (!h.is_object() || !h.contains("magic") || !h["magic"].is_string() ||
      h["magic"].get<std::string>() != kModelMagic) {
    throw InputError(path, "not a c3po model file (magic is not \"c3po-model\")");
  }
  if (!h.contains("format_version") || !h["format_version"].is_number_integer() ||
      h["format_version"].get<int>() != kModelFormatVersion) {
    throw InputError(path, "unsupported model format version (this c3po reads version " +
                               std::to_string(kModelFormatVersion) + ")");
  }
  if (!h.contains("binary") || !h["binary"].is_object() || !h["binary"].contains("bytes") ||
      !h["binary"]["bytes"].is_number_unsigned() || !h["binary"].contains("fnv1a64") ||
      !h["binary"]["fnv1a64"].is_string()) {
    throw InputError(path, "corrupt model header: missing \"binary\" size or checksum");
  }
  file.binary = contents.substr(newline + 1);
  const auto expected_bytes = h["binary"]["bytes"].get<std::uint64_t>();
  if (file.binary.size() != expected_bytes) {
    throw InputError(path, "truncated or corrupt model: " + std::to_string(file.binary.size()) +
                               " weight bytes, header says " + std::to_string(expected_bytes));
  }
  if (Hex(Fnv1a64(file.binary)) != h["binary"]["fnv1a64"].get<std::string>()) {
    throw InputError(path, "corrupt model: weight checksum mismatch");
  }
  return file;
}

void BinaryWriter::Floats(const std::vector<float>& values) {
  const std::size_t offset = bytes_.size();
  bytes_.resize(offset + values.size() * sizeof(float));
  if (!values.empty()) std::memcpy(&bytes_[offset], values.data(), values.size() * sizeof(float));
}

std::vector<float> BinaryReader::Floats(std::size_t count, const char* what) {
  if (count > remaining() / sizeof(float)) {
    throw InputError(path_, std::string("truncated model: ") + what);
  }
  std::vector<float> values(count);
  if (count > 0) std::memcpy(values.data(), bytes_.data() + offset_, count * sizeof(float));
  offset_ += count * sizeof(float);
  return values;
}

std::string BinaryReader::Raw(std::size_t count, const char* what) {
  if (count > remaining()) throw InputError(path_, std::string("truncated model: ") + what);
  std::string bytes = bytes_.substr(offset_, count);
  offset_ += count;
  return bytes;
}

}  // namespace c3po::pointnet
