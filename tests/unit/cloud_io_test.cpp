// Point-cloud readers and writers: round trips through every format, PLY/PCD
// variants built byte by byte here (an encoder independent of the library),
// malformed inputs, and a seeded mutation sweep (no crash, only InputError).
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/io/cloud_io.hpp"
#include "test_helpers.hpp"

using c3po::test::InputErrorOf;

namespace {

using c3po::CloudFormat;
using c3po::InputError;
using c3po::PointSet;

PointSet RandomPoints(std::uint64_t seed, int n, double scale) {
  c3po::Rng rng(seed);
  PointSet points(3, n);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) points(k, i) = rng.Uniform(-scale, scale);
  }
  return points;
}

// What a float32 file stores for `points`. (An element loop on purpose: with
// Eigen 3.4.0 and GCC 12 -O3 the chained expression
// points.cast<float>().cast<double>() leaves some tail elements unrounded.)
PointSet AsFloat32(const PointSet& points) {
  PointSet rounded(3, points.cols());
  for (Eigen::Index i = 0; i < points.size(); ++i) rounded.data()[i] = static_cast<float>(points.data()[i]);
  return rounded;
}

// The message of the InputError thrown by `parse`, or "" if none was thrown.
std::string ParseError(const std::string& bytes, CloudFormat format, const std::string& name) {
  return InputErrorOf([&] { c3po::ParseCloud(bytes, format, name); });
}

// ---- An independent PLY encoder --------------------------------------------

struct TypeInfo {
  const char* name;
  int size;
  bool is_float;
  bool is_signed;
};

TypeInfo Type(const std::string& name) {
  if (name == "char" || name == "int8") return {name == "char" ? "char" : "int8", 1, false, true};
  if (name == "uchar" || name == "uint8") return {name == "uchar" ? "uchar" : "uint8", 1, false, false};
  if (name == "short" || name == "int16") return {name == "short" ? "short" : "int16", 2, false, true};
  if (name == "ushort" || name == "uint16") return {name == "ushort" ? "ushort" : "uint16", 2, false, false};
  if (name == "int" || name == "int32") return {name == "int" ? "int" : "int32", 4, false, true};
  if (name == "uint" || name == "uint32") return {name == "uint" ? "uint" : "uint32", 4, false, false};
  if (name == "float" || name == "float32") return {name == "float" ? "float" : "float32", 4, true, true};
  return {name == "double" ? "double" : "float64", 8, true, true};
}

// Encodes `value` as `type` in little- or big-endian byte order.
std::string Encode(double value, const std::string& type_name, bool big_endian) {
  const TypeInfo type = Type(type_name);
  unsigned char bytes[8] = {};
  if (type.is_float && type.size == 4) {
    const float f = static_cast<float>(value);
    std::memcpy(bytes, &f, 4);
  } else if (type.is_float) {
    std::memcpy(bytes, &value, 8);
  } else {
    const auto integer = static_cast<std::int64_t>(std::llround(value));
    for (int i = 0; i < type.size; ++i) bytes[i] = static_cast<unsigned char>((integer >> (8 * i)) & 0xFF);
  }
  std::string out(reinterpret_cast<char*>(bytes), static_cast<std::size_t>(type.size));
  // The host is little-endian (x86/arm); swap for big-endian output.
  if (big_endian) std::reverse(out.begin(), out.end());
  return out;
}

std::string Text(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

struct PlySpec {
  std::string encoding = "binary_little_endian";   // or ascii / binary_big_endian
  std::string coordinate_type = "float";
  bool face_before = false;
  bool face_after = false;
  bool extra_properties = false;   // nx (double) before x, red (uchar) between, a list after z
};

// The value each property of vertex i holds (the test's ground truth).
double ExtraValue(int i) { return 10 + i; }

std::string BuildPly(const PlySpec& spec, const PointSet& points) {
  const bool ascii = spec.encoding == "ascii";
  const bool big = spec.encoding == "binary_big_endian";
  std::string out = "ply\nformat " + spec.encoding + " 1.0\ncomment built by the test\n";
  const std::string face_header = "element face 2\nproperty list uchar int vertex_indices\nproperty uchar flags\n";
  if (spec.face_before) out += face_header;
  out += "element vertex " + std::to_string(points.cols()) + "\n";
  const std::string& c = spec.coordinate_type;
  if (spec.extra_properties) out += "property double nx\n";
  out += "property " + c + " x\n";
  if (spec.extra_properties) out += "property uchar red\n";
  out += "property " + c + " y\nproperty " + c + " z\n";
  if (spec.extra_properties) out += "property list uchar float texcoord\n";
  if (spec.face_after) out += face_header;
  out += "end_header\n";

  const auto value = [&](double v, const std::string& type) {
    if (!Type(type).is_float) v = std::round(v);
    return ascii ? Text(Type(type).is_float && Type(type).size == 4 ? static_cast<float>(v) : v) + " "
                 : Encode(v, type, big);
  };
  const auto faces = [&] {
    std::string f;
    for (int i = 0; i < 2; ++i) {
      f += value(3, "uchar") + value(0, "int") + value(1, "int") + value(2, "int") + value(7, "uchar");
      if (ascii) f += "\n";
    }
    return f;
  };
  if (spec.face_before) out += faces();
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    if (spec.extra_properties) out += value(-1.5, "double");
    out += value(points(0, i), c);
    if (spec.extra_properties) out += value(ExtraValue(static_cast<int>(i)), "uchar");
    out += value(points(1, i), c) + value(points(2, i), c);
    if (spec.extra_properties) out += value(2, "uchar") + value(0.25, "float") + value(0.5, "float");
    if (ascii) out += "\n";
  }
  if (spec.face_after) out += faces();
  return out;
}

// What reading should give for a coordinate stored as `type`.
PointSet Stored(const PointSet& points, const std::string& type) {
  const TypeInfo info = Type(type);
  if (info.is_float && info.size == 4) return AsFloat32(points);
  if (info.is_float) return points;
  return points.array().round().matrix();
}

}  // namespace

TEST_CASE("every writer round-trips through ReadCloud") {
  c3po::test::TempDir dir("cloud_io_round_trip");
  const PointSet points = RandomPoints(1, 257, 3.0);

  c3po::WritePly(dir / "binary.ply", points);
  CHECK(c3po::ReadCloud(dir / "binary.ply") == AsFloat32(points));
  c3po::WritePlyAscii(dir / "ascii.ply", points);
  CHECK(c3po::ReadCloud(dir / "ascii.ply") == points);
  c3po::WritePcd(dir / "binary.pcd", points, true);
  CHECK(c3po::ReadCloud(dir / "binary.pcd") == AsFloat32(points));
  c3po::WritePcd(dir / "ascii.pcd", points, false);
  CHECK(c3po::ReadCloud(dir / "ascii.pcd") == points);
  c3po::WriteXyz(dir / "cloud.xyz", points);
  CHECK(c3po::ReadCloud(dir / "cloud.xyz") == points);

  // Only the five outputs exist: no temporary files are left behind.
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    CHECK(entry.path().filename().string().front() != '.');
    ++files;
  }
  CHECK(files == 5);
}

TEST_CASE("a single point and extreme magnitudes round-trip") {
  c3po::test::TempDir dir("cloud_io_extremes");
  PointSet points(3, 3);
  points << 1e-300, -0.0, 1e300, 5e-324, 123456789.123456789, -1e-7, 0.1, 0.2, 0.3;
  c3po::WritePlyAscii(dir / "a.ply", points);
  CHECK(c3po::ReadCloud(dir / "a.ply") == points);
  c3po::WriteXyz(dir / "a.xyz", points);
  CHECK(c3po::ReadCloud(dir / "a.xyz") == points);
  // 1e300 does not fit a float: the float writers refuse instead of writing inf.
  CHECK(InputErrorOf([&] { c3po::WritePly(dir / "b.ply", points); }).rfind(dir / "b.ply: cannot write: point 2 ", 0) == 0);
  CHECK_FALSE(std::filesystem::exists(dir / "b.ply"));
  const PointSet one = RandomPoints(2, 1, 1.0);
  c3po::WritePly(dir / "one.ply", one);
  CHECK(c3po::ReadCloud(dir / "one.ply") == AsFloat32(one));
}

TEST_CASE("PLY variants: encodings, scalar types, extra properties, face elements") {
  const PointSet points = RandomPoints(3, 17, 100.0);
  const char* encodings[] = {"ascii", "binary_little_endian", "binary_big_endian"};
  const char* types[] = {"float", "double", "float32", "float64", "int", "short", "int16", "char"};
  for (const char* encoding : encodings) {
    for (const char* type : types) {
      for (int layout = 0; layout < 4; ++layout) {
        PlySpec spec;
        spec.encoding = encoding;
        spec.coordinate_type = type;
        spec.face_before = layout == 1 || layout == 3;
        spec.face_after = layout == 2 || layout == 3;
        spec.extra_properties = layout >= 2;
        const PointSet source = Type(type).size == 1 ? RandomPoints(4, 17, 100.0) : points;
        CAPTURE(encoding);
        CAPTURE(type);
        CAPTURE(layout);
        const PointSet read = c3po::ParseCloud(BuildPly(spec, source), CloudFormat::kPly, "v.ply");
        CHECK(read == Stored(source, type));
      }
    }
  }
}

TEST_CASE("PLY: unsigned types and CRLF header") {
  PointSet points(3, 2);
  points << 1, 2, 3, 4, 250, 6;
  for (const char* type : {"uchar", "uint8", "ushort", "uint16", "uint", "uint32"}) {
    PlySpec spec;
    spec.coordinate_type = type;
    CHECK(c3po::ParseCloud(BuildPly(spec, points), CloudFormat::kPly, "u.ply") == points);
  }
  std::string crlf = "ply\r\nformat ascii 1.0\r\nelement vertex 2\r\nproperty float x\r\n"
                     "property float y\r\nproperty float z\r\nend_header\r\n1 3 250\r\n2 4 6\r\n";
  CHECK(c3po::ParseCloud(crlf, CloudFormat::kPly, "crlf.ply") == points);
}

TEST_CASE("PCD: fields in any order, extra fields with COUNT, ascii and binary") {
  const PointSet points = RandomPoints(5, 9, 2.0);
  std::string header = "# .PCD v0.7\nVERSION 0.7\nFIELDS rgb z normal y x\nSIZE 4 8 4 4 8\nTYPE U F F F F\n"
                       "COUNT 1 1 3 1 1\nWIDTH 3\nHEIGHT 3\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 9\n";
  std::string ascii = header + "DATA ascii\n";
  std::string binary = header + "DATA binary\n";
  for (int i = 0; i < 9; ++i) {
    ascii += "4278190080 " + Text(points(2, i)) + " 0 0 1 " + Text(static_cast<float>(points(1, i))) + " " +
             Text(points(0, i)) + "\n";
    binary += Encode(4278190080.0, "uint", false) + Encode(points(2, i), "double", false) +
              Encode(0, "float", false) + Encode(0, "float", false) + Encode(1, "float", false) +
              Encode(points(1, i), "float", false) + Encode(points(0, i), "double", false);
  }
  PointSet expected = points;
  expected.row(1) = AsFloat32(points).row(1);
  CHECK(c3po::ParseCloud(ascii, CloudFormat::kPcd, "a.pcd") == expected);
  CHECK(c3po::ParseCloud(binary, CloudFormat::kPcd, "b.pcd") == expected);
}

TEST_CASE("XYZ: commas, comments, blank lines, extra columns") {
  const std::string text = "# exported by a scanner\n\n1,2,3,255,0,0\n  4\t5  6 # trailing comment\n"
                           "7.5e0 -8 +9 0.1\r\n";
  PointSet expected(3, 3);
  expected << 1, 4, 7.5, 2, 5, -8, 3, 6, 9;
  CHECK(c3po::ParseCloud(text, CloudFormat::kXyz, "s.xyz") == expected);
}

TEST_CASE("format from extension") {
  CHECK(c3po::CloudFormatFromPath("a/b.PLY") == CloudFormat::kPly);
  CHECK(c3po::CloudFormatFromPath("b.pcd") == CloudFormat::kPcd);
  CHECK(c3po::CloudFormatFromPath("b.xyz") == CloudFormat::kXyz);
  CHECK(c3po::CloudFormatFromPath("b.csv") == CloudFormat::kXyz);
  CHECK(InputErrorOf([] { c3po::CloudFormatFromPath("dir.v2/cloud"); }).find("dir.v2/cloud: unknown") == 0);
  CHECK(InputErrorOf([] { c3po::CloudFormatFromPath("mesh.obj"); }) != "");
}

TEST_CASE("malformed PLY files give one-line InputErrors naming the file") {
  const PointSet points = RandomPoints(6, 1000, 1.0);
  PlySpec binary_spec;
  const std::string binary = BuildPly(binary_spec, points);
  const std::size_t header_size = binary.size() - 1000 * 12;

  // Truncated binary data: 412 whole vertices plus a partial one.
  const std::string truncated = binary.substr(0, header_size + 412 * 12 + 5);
  CHECK(ParseError(truncated, CloudFormat::kPly, "cloud.ply") ==
        "cloud.ply: truncated binary data: header says 1000 vertices, file holds 412");

  // Header claiming 10^12 vertices: an error, not an allocation.
  std::string huge = binary;
  huge.replace(huge.find("vertex 1000"), 11, "vertex 1000000000000");
  CHECK(ParseError(huge, CloudFormat::kPly, "huge.ply").find("huge.ply: truncated binary data: header says 1000000000000 vertices") == 0);
  PlySpec ascii_spec;
  ascii_spec.encoding = "ascii";
  std::string huge_ascii = BuildPly(ascii_spec, points);
  huge_ascii.replace(huge_ascii.find("vertex 1000"), 11, "vertex 1000000000000");
  CHECK(ParseError(huge_ascii, CloudFormat::kPly, "h.ply") == "h.ply: truncated: header says 1000000000000 vertices, file holds 1000");
  // ... also for a face element with a list before the vertices.
  PlySpec face_spec;
  face_spec.face_before = true;
  std::string huge_faces = BuildPly(face_spec, points);
  huge_faces.replace(huge_faces.find("face 2"), 6, "face 999999999999");
  CHECK(ParseError(huge_faces, CloudFormat::kPly, "f.ply").find("f.ply: truncated binary data") == 0);
  // An element without properties but a huge count occupies nothing (no hang).
  std::string empty_element = binary;
  empty_element.replace(empty_element.find("end_header"), 10, "element nothing 999999999999999\nend_header");
  CHECK(c3po::ParseCloud(empty_element, CloudFormat::kPly, "e.ply") == AsFloat32(points));

  // Wrong vertex counts in ASCII: too many and too few lines.
  std::string ascii = BuildPly(ascii_spec, points.leftCols(5));
  std::string says_more = ascii;
  says_more.replace(says_more.find("vertex 5"), 8, "vertex 7");
  CHECK(ParseError(says_more, CloudFormat::kPly, "m.ply") == "m.ply: truncated: header says 7 vertices, file holds 5");
  std::string says_fewer = ascii;
  says_fewer.replace(says_fewer.find("vertex 5"), 8, "vertex 4");
  CHECK(ParseError(says_fewer, CloudFormat::kPly, "f.ply") == "f.ply: line 13: unexpected data after the last element (header says 4 vertices)");
  std::string binary_fewer = binary;
  binary_fewer.replace(binary_fewer.find("vertex 1000"), 11, "vertex 999 ");
  CHECK(ParseError(binary_fewer, CloudFormat::kPly, "bf.ply").find("bf.ply: 12 bytes of unexpected data") == 0);

  // A line with too few values names its line.
  std::string short_line = ascii;
  const std::size_t second_vertex = short_line.find('\n', short_line.find("end_header") + 11) + 1;   // 2nd vertex
  short_line.replace(second_vertex, short_line.find('\n', second_vertex) - second_vertex, "1 2");
  CHECK(ParseError(short_line, CloudFormat::kPly, "cloud.ply") == "cloud.ply: line 10: expected 3 values for vertex 1, found 2");

  // Non-finite coordinates (ASCII text and binary bits).
  std::string nan_ascii = ascii;
  nan_ascii.replace(second_vertex, nan_ascii.find('\n', second_vertex) - second_vertex, "0 NaN 1");
  CHECK(ParseError(nan_ascii, CloudFormat::kPly, "n.ply") == "n.ply: line 10: vertex 1: non-finite coordinate");
  PointSet with_inf = points.leftCols(20);
  with_inf(1, 17) = std::numeric_limits<double>::infinity();
  CHECK(ParseError(BuildPly(binary_spec, with_inf), CloudFormat::kPly, "i.ply") == "i.ply: vertex 17: non-finite coordinate");
  with_inf(1, 17) = std::numeric_limits<double>::quiet_NaN();
  PlySpec be_double;
  be_double.encoding = "binary_big_endian";
  be_double.coordinate_type = "double";
  CHECK(ParseError(BuildPly(be_double, with_inf), CloudFormat::kPly, "i.ply") == "i.ply: vertex 17: non-finite coordinate");

  // Headers.
  CHECK(ParseError("", CloudFormat::kPly, "empty.ply") == "empty.ply: empty file");
  CHECK(ParseError("\x89PNG\r\n\x1a\n", CloudFormat::kPly, "g.ply") == "g.ply: line 1: not a PLY file (first line is not 'ply')");
  CHECK(ParseError("ply\nformat ascii 1.0\nelement vertex 3\n", CloudFormat::kPly, "g.ply") == "g.ply: line 3: header has no end_header line");
  CHECK(ParseError("ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
                   CloudFormat::kPly, "z.ply") == "z.ply: no points (header says 0 vertices)");
  CHECK(ParseError("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n",
                   CloudFormat::kPly, "z.ply") == "z.ply: vertex element has no 'z' property");
  CHECK(ParseError("ply\nformat binary_middle_endian 1.0\n", CloudFormat::kPly, "z.ply") == "z.ply: line 2: unknown PLY format 'binary_middle_endian'");
  CHECK(ParseError("ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n", CloudFormat::kPly, "z.ply") == "z.ply: line 4: unknown property type 'float128'");
  CHECK(ParseError("ply\nformat ascii 1.0\nelement vertex -1\n", CloudFormat::kPly, "z.ply") == "z.ply: line 3: expected 'element <name> <count>'");
  CHECK(ParseError("ply\nformat ascii 1.0\nelement vertex 1\nproperty list float float x\n", CloudFormat::kPly, "z.ply") == "z.ply: line 4: list count type must be an integer type");
  CHECK(ParseError("ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\nproperty float y\nproperty float z\nend_header\n",
                   CloudFormat::kPly, "z.ply") == "z.ply: vertex property 'x' is a list, expected a scalar");
  // A negative list length in binary data.
  std::string negative = "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                         "property float z\nproperty list int float extra\nend_header\n" +
                         Encode(1, "float", false) + Encode(2, "float", false) + Encode(3, "float", false) +
                         Encode(-2, "int", false);
  CHECK(ParseError(negative, CloudFormat::kPly, "neg.ply") == "neg.ply: vertex 0: negative list length in property 'extra'");
}

TEST_CASE("malformed PCD and XYZ files give InputErrors naming the file") {
  const std::string header = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\n";
  CHECK(ParseError(header + "DATA binary_compressed\n\x10\x00", CloudFormat::kPcd, "c.pcd") ==
        "c.pcd: line 9: DATA binary_compressed is not supported (save the cloud as ascii or binary PCD)");
  CHECK(ParseError(header + "DATA binary\n" + std::string(13, '\0'), CloudFormat::kPcd, "t.pcd") ==
        "t.pcd: truncated binary data: header says 2 points, file holds 1");
  std::string huge = header + "DATA binary\n" + std::string(24, '\0');
  huge.replace(huge.find("POINTS 2"), 8, "POINTS 1000000000000");
  huge.replace(huge.find("WIDTH 2"), 7, "WIDTH 1000000000000");
  CHECK(ParseError(huge, CloudFormat::kPcd, "h.pcd") == "h.pcd: truncated binary data: header says 1000000000000 points, file holds 2");
  CHECK(ParseError(header + "DATA ascii\n1 2 3\n", CloudFormat::kPcd, "a.pcd") == "a.pcd: truncated: header says 2 points, file holds 1");
  CHECK(ParseError(header + "DATA ascii\n1 2 3\n4 5 nan\n", CloudFormat::kPcd, "a.pcd") == "a.pcd: line 11: point 1: non-finite coordinate");
  CHECK(ParseError(header + "DATA ascii\n1 2 3\n4 5\n", CloudFormat::kPcd, "a.pcd") == "a.pcd: line 11: expected 3 values, found 2");
  CHECK(ParseError(header + "DATA ascii\n1 2 3\n4 5 6\n7 8 9\n", CloudFormat::kPcd, "a.pcd") ==
        "a.pcd: line 12: unexpected data after the last point (header says 2 points)");
  std::string wrong_points = header + "DATA ascii\n1 2 3\n4 5 6\n";
  wrong_points.replace(wrong_points.find("POINTS 2"), 8, "POINTS 3");
  CHECK(ParseError(wrong_points, CloudFormat::kPcd, "p.pcd") == "p.pcd: line 9: POINTS 3 differs from WIDTH x HEIGHT = 2");
  CHECK(ParseError("VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 1\nDATA ascii\n1 2\n", CloudFormat::kPcd, "n.pcd") ==
        "n.pcd: no 'z' field in the PCD header");
  CHECK(ParseError("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F X\nPOINTS 1\nDATA ascii\n1 2 3\n", CloudFormat::kPcd, "n.pcd") ==
        "n.pcd: line 6: field 'z': unsupported TYPE 'X' with SIZE 4");
  CHECK(ParseError("garbage", CloudFormat::kPcd, "g.pcd") == "g.pcd: line 1: unknown header keyword 'garbage'");
  // Found by fuzzing: a header line of only a vertical tab.
  CHECK(ParseError("\v", CloudFormat::kPcd, "v.pcd") == "v.pcd: not a PCD file (no DATA line in the header)");

  CHECK(ParseError("1 2 3\n4 5\n", CloudFormat::kXyz, "cloud.xyz") == "cloud.xyz: line 2: expected 3 coordinates, found 2");
  CHECK(ParseError("1 2 3\n4 5 inf\n", CloudFormat::kXyz, "cloud.xyz") == "cloud.xyz: line 2: point 1: non-finite coordinate");
  CHECK(ParseError("1 2 3\n4 5 1e999\n", CloudFormat::kXyz, "cloud.xyz") == "cloud.xyz: line 2: point 1: non-finite coordinate");
  CHECK(ParseError("1 2 3\nx y z\n", CloudFormat::kXyz, "cloud.xyz") == "cloud.xyz: line 2: 'x' is not a number");
  CHECK(ParseError("# only a comment\n\n", CloudFormat::kXyz, "c.xyz") == "c.xyz: no points (only blank lines and comments)");
  CHECK(ParseError("", CloudFormat::kXyz, "e.xyz") == "e.xyz: empty file");
  CHECK(ParseError("1 2 +-3\n", CloudFormat::kXyz, "s.xyz") == "s.xyz: line 1: '+-3' is not a number");
}

TEST_CASE("ReadCloud: missing file and folder") {
  c3po::test::TempDir dir("cloud_io_missing");
  CHECK(InputErrorOf([&] { c3po::ReadCloud(dir / "none.ply"); }) == dir / "none.ply" + ": cannot read: No such file or directory");
  std::filesystem::create_directory(dir / "folder.ply");
  CHECK(InputErrorOf([&] { c3po::ReadCloud(dir / "folder.ply"); }) == dir / "folder.ply" + ": cannot read: Is a directory");
}

TEST_CASE("mutated and truncated inputs never crash: valid cloud or InputError") {
  const PointSet points = RandomPoints(7, 6, 1.0);
  std::vector<std::pair<std::string, CloudFormat>> seeds;
  for (const char* encoding : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    PlySpec spec;
    spec.encoding = encoding;
    spec.face_before = true;
    spec.extra_properties = true;
    seeds.emplace_back(BuildPly(spec, points), CloudFormat::kPly);
  }
  c3po::test::TempDir dir("cloud_io_mutation");
  c3po::WritePcd(dir / "a.pcd", points, false);
  c3po::WritePcd(dir / "b.pcd", points, true);
  c3po::WriteXyz(dir / "c.xyz", points);
  seeds.emplace_back(c3po::ReadFileToString(dir / "a.pcd"), CloudFormat::kPcd);
  seeds.emplace_back(c3po::ReadFileToString(dir / "b.pcd"), CloudFormat::kPcd);
  seeds.emplace_back(c3po::ReadFileToString(dir / "c.xyz"), CloudFormat::kXyz);

  c3po::Rng rng(8);
  const char interesting[] = {'0', '9', ' ', '\n', '-', '.', 'e', '\0', '\xff', 'n'};
  int parsed = 0, rejected = 0;
  const auto attempt = [&](const std::string& bytes, CloudFormat format) {
    try {
      const PointSet cloud = c3po::ParseCloud(bytes, format, "m");
      REQUIRE(cloud.cols() > 0);
      REQUIRE(cloud.allFinite());
      ++parsed;
    } catch (const InputError& error) {
      REQUIRE(std::string(error.what()).rfind("m: ", 0) == 0);
      REQUIRE(std::string(error.what()).find('\n') == std::string::npos);
      ++rejected;
    }
  };
  for (const auto& [seed, format] : seeds) {
    for (std::size_t length = 0; length < seed.size(); ++length) attempt(seed.substr(0, length), format);
    for (int trial = 0; trial < 400; ++trial) {
      std::string mutated = seed;
      const int edits = 1 + rng.UniformInt(3);
      for (int e = 0; e < edits; ++e) {
        const std::size_t at = static_cast<std::size_t>(rng.UniformInt(static_cast<int>(mutated.size())));
        mutated[at] = rng.Uniform() < 0.5 ? interesting[rng.UniformInt(10)] : static_cast<char>(rng.UniformInt(256));
      }
      attempt(mutated, format);
    }
  }
  MESSAGE("mutation sweep: " << parsed << " parsed, " << rejected << " rejected with InputError");
  CHECK(rejected > 0);
}

TEST_CASE("fixture files: good_* parse to the reference points, bad_* give InputError") {
  // Every good fixture stores the same 4 points (see tests/fixtures/clouds/README.md).
  PointSet reference(3, 4);
  reference << 0, 1, 0, 0,
               0, 0, 2, 0,
               0, 0, 0, 3;
  const std::string folder = c3po::test::SourceDir() + "/tests/fixtures/clouds";
  REQUIRE(std::filesystem::is_directory(folder));
  int good = 0, bad = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    const std::string path = entry.path().string();
    const std::string leaf = entry.path().filename().string();
    CAPTURE(leaf);
    if (leaf.rfind("good_", 0) == 0) {
      CHECK(c3po::ReadCloud(path) == reference);
      ++good;
    } else if (leaf.rfind("bad_", 0) == 0) {
      const std::string message = InputErrorOf([&] { c3po::ReadCloud(path); });
      CHECK(message.rfind(path + ": ", 0) == 0);
      ++bad;
    }
  }
  CHECK(good >= 6);
  CHECK(bad >= 6);
}
