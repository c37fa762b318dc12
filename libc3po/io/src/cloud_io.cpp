// Point-cloud I/O: format dispatch and the helpers shared by the PLY, PCD and
// XYZ readers and writers.
#include "c3po/io/cloud_io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "cloud_io_internal.hpp"

namespace c3po {
namespace cloud_detail {

std::size_t SizeOf(Scalar type) {
  switch (type) {
    case Scalar::kInt8: case Scalar::kUint8: return 1;
    case Scalar::kInt16: case Scalar::kUint16: return 2;
    case Scalar::kInt32: case Scalar::kUint32: case Scalar::kFloat32: return 4;
    case Scalar::kInt64: case Scalar::kUint64: case Scalar::kFloat64: return 8;
  }
  return 0;
}

bool IsInteger(Scalar type) { return type != Scalar::kFloat32 && type != Scalar::kFloat64; }

namespace {

// Assembles an unsigned integer of `size` bytes in the given byte order.
std::uint64_t LoadBits(const unsigned char* data, std::size_t size, bool little_endian) {
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < size; ++i) {
    const std::size_t byte = little_endian ? size - 1 - i : i;
    bits = (bits << 8) | data[byte];
  }
  return bits;
}

template <typename Signed, typename Unsigned>
Signed AsSigned(std::uint64_t bits) {
  const auto narrow = static_cast<Unsigned>(bits);
  Signed value;
  std::memcpy(&value, &narrow, sizeof value);
  return value;
}

}  // namespace

double DecodeScalar(const unsigned char* data, Scalar type, bool little_endian) {
  const std::uint64_t bits = LoadBits(data, SizeOf(type), little_endian);
  switch (type) {
    case Scalar::kInt8: return AsSigned<std::int8_t, std::uint8_t>(bits);
    case Scalar::kUint8: return static_cast<double>(bits);
    case Scalar::kInt16: return AsSigned<std::int16_t, std::uint16_t>(bits);
    case Scalar::kUint16: return static_cast<double>(bits);
    case Scalar::kInt32: return AsSigned<std::int32_t, std::uint32_t>(bits);
    case Scalar::kUint32: return static_cast<double>(bits);
    case Scalar::kInt64: return static_cast<double>(AsSigned<std::int64_t, std::uint64_t>(bits));
    case Scalar::kUint64: return static_cast<double>(bits);
    case Scalar::kFloat32: return AsSigned<float, std::uint32_t>(bits);
    case Scalar::kFloat64: return AsSigned<double, std::uint64_t>(bits);
  }
  return 0.0;
}

bool DecodeCount(const unsigned char* data, Scalar type, bool little_endian, std::uint64_t* count) {
  if (!IsInteger(type)) return false;
  const std::size_t size = SizeOf(type);
  const std::uint64_t bits = LoadBits(data, size, little_endian);
  const bool is_signed = type == Scalar::kInt8 || type == Scalar::kInt16 ||
                         type == Scalar::kInt32 || type == Scalar::kInt64;
  if (is_signed && ((bits >> (8 * size - 1)) & 1u)) return false;   // negative
  *count = bits;
  return true;
}

bool LineReader::Next(std::string_view* line) {
  if (pos_ >= text_.size()) return false;
  std::size_t end = text_.find('\n', pos_);
  const std::size_t next = end == std::string_view::npos ? text_.size() : end + 1;
  if (end == std::string_view::npos) end = text_.size();
  std::size_t stop = end;
  if (stop > pos_ && text_[stop - 1] == '\r') --stop;
  *line = text_.substr(pos_, stop - pos_);
  pos_ = next;
  ++next_line_;
  return true;
}

std::vector<std::string_view> SplitTokens(std::string_view line, bool commas) {
  std::vector<std::string_view> tokens;
  SplitTokens(line, commas, &tokens);
  return tokens;
}

void SplitTokens(std::string_view line, bool commas, std::vector<std::string_view>* tokens) {
  tokens->clear();
  std::size_t i = 0;
  const auto is_separator = [commas](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || (commas && c == ',');
  };
  while (i < line.size()) {
    while (i < line.size() && is_separator(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_separator(line[i])) ++i;
    if (i > start) tokens->push_back(line.substr(start, i - start));
  }
}

std::string_view Trim(std::string_view text) {
  const auto is_space = [](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
  };
  while (!text.empty() && is_space(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
  return text;
}

bool ParseDouble(std::string_view token, double* value) {
  if (!token.empty() && token.front() == '+') {
    token.remove_prefix(1);
    if (!token.empty() && (token.front() == '+' || token.front() == '-')) return false;
  }
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, *value);
  if (result.ec == std::errc::result_out_of_range && result.ptr == end) {
    // Overflow becomes +-HUGE_VAL (rejected later as non-finite), underflow 0.
    *value = std::strtod(std::string(token).c_str(), nullptr);
    return true;
  }
  return result.ec == std::errc() && result.ptr == end;
}

bool ParseCount(std::string_view token, std::uint64_t* value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, *value);
  return result.ec == std::errc() && result.ptr == end;
}

std::string Quote(std::string_view token) {
  std::string text = "'";
  for (char c : token.substr(0, 32)) {
    text += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  }
  if (token.size() > 32) text += "...";
  return text + "'";
}

PointSet PointCollector::Take() const {
  PointSet points(3, static_cast<Eigen::Index>(size()));
  std::copy(coordinates_.begin(), coordinates_.end(), points.data());
  return points;
}

bool AllFinite(double x, double y, double z) {
  return std::isfinite(x) && std::isfinite(y) && std::isfinite(z);
}

std::string ParseCoordinates(const std::string_view* tokens, double xyz[3]) {
  for (int k = 0; k < 3; ++k) {
    if (!ParseDouble(tokens[k], &xyz[k])) return Quote(tokens[k]) + " is not a number";
  }
  return AllFinite(xyz[0], xyz[1], xyz[2]) ? "" : "non-finite coordinate";
}

void AppendFloat32LE(std::string* out, float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((bits >> (8 * i)) & 0xFF));
}

std::string FormatDouble(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

void CheckWritable(const std::string& path, const PointSet& points, bool as_float32) {
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const double value = points(k, i);
      const bool finite = as_float32 ? std::isfinite(static_cast<float>(value)) : std::isfinite(value);
      if (!finite) {
        throw InputError(path, "cannot write: point " + std::to_string(i) +
                                   " has a coordinate that is not a finite" +
                                   (as_float32 ? " float" : " number"));
      }
    }
  }
}

}  // namespace cloud_detail

CloudFormat CloudFormatFromPath(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  const std::size_t slash = path.find_last_of('/');
  std::string extension;
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) {
    extension = path.substr(dot + 1);
  }
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == "ply") return CloudFormat::kPly;
  if (extension == "pcd") return CloudFormat::kPcd;
  if (extension == "xyz" || extension == "txt" || extension == "csv") return CloudFormat::kXyz;
  throw InputError(path, "unknown point-cloud format '." + extension +
                             "' (expected .ply, .pcd, .xyz, .txt or .csv)");
}

PointSet ParseCloud(const std::string& bytes, CloudFormat format, const std::string& name) {
  if (bytes.empty()) throw InputError(name, "empty file");
  const std::string_view view(bytes);
  switch (format) {
    case CloudFormat::kPly: return cloud_detail::ParsePly(view, name);
    case CloudFormat::kPcd: return cloud_detail::ParsePcd(view, name);
    case CloudFormat::kXyz: return cloud_detail::ParseXyz(view, name);
  }
  throw std::invalid_argument("ParseCloud: unknown format");
}

PointSet ReadCloud(const std::string& path) {
  const CloudFormat format = CloudFormatFromPath(path);
  return ParseCloud(ReadFileToString(path), format, path);
}

}  // namespace c3po
