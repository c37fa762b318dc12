#pragma once
// Shared helpers of the point-cloud readers and writers (cloud_io_ply.cpp,
// cloud_io_pcd.cpp, cloud_io_xyz.cpp). Private to libc3po.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "c3po/base/types.hpp"

namespace c3po::cloud_detail {

// Scalar types of binary point formats.
enum class Scalar { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kInt64, kUint64, kFloat32, kFloat64 };
std::size_t SizeOf(Scalar type);
bool IsInteger(Scalar type);
// Decodes one value at `data` (SizeOf(type) bytes) stored little- or big-endian.
double DecodeScalar(const unsigned char* data, Scalar type, bool little_endian);
// Same for integer types, exact (for list counts); false for a float type.
bool DecodeCount(const unsigned char* data, Scalar type, bool little_endian, std::uint64_t* count);

// Reads lines of a text buffer, numbering them from 1; strips "\r\n"/"\n".
class LineReader {
 public:
  explicit LineReader(std::string_view text, std::size_t offset = 0, std::size_t first_line = 1)
      : text_(text), pos_(offset), next_line_(first_line) {}
  bool Next(std::string_view* line);           // false at the end of the text
  std::size_t line_number() const { return next_line_ - 1; }   // of the last line returned
  std::size_t offset() const { return pos_; }                  // just after the last line
  bool AtEnd() const { return pos_ >= text_.size(); }

 private:
  std::string_view text_;
  std::size_t pos_;
  std::size_t next_line_;
};

// Splits on spaces and tabs (and commas when `commas`); empty tokens are dropped.
std::vector<std::string_view> SplitTokens(std::string_view line, bool commas = false);
// Same into a reused vector (no allocation per line in data loops).
void SplitTokens(std::string_view line, bool commas, std::vector<std::string_view>* tokens);
std::string_view Trim(std::string_view text);
// Parses a whole token as a number (decimal, optional sign and exponent;
// "nan"/"inf" parse and are rejected later as non-finite). False if invalid.
bool ParseDouble(std::string_view token, double* value);
bool ParseCount(std::string_view token, std::uint64_t* value);   // non-negative integer
// A short, printable quotation of a token for error messages.
std::string Quote(std::string_view token);

// Collects points; the readers grow it only as data is actually present, so a
// lying header never causes a large allocation.
class PointCollector {
 public:
  void Reserve(std::size_t n) { coordinates_.reserve(3 * n); }
  void Add(double x, double y, double z) {
    coordinates_.push_back(x);
    coordinates_.push_back(y);
    coordinates_.push_back(z);
  }
  std::size_t size() const { return coordinates_.size() / 3; }
  PointSet Take() const;

 private:
  std::vector<double> coordinates_;
};

// "vertex 17: non-finite coordinate" style check; `what` names the point.
bool AllFinite(double x, double y, double z);
// Reads the point tokens[0..2] into xyz (the mesh readers' vertices).
// Returns "" or the problem: "'x' is not a number" or "non-finite coordinate".
std::string ParseCoordinates(const std::string_view* tokens, double xyz[3]);

// Format-specific parsers; `name` is used in every message.
PointSet ParsePly(std::string_view bytes, const std::string& name);
PointSet ParsePcd(std::string_view bytes, const std::string& name);
PointSet ParseXyz(std::string_view bytes, const std::string& name);

// WritePly with a choice of fsync (see WriteFileAtomically).
void WritePlyBinary(const std::string& path, const PointSet& points, bool sync);

// Encoding helpers for writers.
void AppendFloat32LE(std::string* out, float value);
std::string FormatDouble(double value);   // shortest text that reads back exactly
// Throws InputError("path: cannot write: point i has a non-finite coordinate").
void CheckWritable(const std::string& path, const PointSet& points, bool as_float32);

}  // namespace c3po::cloud_detail
