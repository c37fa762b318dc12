// PLY point clouds and meshes: reader (ASCII, binary little/big endian, any
// scalar types, any elements around `vertex`; list properties skipped, except
// a mesh's face `vertex_indices`, fan-triangulated) and writers.
//
// Every count in the header is checked against the bytes actually present
// before anything is allocated, so a header that lies cannot exhaust memory.
// LoadMesh reads .ply meshes here rather than with assimp, whose PLY importer
// aborts the process on some malformed headers (found by fuzz_mesh).
#include <algorithm>
#include <optional>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/io/cloud_io.hpp"
#include "cloud_io_internal.hpp"
#include "mesh_io_internal.hpp"

namespace c3po {
namespace cloud_detail {
namespace {

using mesh_detail::TriangleCollector;

enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyProperty {
  std::string name;
  Scalar type = Scalar::kFloat32;   // item type for lists
  bool is_list = false;
  Scalar count_type = Scalar::kUint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;

  bool HasLists() const {
    return std::any_of(properties.begin(), properties.end(),
                       [](const PlyProperty& p) { return p.is_list; });
  }
  // Bytes of one item in binary; a lower bound when there are lists.
  std::size_t MinBinaryBytes() const {
    std::size_t bytes = 0;
    for (const PlyProperty& p : properties) bytes += SizeOf(p.is_list ? p.count_type : p.type);
    return bytes;
  }
  std::string Item(std::uint64_t i) const {
    return (name == "vertex" ? "vertex " : "'" + name + "' element ") + std::to_string(i);
  }
  std::string Plural() const { return name == "vertex" ? "vertices" : "'" + name + "' elements"; }
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<PlyElement> elements;
  std::size_t vertex_element = 0;
  int xyz[3] = {-1, -1, -1};   // property indices of x, y, z in the vertex element
  std::size_t data_offset = 0;
  std::size_t data_first_line = 0;
  // Meshes only: the face element and its vertex-index list property.
  std::optional<std::size_t> face_element;
  std::size_t face_indices = 0;

  bool IsFaceIndices(std::size_t element, std::size_t property) const {
    return face_element && *face_element == element && face_indices == property;
  }
  std::uint64_t VertexCount() const { return elements[vertex_element].count; }
};

std::optional<Scalar> PlyScalarType(std::string_view name) {
  if (name == "char" || name == "int8") return Scalar::kInt8;
  if (name == "uchar" || name == "uint8") return Scalar::kUint8;
  if (name == "short" || name == "int16") return Scalar::kInt16;
  if (name == "ushort" || name == "uint16") return Scalar::kUint16;
  if (name == "int" || name == "int32") return Scalar::kInt32;
  if (name == "uint" || name == "uint32") return Scalar::kUint32;
  if (name == "float" || name == "float32") return Scalar::kFloat32;
  if (name == "double" || name == "float64") return Scalar::kFloat64;
  return std::nullopt;
}

class PlyHeaderParser {
 public:
  PlyHeaderParser(std::string_view bytes, const std::string& name) : reader_(bytes), name_(name) {}

  PlyHeader Parse() {
    std::string_view line;
    if (!reader_.Next(&line) || Trim(line) != "ply") Fail(1, "not a PLY file (first line is not 'ply')");
    bool have_format = false;
    for (;;) {
      if (!reader_.Next(&line)) Fail(reader_.line_number(), "header has no end_header line");
      const std::vector<std::string_view> tokens = SplitTokens(line);
      if (tokens.empty()) continue;
      const std::string_view keyword = tokens[0];
      if (keyword == "end_header") break;
      if (keyword == "comment" || keyword == "obj_info") continue;
      if (keyword == "format") {
        ParseFormat(tokens);
        have_format = true;
      } else if (keyword == "element") {
        ParseElement(tokens);
      } else if (keyword == "property") {
        ParseProperty(tokens);
      } else {
        Fail(reader_.line_number(), "unknown header keyword " + Quote(keyword));
      }
    }
    if (!have_format) Fail(reader_.line_number(), "header has no format line");
    header_.data_offset = reader_.offset();
    header_.data_first_line = reader_.line_number() + 1;
    FindVertexCoordinates();
    return header_;
  }

 private:
  [[noreturn]] void Fail(std::size_t line, const std::string& problem) const {
    throw InputError(name_, "line " + std::to_string(line) + ": " + problem);
  }

  void ParseFormat(const std::vector<std::string_view>& tokens) {
    if (tokens.size() != 3) Fail(reader_.line_number(), "expected 'format <encoding> 1.0'");
    if (tokens[1] == "ascii") {
      header_.encoding = PlyEncoding::kAscii;
    } else if (tokens[1] == "binary_little_endian") {
      header_.encoding = PlyEncoding::kBinaryLittleEndian;
    } else if (tokens[1] == "binary_big_endian") {
      header_.encoding = PlyEncoding::kBinaryBigEndian;
    } else {
      Fail(reader_.line_number(), "unknown PLY format " + Quote(tokens[1]));
    }
    if (tokens[2] != "1.0") Fail(reader_.line_number(), "unsupported PLY version " + Quote(tokens[2]));
  }

  void ParseElement(const std::vector<std::string_view>& tokens) {
    PlyElement element;
    if (tokens.size() != 3 || !ParseCount(tokens[2], &element.count)) {
      Fail(reader_.line_number(), "expected 'element <name> <count>'");
    }
    element.name = std::string(tokens[1]);
    header_.elements.push_back(element);
  }

  void ParseProperty(const std::vector<std::string_view>& tokens) {
    if (header_.elements.empty()) Fail(reader_.line_number(), "property before any element");
    PlyProperty property;
    if (tokens.size() == 5 && tokens[1] == "list") {
      const auto count_type = PlyScalarType(tokens[2]);
      const auto item_type = PlyScalarType(tokens[3]);
      if (!count_type || !IsInteger(*count_type)) Fail(reader_.line_number(), "list count type must be an integer type");
      if (!item_type) Fail(reader_.line_number(), "unknown property type " + Quote(tokens[3]));
      property.is_list = true;
      property.count_type = *count_type;
      property.type = *item_type;
      property.name = std::string(tokens[4]);
    } else if (tokens.size() == 3) {
      const auto type = PlyScalarType(tokens[1]);
      if (!type) Fail(reader_.line_number(), "unknown property type " + Quote(tokens[1]));
      property.type = *type;
      property.name = std::string(tokens[2]);
    } else {
      Fail(reader_.line_number(), "expected 'property <type> <name>' or 'property list <type> <type> <name>'");
    }
    header_.elements.back().properties.push_back(property);
  }

  void FindVertexCoordinates() {
    const auto& elements = header_.elements;
    const auto vertex = std::find_if(elements.begin(), elements.end(),
                                     [](const PlyElement& e) { return e.name == "vertex"; });
    if (vertex == elements.end()) throw InputError(name_, "no vertex element in the PLY header");
    header_.vertex_element = static_cast<std::size_t>(vertex - elements.begin());
    const char* axes[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      for (std::size_t p = 0; p < vertex->properties.size(); ++p) {
        if (vertex->properties[p].name == axes[k] && header_.xyz[k] < 0) header_.xyz[k] = static_cast<int>(p);
      }
      if (header_.xyz[k] < 0) throw InputError(name_, std::string("vertex element has no '") + axes[k] + "' property");
      if (vertex->properties[static_cast<std::size_t>(header_.xyz[k])].is_list) {
        throw InputError(name_, std::string("vertex property '") + axes[k] + "' is a list, expected a scalar");
      }
    }
    if (vertex->count == 0) throw InputError(name_, "no points (header says 0 vertices)");
  }

  LineReader reader_;
  const std::string& name_;
  PlyHeader header_;
};

// Marks the `face` element's `vertex_indices` (or `vertex_index`) list.
void FindFaceIndices(PlyHeader* header, const std::string& name) {
  const auto& elements = header->elements;
  const auto face = std::find_if(elements.begin(), elements.end(),
                                 [](const PlyElement& e) { return e.name == "face"; });
  if (face == elements.end()) throw InputError(name, "no face element in the PLY header (a point cloud, not a mesh)");
  const auto& properties = face->properties;
  const auto indices = std::find_if(properties.begin(), properties.end(), [](const PlyProperty& p) {
    return p.name == "vertex_indices" || p.name == "vertex_index";
  });
  if (indices == properties.end()) throw InputError(name, "face element has no 'vertex_indices' property");
  if (!indices->is_list || !IsInteger(indices->type)) {
    throw InputError(name, "face property '" + indices->name + "' must be a list of integers");
  }
  if (header->VertexCount() > mesh_detail::kMaxMeshVertices) {
    throw InputError(name, "header says " + std::to_string(header->VertexCount()) +
                               " vertices, more than a mesh can index");
  }
  header->face_element = static_cast<std::size_t>(face - elements.begin());
  header->face_indices = static_cast<std::size_t>(indices - properties.begin());
}

// Which property of the current element feeds which coordinate (-1: none).
int AxisOf(const PlyHeader& header, std::size_t element, std::size_t property) {
  if (element != header.vertex_element) return -1;
  for (int k = 0; k < 3; ++k) {
    if (header.xyz[k] == static_cast<int>(property)) return k;
  }
  return -1;
}

class PlyBinaryReader {
 public:
  // `triangles` receives the faces when reading a mesh (nullptr: a cloud).
  PlyBinaryReader(std::string_view bytes, const PlyHeader& header, const std::string& name,
                  TriangleCollector* triangles = nullptr)
      : data_(reinterpret_cast<const unsigned char*>(bytes.data())),
        size_(bytes.size()),
        pos_(header.data_offset),
        header_(header),
        name_(name),
        little_endian_(header.encoding == PlyEncoding::kBinaryLittleEndian),
        triangles_(triangles) {}

  PointSet Read() {
    for (std::size_t e = 0; e < header_.elements.size(); ++e) ReadElement(e);
    CheckTrailingBytes();
    return points_.Take();
  }

 private:
  [[noreturn]] void Fail(const std::string& problem) const { throw InputError(name_, problem); }

  std::size_t Remaining() const { return size_ - pos_; }

  // Rejects a count that cannot fit in the remaining bytes, before any work.
  void CheckCountFits(const PlyElement& element) const {
    const std::size_t min_bytes = element.MinBinaryBytes();
    const std::uint64_t fits = Remaining() / min_bytes;
    if (element.count > fits) {
      Fail("truncated binary data: header says " + std::to_string(element.count) + " " +
           element.Plural() + ", file holds " + (element.HasLists() ? "at most " : "") +
           std::to_string(fits));
    }
  }

  void ReadElement(std::size_t e) {
    const PlyElement& element = header_.elements[e];
    if (element.properties.empty() || element.count == 0) return;   // occupies no bytes
    CheckCountFits(element);
    const bool is_vertex = e == header_.vertex_element;
    if (is_vertex) points_.Reserve(static_cast<std::size_t>(element.count));
    if (!element.HasLists()) {
      ReadFixedItems(e);
    } else {
      for (std::uint64_t i = 0; i < element.count; ++i) ReadListItem(e, i);
    }
  }

  // Items of constant size: x, y, z at fixed offsets.
  void ReadFixedItems(std::size_t e) {
    const PlyElement& element = header_.elements[e];
    const std::size_t stride = element.MinBinaryBytes();
    if (e != header_.vertex_element) {
      pos_ += static_cast<std::size_t>(element.count) * stride;
      return;
    }
    std::size_t offsets[3];
    Scalar types[3];
    for (int k = 0; k < 3; ++k) {
      const std::size_t p = static_cast<std::size_t>(header_.xyz[k]);
      offsets[k] = 0;
      for (std::size_t q = 0; q < p; ++q) offsets[k] += SizeOf(element.properties[q].type);
      types[k] = element.properties[p].type;
    }
    for (std::uint64_t i = 0; i < element.count; ++i) {
      const unsigned char* item = data_ + pos_;
      AddVertex(i, DecodeScalar(item + offsets[0], types[0], little_endian_),
                DecodeScalar(item + offsets[1], types[1], little_endian_),
                DecodeScalar(item + offsets[2], types[2], little_endian_));
      pos_ += stride;
    }
  }

  // Items with list properties: walk property by property, checking bounds.
  void ReadListItem(std::size_t e, std::uint64_t i) {
    const PlyElement& element = header_.elements[e];
    double xyz[3] = {0.0, 0.0, 0.0};
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      if (property.is_list) {
        const std::size_t count_size = SizeOf(property.count_type);
        if (Remaining() < count_size) FailItem(element, i);
        std::uint64_t length = 0;
        if (!DecodeCount(data_ + pos_, property.count_type, little_endian_, &length)) {
          Fail(element.Item(i) + ": negative list length in property '" + property.name + "'");
        }
        pos_ += count_size;
        if (length > Remaining() / SizeOf(property.type)) FailItem(element, i);
        if (triangles_ != nullptr && header_.IsFaceIndices(e, p)) ReadPolygon(property.type, length, i);
        pos_ += static_cast<std::size_t>(length) * SizeOf(property.type);
      } else {
        const std::size_t size = SizeOf(property.type);
        if (Remaining() < size) FailItem(element, i);
        const int axis = AxisOf(header_, e, p);
        if (axis >= 0) xyz[axis] = DecodeScalar(data_ + pos_, property.type, little_endian_);
        pos_ += size;
      }
    }
    if (e == header_.vertex_element) AddVertex(i, xyz[0], xyz[1], xyz[2]);
  }

  // The `length` indices at pos_ (already checked to be present) of face i.
  void ReadPolygon(Scalar type, std::uint64_t length, std::uint64_t i) {
    triangles_->BeginPolygon();
    for (std::uint64_t k = 0; k < length; ++k) {
      const unsigned char* item = data_ + pos_ + k * SizeOf(type);
      std::uint64_t index = 0;
      const bool non_negative = DecodeCount(item, type, little_endian_, &index);
      if (!non_negative || !triangles_->AddIndex(index)) {
        Fail("face " + std::to_string(i) + ": vertex index " + FormatDouble(DecodeScalar(item, type, little_endian_)) +
             " is not one of the header's " + std::to_string(header_.VertexCount()) + " vertices");
      }
    }
    triangles_->EndPolygon();
  }

  [[noreturn]] void FailItem(const PlyElement& element, std::uint64_t i) const {
    Fail("truncated binary data in " + element.Item(i) + " (header says " +
         std::to_string(element.count) + " " + element.Plural() + ")");
  }

  void AddVertex(std::uint64_t i, double x, double y, double z) {
    if (!AllFinite(x, y, z)) Fail("vertex " + std::to_string(i) + ": non-finite coordinate");
    points_.Add(x, y, z);
  }

  // A trailing newline is tolerated; anything else means a wrong count.
  void CheckTrailingBytes() const {
    for (std::size_t k = pos_; k < size_; ++k) {
      if (data_[k] != '\n' && data_[k] != '\r' && data_[k] != ' ') {
        Fail(std::to_string(size_ - pos_) + " bytes of unexpected data after the last element "
             "(header says " + std::to_string(header_.VertexCount()) +
             " vertices)");
      }
    }
  }

  const unsigned char* data_;
  std::size_t size_;
  std::size_t pos_;
  const PlyHeader& header_;
  const std::string& name_;
  bool little_endian_;
  TriangleCollector* triangles_;
  PointCollector points_;
};

class PlyAsciiReader {
 public:
  PlyAsciiReader(std::string_view bytes, const PlyHeader& header, const std::string& name,
                 TriangleCollector* triangles = nullptr)
      : reader_(bytes, header.data_offset, header.data_first_line),
        remaining_bytes_(bytes.size() - header.data_offset),
        header_(header),
        name_(name),
        triangles_(triangles) {}

  PointSet Read() {
    for (std::size_t e = 0; e < header_.elements.size(); ++e) ReadElement(e);
    std::string_view line;
    if (NextDataLine(&line)) {
      Fail(reader_.line_number(), "unexpected data after the last element (header says " +
                                      std::to_string(header_.VertexCount()) +
                                      " vertices)");
    }
    return points_.Take();
  }

 private:
  [[noreturn]] void Fail(std::size_t line, const std::string& problem) const {
    throw InputError(name_, "line " + std::to_string(line) + ": " + problem);
  }

  bool NextDataLine(std::string_view* line) {
    while (reader_.Next(line)) {
      if (!Trim(*line).empty()) return true;
    }
    return false;
  }

  void ReadElement(std::size_t e) {
    const PlyElement& element = header_.elements[e];
    if (element.properties.empty()) return;
    if (e == header_.vertex_element) {
      // Each vertex line holds at least "0 0 0": never reserve more than fits.
      points_.Reserve(static_cast<std::size_t>(std::min<std::uint64_t>(element.count, remaining_bytes_ / 5 + 1)));
    }
    for (std::uint64_t i = 0; i < element.count; ++i) {
      std::string_view line;
      if (!NextDataLine(&line)) {
        throw InputError(name_, "truncated: header says " + std::to_string(element.count) + " " +
                                    element.Plural() + ", file holds " + std::to_string(i));
      }
      SplitTokens(line, false, &tokens_);
      ReadItem(e, i, tokens_);
    }
  }

  void ReadItem(std::size_t e, std::uint64_t i, const std::vector<std::string_view>& tokens) {
    const PlyElement& element = header_.elements[e];
    double xyz[3] = {0.0, 0.0, 0.0};
    std::size_t next = 0;
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      if (next >= tokens.size()) FailCount(element, i, tokens.size());
      if (property.is_list) {
        std::uint64_t length = 0;
        if (!ParseCount(tokens[next], &length)) {
          Fail(reader_.line_number(), "invalid list length " + Quote(tokens[next]));
        }
        ++next;
        if (length > tokens.size() - next) FailCount(element, i, tokens.size());
        if (triangles_ != nullptr && header_.IsFaceIndices(e, p)) {
          ReadPolygon(tokens.data() + next, static_cast<std::size_t>(length), i);
        }
        next += static_cast<std::size_t>(length);
        continue;
      }
      double value = 0.0;
      if (!ParseDouble(tokens[next], &value)) {
        Fail(reader_.line_number(), Quote(tokens[next]) + " is not a number");
      }
      const int axis = AxisOf(header_, e, p);
      if (axis >= 0) xyz[axis] = value;
      ++next;
    }
    if (next != tokens.size()) FailCount(element, i, tokens.size());
    if (e != header_.vertex_element) return;
    if (!AllFinite(xyz[0], xyz[1], xyz[2])) {
      Fail(reader_.line_number(), "vertex " + std::to_string(i) + ": non-finite coordinate");
    }
    points_.Add(xyz[0], xyz[1], xyz[2]);
  }

  void ReadPolygon(const std::string_view* indices, std::size_t length, std::uint64_t i) {
    triangles_->BeginPolygon();
    for (std::size_t k = 0; k < length; ++k) {
      std::uint64_t index = 0;
      if (!ParseCount(indices[k], &index) || !triangles_->AddIndex(index)) {
        Fail(reader_.line_number(), "face " + std::to_string(i) + ": vertex index " + Quote(indices[k]) +
                                        " is not one of the header's " +
                                        std::to_string(header_.VertexCount()) + " vertices");
      }
    }
    triangles_->EndPolygon();
  }

  [[noreturn]] void FailCount(const PlyElement& element, std::uint64_t i, std::size_t found) const {
    if (element.HasLists()) {
      Fail(reader_.line_number(), element.Item(i) + ": list lengths do not match the " +
                                      std::to_string(found) + " values on the line");
    }
    Fail(reader_.line_number(), "expected " + std::to_string(element.properties.size()) +
                                    " values for " + element.Item(i) + ", found " + std::to_string(found));
  }

  LineReader reader_;
  std::vector<std::string_view> tokens_;   // of the current line, reused
  std::size_t remaining_bytes_;
  const PlyHeader& header_;
  const std::string& name_;
  TriangleCollector* triangles_;
  PointCollector points_;
};

std::string PlyHeaderText(const char* encoding, const char* type, Eigen::Index count) {
  return std::string("ply\nformat ") + encoding + " 1.0\ncomment written by c3po\nelement vertex " +
         std::to_string(count) + "\nproperty " + type + " x\nproperty " + type + " y\nproperty " +
         type + " z\nend_header\n";
}

}  // namespace

PointSet ParsePly(std::string_view bytes, const std::string& name) {
  const PlyHeader header = PlyHeaderParser(bytes, name).Parse();
  if (header.encoding == PlyEncoding::kAscii) return PlyAsciiReader(bytes, header, name).Read();
  return PlyBinaryReader(bytes, header, name).Read();
}

void WritePlyBinary(const std::string& path, const PointSet& points, bool sync) {
  CheckWritable(path, points, true);
  WriteFileAtomically(path, [&points](std::ostream& out) {
    out << PlyHeaderText("binary_little_endian", "float", points.cols());
    constexpr Eigen::Index kChunk = 1 << 14;
    std::string buffer;
    for (Eigen::Index start = 0; start < points.cols(); start += kChunk) {
      buffer.clear();
      const Eigen::Index end = std::min(points.cols(), start + kChunk);
      for (Eigen::Index i = start; i < end; ++i) {
        for (int k = 0; k < 3; ++k) AppendFloat32LE(&buffer, static_cast<float>(points(k, i)));
      }
      out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    }
  }, sync);
}

}  // namespace cloud_detail

void WritePly(const std::string& path, const PointSet& points) {
  cloud_detail::WritePlyBinary(path, points, true);
}

void WritePlyAscii(const std::string& path, const PointSet& points) {
  cloud_detail::CheckWritable(path, points, false);
  WriteFileAtomically(path, [&points](std::ostream& out) {
    out << cloud_detail::PlyHeaderText("ascii", "double", points.cols());
    for (Eigen::Index i = 0; i < points.cols(); ++i) {
      out << cloud_detail::FormatDouble(points(0, i)) << ' ' << cloud_detail::FormatDouble(points(1, i))
          << ' ' << cloud_detail::FormatDouble(points(2, i)) << '\n';
    }
  });
}

namespace mesh_detail {

MeshData ParsePlyMesh(std::string_view bytes, const std::string& name) {
  if (bytes.empty()) throw InputError(name, "empty file");
  cloud_detail::PlyHeader header = cloud_detail::PlyHeaderParser(bytes, name).Parse();
  cloud_detail::FindFaceIndices(&header, name);
  TriangleCollector triangles(header.VertexCount());
  MeshData mesh;
  mesh.vertices = header.encoding == cloud_detail::PlyEncoding::kAscii
                      ? cloud_detail::PlyAsciiReader(bytes, header, name, &triangles).Read()
                      : cloud_detail::PlyBinaryReader(bytes, header, name, &triangles).Read();
  mesh.triangles = triangles.Take();
  return mesh;
}

}  // namespace mesh_detail
}  // namespace c3po
