// PCD point clouds (PCL's format, v0.7): reader for DATA ascii and binary
// (binary_compressed is refused with a clear message) and writers.
#include <algorithm>
#include <cctype>
#include <limits>
#include <optional>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/io/cloud_io.hpp"
#include "cloud_io_internal.hpp"

namespace c3po {
namespace cloud_detail {
namespace {

constexpr std::uint64_t kMaxFieldCount = 1u << 20;   // per-field COUNT sanity bound

struct PcdField {
  std::string name;
  std::uint64_t size = 4;
  char type = 'F';
  std::uint64_t count = 1;
  Scalar scalar = Scalar::kFloat32;
};

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t points = 0;
  bool binary = false;
  std::size_t data_offset = 0;
  std::size_t data_first_line = 0;
  std::size_t xyz_field[3] = {0, 0, 0};
};

std::string Upper(std::string_view text) {
  std::string upper(text);
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return upper;
}

std::optional<Scalar> PcdScalar(char type, std::uint64_t size) {
  if (type == 'F' && size == 4) return Scalar::kFloat32;
  if (type == 'F' && size == 8) return Scalar::kFloat64;
  if (type == 'I' && size == 1) return Scalar::kInt8;
  if (type == 'I' && size == 2) return Scalar::kInt16;
  if (type == 'I' && size == 4) return Scalar::kInt32;
  if (type == 'I' && size == 8) return Scalar::kInt64;
  if (type == 'U' && size == 1) return Scalar::kUint8;
  if (type == 'U' && size == 2) return Scalar::kUint16;
  if (type == 'U' && size == 4) return Scalar::kUint32;
  if (type == 'U' && size == 8) return Scalar::kUint64;
  return std::nullopt;
}

class PcdHeaderParser {
 public:
  PcdHeaderParser(std::string_view bytes, const std::string& name) : reader_(bytes), name_(name) {}

  PcdHeader Parse() {
    std::string_view line;
    for (;;) {
      if (!reader_.Next(&line)) throw InputError(name_, "not a PCD file (no DATA line in the header)");
      const std::string_view content = Trim(line);
      if (content.empty() || content.front() == '#') continue;
      const std::vector<std::string_view> tokens = SplitTokens(content);
      if (tokens.empty()) continue;
      const std::string keyword = Upper(tokens[0]);
      if (keyword == "DATA") {
        ParseData(tokens);
        break;
      }
      ParseKeyword(keyword, tokens);
    }
    header_.data_offset = reader_.offset();
    header_.data_first_line = reader_.line_number() + 1;
    Validate();
    return header_;
  }

 private:
  [[noreturn]] void Fail(const std::string& problem) const {
    throw InputError(name_, "line " + std::to_string(reader_.line_number()) + ": " + problem);
  }

  std::vector<std::uint64_t> Counts(const std::vector<std::string_view>& tokens) const {
    std::vector<std::uint64_t> values;
    for (std::size_t i = 1; i < tokens.size(); ++i) {
      std::uint64_t value = 0;
      if (!ParseCount(tokens[i], &value)) Fail(Quote(tokens[i]) + " is not a non-negative integer");
      values.push_back(value);
    }
    return values;
  }

  std::uint64_t OneCount(const std::vector<std::string_view>& tokens) const {
    if (tokens.size() != 2) Fail("expected one number after " + std::string(tokens[0]));
    return Counts(tokens)[0];
  }

  void ParseKeyword(const std::string& keyword, const std::vector<std::string_view>& tokens) {
    if (keyword == "VERSION" || keyword == "VIEWPOINT") return;
    if (keyword == "FIELDS" || keyword == "COLUMNS") {
      fields_.assign(tokens.begin() + 1, tokens.end());
    } else if (keyword == "SIZE") {
      sizes_ = Counts(tokens);
    } else if (keyword == "TYPE") {
      types_.assign(tokens.begin() + 1, tokens.end());
    } else if (keyword == "COUNT") {
      counts_ = Counts(tokens);
    } else if (keyword == "WIDTH") {
      width_ = OneCount(tokens);
    } else if (keyword == "HEIGHT") {
      height_ = OneCount(tokens);
    } else if (keyword == "POINTS") {
      points_ = OneCount(tokens);
    } else {
      Fail("unknown header keyword " + Quote(tokens[0]));
    }
  }

  void ParseData(const std::vector<std::string_view>& tokens) {
    const std::string kind = tokens.size() == 2 ? std::string(tokens[1]) : "";
    if (kind == "binary_compressed") {
      Fail("DATA binary_compressed is not supported (save the cloud as ascii or binary PCD)");
    }
    if (kind != "ascii" && kind != "binary") Fail("expected 'DATA ascii' or 'DATA binary'");
    header_.binary = kind == "binary";
  }

  void Validate() {
    if (fields_.empty()) Fail("header has no FIELDS line");
    const std::size_t n = fields_.size();
    if (sizes_.size() != n) Fail("SIZE has " + std::to_string(sizes_.size()) + " entries, FIELDS has " + std::to_string(n));
    if (types_.size() != n) Fail("TYPE has " + std::to_string(types_.size()) + " entries, FIELDS has " + std::to_string(n));
    if (counts_.empty()) counts_.assign(n, 1);
    if (counts_.size() != n) Fail("COUNT has " + std::to_string(counts_.size()) + " entries, FIELDS has " + std::to_string(n));
    for (std::size_t i = 0; i < n; ++i) header_.fields.push_back(MakeField(i));
    ResolvePointCount();
    FindCoordinates();
  }

  PcdField MakeField(std::size_t i) const {
    PcdField field;
    field.name = std::string(fields_[i]);
    field.size = sizes_[i];
    field.count = counts_[i];
    field.type = types_[i].size() == 1 ? static_cast<char>(std::toupper(static_cast<unsigned char>(types_[i][0]))) : '?';
    const auto scalar = PcdScalar(field.type, field.size);
    if (!scalar) Fail("field '" + field.name + "': unsupported TYPE " + Quote(types_[i]) + " with SIZE " + std::to_string(field.size));
    if (field.count == 0 || field.count > kMaxFieldCount) Fail("field '" + field.name + "': invalid COUNT " + std::to_string(field.count));
    field.scalar = *scalar;
    return field;
  }

  void ResolvePointCount() {
    std::optional<std::uint64_t> from_size;
    if (width_ && height_) {
      if (*height_ != 0 && *width_ > std::numeric_limits<std::uint64_t>::max() / *height_) Fail("WIDTH x HEIGHT overflows");
      from_size = *width_ * *height_;
    }
    if (points_ && from_size && *points_ != *from_size) {
      Fail("POINTS " + std::to_string(*points_) + " differs from WIDTH x HEIGHT = " + std::to_string(*from_size));
    }
    if (!points_ && !from_size) Fail("header has neither POINTS nor WIDTH and HEIGHT");
    header_.points = points_ ? *points_ : *from_size;
    if (header_.points == 0) throw InputError(name_, "no points (header says 0 points)");
  }

  void FindCoordinates() {
    const char* axes[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      const auto& fields = header_.fields;
      const auto it = std::find_if(fields.begin(), fields.end(), [&](const PcdField& f) { return f.name == axes[k]; });
      if (it == fields.end()) throw InputError(name_, std::string("no '") + axes[k] + "' field in the PCD header");
      if (it->count != 1) throw InputError(name_, std::string("field '") + axes[k] + "' has COUNT " + std::to_string(it->count) + ", expected 1");
      header_.xyz_field[k] = static_cast<std::size_t>(it - fields.begin());
    }
  }

  LineReader reader_;
  const std::string& name_;
  PcdHeader header_;
  std::vector<std::string_view> fields_, types_;
  std::vector<std::uint64_t> sizes_, counts_;
  std::optional<std::uint64_t> width_, height_, points_;
};

PointSet ReadBinaryPcd(std::string_view bytes, const PcdHeader& header, const std::string& name) {
  std::size_t stride = 0;
  std::size_t offsets[3] = {0, 0, 0};
  for (std::size_t f = 0; f < header.fields.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (header.xyz_field[k] == f) offsets[k] = stride;
    }
    stride += static_cast<std::size_t>(header.fields[f].size * header.fields[f].count);
  }
  const std::size_t available = bytes.size() - header.data_offset;
  const std::uint64_t fits = available / stride;
  if (header.points > fits) {
    throw InputError(name, "truncated binary data: header says " + std::to_string(header.points) +
                               " points, file holds " + std::to_string(fits));
  }
  if (available != header.points * stride) {
    throw InputError(name, std::to_string(available - header.points * stride) +
                               " bytes of unexpected data after the last point (header says " +
                               std::to_string(header.points) + " points)");
  }
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data()) + header.data_offset;
  PointCollector points;
  points.Reserve(static_cast<std::size_t>(header.points));
  for (std::uint64_t i = 0; i < header.points; ++i) {
    const unsigned char* point = data + i * stride;
    double xyz[3];
    for (int k = 0; k < 3; ++k) {
      xyz[k] = DecodeScalar(point + offsets[k], header.fields[header.xyz_field[k]].scalar, true);
    }
    if (!AllFinite(xyz[0], xyz[1], xyz[2])) {
      throw InputError(name, "point " + std::to_string(i) + ": non-finite coordinate");
    }
    points.Add(xyz[0], xyz[1], xyz[2]);
  }
  return points.Take();
}

PointSet ReadAsciiPcd(std::string_view bytes, const PcdHeader& header, const std::string& name) {
  std::size_t values_per_point = 0;
  std::size_t columns[3] = {0, 0, 0};
  for (std::size_t f = 0; f < header.fields.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (header.xyz_field[k] == f) columns[k] = values_per_point;
    }
    values_per_point += static_cast<std::size_t>(header.fields[f].count);
  }
  LineReader reader(bytes, header.data_offset, header.data_first_line);
  const auto fail = [&](const std::string& problem) {
    throw InputError(name, "line " + std::to_string(reader.line_number()) + ": " + problem);
  };
  PointCollector points;
  // A point line holds at least values_per_point one-character values.
  points.Reserve(static_cast<std::size_t>(std::min<std::uint64_t>(
      header.points, (bytes.size() - header.data_offset) / (2 * values_per_point - 1) + 1)));
  std::string_view line;
  std::vector<std::string_view> tokens;
  while (reader.Next(&line)) {
    if (Trim(line).empty()) continue;
    const std::uint64_t i = points.size();
    if (i == header.points) fail("unexpected data after the last point (header says " + std::to_string(header.points) + " points)");
    SplitTokens(line, false, &tokens);
    if (tokens.size() != values_per_point) {
      fail("expected " + std::to_string(values_per_point) + " values, found " + std::to_string(tokens.size()));
    }
    double xyz[3];
    for (int k = 0; k < 3; ++k) {
      if (!ParseDouble(tokens[columns[k]], &xyz[k])) fail(Quote(tokens[columns[k]]) + " is not a number");
    }
    if (!AllFinite(xyz[0], xyz[1], xyz[2])) fail("point " + std::to_string(i) + ": non-finite coordinate");
    points.Add(xyz[0], xyz[1], xyz[2]);
  }
  if (points.size() != header.points) {
    throw InputError(name, "truncated: header says " + std::to_string(header.points) +
                               " points, file holds " + std::to_string(points.size()));
  }
  return points.Take();
}

std::string PcdHeaderText(const char* size, const char* data, Eigen::Index count) {
  const std::string n = std::to_string(count);
  return std::string("# .PCD v0.7 - Point Cloud Data file format (written by c3po)\nVERSION 0.7\n"
                     "FIELDS x y z\nSIZE ") + size + " " + size + " " + size +
         "\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + n + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
         n + "\nDATA " + data + "\n";
}

}  // namespace

PointSet ParsePcd(std::string_view bytes, const std::string& name) {
  const PcdHeader header = PcdHeaderParser(bytes, name).Parse();
  return header.binary ? ReadBinaryPcd(bytes, header, name) : ReadAsciiPcd(bytes, header, name);
}

}  // namespace cloud_detail

void WritePcd(const std::string& path, const PointSet& points, bool binary) {
  cloud_detail::CheckWritable(path, points, binary);
  WriteFileAtomically(path, [&points, binary](std::ostream& out) {
    if (binary) {
      out << cloud_detail::PcdHeaderText("4", "binary", points.cols());
      std::string buffer;
      buffer.reserve(12 * static_cast<std::size_t>(std::min<Eigen::Index>(points.cols(), 1 << 14)));
      for (Eigen::Index i = 0; i < points.cols(); ++i) {
        for (int k = 0; k < 3; ++k) cloud_detail::AppendFloat32LE(&buffer, static_cast<float>(points(k, i)));
        if (buffer.size() >= (1u << 18) || i + 1 == points.cols()) {
          out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
          buffer.clear();
        }
      }
      return;
    }
    out << cloud_detail::PcdHeaderText("8", "ascii", points.cols());
    for (Eigen::Index i = 0; i < points.cols(); ++i) {
      out << cloud_detail::FormatDouble(points(0, i)) << ' ' << cloud_detail::FormatDouble(points(1, i))
          << ' ' << cloud_detail::FormatDouble(points(2, i)) << '\n';
    }
  });
}

}  // namespace c3po
