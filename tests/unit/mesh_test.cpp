// Mesh loading (every format, written here byte by byte), surface sampling and
// closest-point queries against analytic values and brute force.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/io/mesh_io.hpp"
#include "test_helpers.hpp"

namespace {

using c3po::Mesh;
using c3po::PointSet;

// An axis-aligned box [lo, lo + size] as 8 corners and 6 quads (cyclic order).
// Corner i has coordinate lo + (bit0 * sx, bit1 * sy, bit2 * sz).
const Eigen::Vector3d kLo(0.5, -1.0, 2.0), kSize(1.0, 2.0, 3.0);
const int kQuads[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                          {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
const double kBoxArea = 2 * (1.0 * 2.0 + 2.0 * 3.0 + 3.0 * 1.0);  // 22

Eigen::Vector3d Corner(int i) {
  return kLo + Eigen::Vector3d((i & 1) * kSize.x(), ((i >> 1) & 1) * kSize.y(), ((i >> 2) & 1) * kSize.z());
}

std::vector<Eigen::Vector3i> BoxTriangles() {
  std::vector<Eigen::Vector3i> t;
  for (const auto& q : kQuads) {
    t.emplace_back(q[0], q[1], q[2]);
    t.emplace_back(q[0], q[2], q[3]);
  }
  return t;
}

Mesh BoxMesh() {
  Mesh mesh;
  mesh.vertices.resize(3, 8);
  for (int i = 0; i < 8; ++i) mesh.vertices.col(i) = Corner(i);
  const auto triangles = BoxTriangles();
  mesh.triangles.resize(3, 12);
  for (int t = 0; t < 12; ++t) mesh.triangles.col(t) = triangles[t];
  return mesh;
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string BoxObj() {
  std::ostringstream out;
  out << "# box\n";
  for (int i = 0; i < 8; ++i) out << "v " << Corner(i).x() << ' ' << Corner(i).y() << ' ' << Corner(i).z() << '\n';
  for (const auto& q : kQuads) out << "f " << q[0] + 1 << ' ' << q[1] + 1 << ' ' << q[2] + 1 << ' ' << q[3] + 1 << '\n';
  return out.str();
}

std::string BoxOff() {
  std::ostringstream out;
  out << "OFF\n8 6 0\n";
  for (int i = 0; i < 8; ++i) out << Corner(i).x() << ' ' << Corner(i).y() << ' ' << Corner(i).z() << '\n';
  for (const auto& q : kQuads) out << "4 " << q[0] << ' ' << q[1] << ' ' << q[2] << ' ' << q[3] << '\n';
  return out.str();
}

std::string PlyHeader(const std::string& format, int vertices, int faces) {
  std::ostringstream out;
  out << "ply\nformat " << format << " 1.0\ncomment box\nelement vertex " << vertices
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << faces
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  return out.str();
}

std::string BoxPlyAscii() {
  std::ostringstream out;
  out << PlyHeader("ascii", 8, 6);
  for (int i = 0; i < 8; ++i) out << Corner(i).x() << ' ' << Corner(i).y() << ' ' << Corner(i).z() << '\n';
  for (const auto& q : kQuads) out << "4 " << q[0] << ' ' << q[1] << ' ' << q[2] << ' ' << q[3] << '\n';
  return out.str();
}

template <class T>
void AppendBytes(std::string* out, T value, bool big_endian) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (big_endian) std::reverse(bytes, bytes + sizeof(T));  // the test machine is little-endian
  out->append(bytes, sizeof(T));
}

std::string BoxPlyBinary(bool big_endian) {
  std::string out = PlyHeader(big_endian ? "binary_big_endian" : "binary_little_endian", 8, 6);
  for (int i = 0; i < 8; ++i) {
    for (int k = 0; k < 3; ++k) AppendBytes(&out, static_cast<float>(Corner(i)(k)), big_endian);
  }
  for (const auto& q : kQuads) {
    AppendBytes(&out, static_cast<std::uint8_t>(4), big_endian);
    for (int k = 0; k < 4; ++k) AppendBytes(&out, static_cast<std::int32_t>(q[k]), big_endian);
  }
  return out;
}

std::string BoxStlAscii() {
  std::ostringstream out;
  out << "solid box\n";
  for (const auto& t : BoxTriangles()) {
    out << " facet normal 0 0 0\n  outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d v = Corner(t(k));
      out << "   vertex " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
    }
    out << "  endloop\n endfacet\n";
  }
  out << "endsolid box\n";
  return out.str();
}

std::string BoxStlBinary() {
  std::string out(80, ' ');
  out.replace(0, 10, "binary box");
  AppendBytes(&out, static_cast<std::uint32_t>(12), false);
  for (const auto& t : BoxTriangles()) {
    for (int k = 0; k < 3; ++k) AppendBytes(&out, 0.0f, false);  // normal
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 3; ++k) AppendBytes(&out, static_cast<float>(Corner(t(c))(k)), false);
    }
    AppendBytes(&out, static_cast<std::uint16_t>(0), false);
  }
  return out;
}

void CheckIsBox(const Mesh& mesh, double scale) {
  CHECK(mesh.triangles.cols() == 12);
  CHECK(mesh.SurfaceArea() == doctest::Approx(kBoxArea * scale * scale).epsilon(1e-9));
  const Eigen::AlignedBox3d box = mesh.BoundingBox();
  CHECK((box.min() - scale * kLo).norm() < 1e-9 * scale);
  CHECK((box.max() - scale * (kLo + kSize)).norm() < 1e-9 * scale);
  CHECK(mesh.Diameter() == doctest::Approx(scale * kSize.norm()).epsilon(1e-9));
  CHECK_NOTHROW(mesh.Validate());
}

// Expects LoadMesh to throw InputError whose message names the file.
void CheckLoadFails(const std::string& path) {
  CAPTURE(path);
  try {
    c3po::LoadMesh(path);
    FAIL_CHECK("LoadMesh accepted " << path);
  } catch (const c3po::InputError& e) {
    const std::string message = e.what();
    CAPTURE(message);
    CHECK(message.find(path) != std::string::npos);
    CHECK(message.find('\n') == std::string::npos);
  }
}

// Barycentric coordinates (alpha for a, beta for b, gamma for c) of p's projection.
Eigen::Vector3d Barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  Eigen::Matrix<double, 3, 2> E;
  E << b - a, c - a;
  const Eigen::Vector2d uv = E.colPivHouseholderQr().solve(p - a);
  return {1 - uv(0) - uv(1), uv(0), uv(1)};
}

}  // namespace

TEST_CASE("every mesh format loads to the same box") {
  c3po::test::TempDir dir("mesh_formats");
  const std::vector<std::pair<std::string, std::string>> files = {
      {"box.obj", BoxObj()},
      {"box.off", BoxOff()},
      {"box_ascii.ply", BoxPlyAscii()},
      {"box_le.ply", BoxPlyBinary(false)},
      {"box_be.ply", BoxPlyBinary(true)},
      {"box_ascii.stl", BoxStlAscii()},
      {"box_binary.stl", BoxStlBinary()},
  };
  for (const auto& [name, contents] : files) {
    const std::string& file_name = name;  // CAPTURE's lambda may not name a structured binding (C++17)
    CAPTURE(file_name);
    WriteText(dir / name, contents);
    CheckIsBox(c3po::LoadMesh(dir / name), 1.0);
    CheckIsBox(c3po::LoadMesh(dir / name, 0.001), 0.001);  // a mesh in millimetres
  }
}

TEST_CASE("the hand-written fixture meshes load") {
  const std::string root = c3po::test::SourceDir() + "/tests/fixtures/objects/";
  for (const char* name : {"cube.obj", "cube.off", "cube.ply", "cube.stl"}) {
    CAPTURE(name);
    const Mesh mesh = c3po::LoadMesh(root + name);
    CHECK(mesh.triangles.cols() == 12);
    CHECK(mesh.SurfaceArea() == doctest::Approx(6.0));
    CHECK(mesh.Diameter() == doctest::Approx(std::sqrt(3.0)));
  }
}

TEST_CASE("bad mesh files give an InputError naming the file") {
  c3po::test::TempDir dir("mesh_errors");
  CheckLoadFails(dir / "does_not_exist.obj");
  CheckLoadFails(dir.path());  // a folder, not a file

  WriteText(dir / "empty.obj", "");
  CheckLoadFails(dir / "empty.obj");
  // Counts the file cannot hold are rejected before anything is allocated
  // (the fuzzer's OFF header claiming 8.9e9 faces asked for 48 GB).
  const std::string cube_off_body =
      "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
      "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";
  WriteText(dir / "huge_faces.off", "OFF\n8 8888888886 0\n" + cube_off_body);
  CheckLoadFails(dir / "huge_faces.off");
  WriteText(dir / "huge_vertices.off", "OFF\n# comment\n900000000000 6 0\n" + cube_off_body);
  CheckLoadFails(dir / "huge_vertices.off");
  WriteText(dir / "cube.off", "OFF\n8 6 0\n" + cube_off_body);
  CHECK(c3po::LoadMesh(dir / "cube.off").triangles.cols() == 12);
  WriteText(dir / "empty.ply", "");
  CheckLoadFails(dir / "empty.ply");
  WriteText(dir / "only_vertices.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  CheckLoadFails(dir / "only_vertices.obj");
  WriteText(dir / "only_points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n");
  CheckLoadFails(dir / "only_points.obj");
  WriteText(dir / "only_lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n");
  CheckLoadFails(dir / "only_lines.obj");
  WriteText(dir / "only_vertices.ply", PlyHeader("ascii", 3, 0) + "0 0 0\n1 0 0\n0 1 0\n");
  CheckLoadFails(dir / "only_vertices.ply");
  WriteText(dir / "zero_area.obj", "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n");
  CheckLoadFails(dir / "zero_area.obj");
  WriteText(dir / "nan.ply", PlyHeader("ascii", 3, 1) + "0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n");
  CheckLoadFails(dir / "nan.ply");
  WriteText(dir / "bad_index.ply", PlyHeader("ascii", 3, 1) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 99\n");
  CheckLoadFails(dir / "bad_index.ply");

  const std::string binary = BoxPlyBinary(false);
  WriteText(dir / "truncated.ply", binary.substr(0, binary.size() - 30));
  CheckLoadFails(dir / "truncated.ply");
  const std::string stl = BoxStlBinary();
  WriteText(dir / "truncated.stl", stl.substr(0, 84 + 50 * 5 + 7));
  CheckLoadFails(dir / "truncated.stl");

  c3po::Rng rng(41);
  std::string garbage;
  for (int i = 0; i < 4000; ++i) garbage.push_back(static_cast<char>(rng.UniformInt(256)));
  for (const char* name : {"garbage.obj", "garbage.ply", "garbage.stl", "garbage.off", "garbage.xyz"}) {
    WriteText(dir / name, garbage);
    CheckLoadFails(dir / name);
  }
  WriteText(dir / "words.obj", "this is not a mesh\nat all\n");
  CheckLoadFails(dir / "words.obj");
}

TEST_CASE("points and vertices outside every triangle do not count") {
  // A stray vertex (unreferenced, or only used by a point element) must not
  // enlarge the bounding box, and hence the diameter d.
  c3po::test::TempDir dir("mesh_stray");
  WriteText(dir / "stray_point.obj", BoxObj() + "v 100 100 100\np 9\n");
  WriteText(dir / "stray_vertex.ply", PlyHeader("ascii", 9, 6) + [] {
    std::ostringstream out;
    for (int i = 0; i < 8; ++i) out << Corner(i).x() << ' ' << Corner(i).y() << ' ' << Corner(i).z() << '\n';
    out << "100 100 100\n";
    for (const auto& q : kQuads) out << "4 " << q[0] << ' ' << q[1] << ' ' << q[2] << ' ' << q[3] << '\n';
    return out.str();
  }());
  for (const char* name : {"stray_point.obj", "stray_vertex.ply"}) {
    CAPTURE(name);
    CheckIsBox(c3po::LoadMesh(dir / name), 1.0);
  }
}

TEST_CASE("WriteObj round trip") {
  c3po::test::TempDir dir("mesh_write");
  const Mesh box = BoxMesh();
  c3po::WriteObj(box, dir / "out.obj");
  CheckIsBox(c3po::LoadMesh(dir / "out.obj"), 1.0);
}

TEST_CASE("Mesh::Validate rejects bad indices and non-finite vertices") {
  Mesh mesh = BoxMesh();
  mesh.triangles(1, 3) = 8;
  CHECK_THROWS_AS(mesh.Validate(), std::invalid_argument);
  mesh.triangles(1, 3) = -1;
  CHECK_THROWS_AS(mesh.Validate(), std::invalid_argument);
  mesh = BoxMesh();
  mesh.vertices(2, 5) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(mesh.Validate(), std::invalid_argument);
}

TEST_CASE("surface samples lie on the surface, on their triangle, deterministically") {
  const Mesh box = BoxMesh();
  const double d = box.Diameter();
  const auto sample = c3po::SampleSurfaceWithTriangles(box, 3000, 7);
  REQUIRE(sample.points.cols() == 3000);
  REQUIRE(sample.triangle.size() == 3000);
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d p = sample.points.col(i);
    CHECK(c3po::ClosestSurfacePoint(box, p).distance < 1e-9 * d);
    const int t = sample.triangle(i);
    REQUIRE(t >= 0);
    REQUIRE(t < 12);
    const Eigen::Vector3d on = c3po::ClosestPointOnTriangle(
        p, box.vertices.col(box.triangles(0, t)), box.vertices.col(box.triangles(1, t)),
        box.vertices.col(box.triangles(2, t)));
    CHECK((on - p).norm() < 1e-9 * d);
  }
  CHECK(c3po::SampleSurface(box, 3000, 7) == sample.points);
  CHECK(c3po::SampleSurface(box, 3000, 8) != sample.points);
  CHECK(c3po::SampleSurface(box, 0, 7).cols() == 0);
  CHECK_THROWS_AS(c3po::SampleSurface(box, -1, 7), std::invalid_argument);
  CHECK_THROWS_AS(c3po::SampleSurface(Mesh(), 10, 7), std::invalid_argument);
}

TEST_CASE("sampling is area-weighted: two triangles with areas 1 : 3") {
  Mesh mesh;
  mesh.vertices.resize(3, 6);
  mesh.vertices << 0, 1, 0, 0, 2, 0,   //
                   0, 0, 2, 0, 0, 3,   //
                   0, 0, 0, 5, 5, 5;   // area 1 at z = 0, area 3 at z = 5
  mesh.triangles.resize(3, 2);
  mesh.triangles << 0, 3, 1, 4, 2, 5;
  REQUIRE(mesh.SurfaceArea() == doctest::Approx(4.0));
  constexpr int kCount = 40000;
  const PointSet points = c3po::SampleSurface(mesh, kCount, 3);
  const double fraction = (points.row(2).array() < 2.5).cast<double>().sum() / kCount;
  const double sigma = std::sqrt(0.25 * 0.75 / kCount);  // binomial standard deviation
  CHECK(std::abs(fraction - 0.25) < 5 * sigma);
}

TEST_CASE("sampling is uniform inside a triangle: the 4 medial sub-triangles get 1/4 each") {
  Mesh mesh;
  mesh.vertices.resize(3, 3);
  mesh.vertices << 0, 3, 0.5,  //
                   0, 0, 2,    //
                   1, 1, 1;
  mesh.triangles = Eigen::Vector3i(0, 1, 2);
  constexpr int kCount = 40000;
  const PointSet points = c3po::SampleSurface(mesh, kCount, 4);
  int counts[4] = {0, 0, 0, 0};  // near a, near b, near c, middle
  for (int i = 0; i < kCount; ++i) {
    const Eigen::Vector3d w = Barycentric(points.col(i), mesh.vertices.col(0), mesh.vertices.col(1),
                                          mesh.vertices.col(2));
    REQUIRE(w.minCoeff() > -1e-9);
    int region = 3;
    for (int k = 0; k < 3; ++k) {
      if (w(k) > 0.5) region = k;
    }
    ++counts[region];
  }
  const double sigma = std::sqrt(0.25 * 0.75 / kCount);
  for (int r = 0; r < 4; ++r) {
    CAPTURE(r);
    CHECK(std::abs(counts[r] / static_cast<double>(kCount) - 0.25) < 5 * sigma);
  }
}

TEST_CASE("ClosestPointOnTriangle matches a dense barycentric grid") {
  c3po::Rng rng(42);
  constexpr int kGrid = 300;
  for (int trial = 0; trial < 60; ++trial) {
    Eigen::Vector3d a = rng.UnitVector(), b = rng.UnitVector(), c = rng.UnitVector();
    if (trial % 3 == 1) c = a + 0.5 * (b - a) + 0.02 * rng.UnitVector();  // thin / obtuse
    const double h = ((b - a).norm() + (c - a).norm()) / kGrid;  // max distance to the grid
    for (int q = 0; q < 15; ++q) {
      Eigen::Vector3d p = 1.5 * rng.UnitVector() * rng.Uniform();
      if (q % 5 == 0) {  // in the triangle's plane
        const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
        p -= n * n.dot(p - a);
      }
      double brute = std::numeric_limits<double>::infinity();
      for (int i = 0; i <= kGrid; ++i) {
        for (int j = 0; i + j <= kGrid; ++j) {
          const Eigen::Vector3d g = a + (b - a) * (double(i) / kGrid) + (c - a) * (double(j) / kGrid);
          brute = std::min(brute, (g - p).norm());
        }
      }
      const Eigen::Vector3d closest = c3po::ClosestPointOnTriangle(p, a, b, c);
      const double d = (closest - p).norm();
      CHECK(d <= brute + 1e-12);
      CHECK(brute - d <= h + 1e-12);
      const Eigen::Vector3d w = Barycentric(closest, a, b, c);
      CHECK(w.minCoeff() > -1e-9);
      CHECK((a * w(0) + b * w(1) + c * w(2) - closest).norm() < 1e-9);
    }
  }
}

TEST_CASE("ClosestPointOnTriangle on degenerate triangles is finite and on the segment") {
  c3po::Rng rng(43);
  const Eigen::Vector3d a(0, 0, 0), b(2, 0, 0), mid(1, 0, 0);
  for (int q = 0; q < 200; ++q) {
    const Eigen::Vector3d p = 3 * rng.UnitVector();
    const double t = std::clamp(p.x() / 2.0, 0.0, 1.0);
    const double segment_distance = (p - a - t * (b - a)).norm();
    for (const auto& tri : {std::array<Eigen::Vector3d, 3>{a, b, mid}, {a, mid, b}, {a, a, b}, {mid, mid, mid}}) {
      const Eigen::Vector3d closest = c3po::ClosestPointOnTriangle(p, tri[0], tri[1], tri[2]);
      REQUIRE(closest.allFinite());
      CHECK(std::abs(closest.y()) + std::abs(closest.z()) < 1e-12);
      if (tri[0] != tri[2]) CHECK((closest - p).norm() == doctest::Approx(segment_distance).epsilon(1e-9));
    }
  }
}

TEST_CASE("ClosestSurfacePoint of a box equals the analytic distance") {
  const Mesh box = BoxMesh();
  const Eigen::AlignedBox3d bounds(kLo, kLo + kSize);
  c3po::Rng rng(44);
  for (int q = 0; q < 500; ++q) {
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) p(k) = rng.Uniform(kLo(k) - 1.5, kLo(k) + kSize(k) + 1.5);
    double expected;
    if (bounds.contains(p)) {  // inside: distance to the nearest face plane
      expected = std::min((p - bounds.min()).minCoeff(), (bounds.max() - p).minCoeff());
    } else {
      expected = (p - p.cwiseMax(bounds.min()).cwiseMin(bounds.max())).norm();
    }
    const auto surface = c3po::ClosestSurfacePoint(box, p);
    CHECK(surface.distance == doctest::Approx(expected).epsilon(1e-12).scale(1));
    CHECK((surface.point - p).norm() == doctest::Approx(surface.distance).epsilon(1e-12).scale(1));
    REQUIRE(surface.triangle >= 0);
    REQUIRE(surface.triangle < 12);
  }
  const auto none = c3po::ClosestSurfacePoint(Mesh(), Eigen::Vector3d::Zero());
  CHECK(none.triangle == -1);
  CHECK(std::isinf(none.distance));
}

TEST_CASE("several meshes in one file are merged with correct vertex offsets") {
  // Two boxes as separate OBJ objects with different materials: assimp returns
  // two meshes whose indices must be shifted when merged.
  c3po::test::TempDir dir("mesh_merge");
  std::ostringstream out;
  const Eigen::Vector3d shift(10, 0, 0);
  for (int copy = 0; copy < 2; ++copy) {
    out << "o box" << copy << "\nusemtl material" << copy << '\n';
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d v = Corner(i) + copy * shift;
      out << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
    }
    for (const auto& q : kQuads) {
      out << "f";
      for (int k = 0; k < 4; ++k) out << ' ' << q[k] + 1 + 8 * copy;
      out << '\n';
    }
  }
  WriteText(dir / "two_boxes.obj", out.str());
  const Mesh mesh = c3po::LoadMesh(dir / "two_boxes.obj");
  CHECK(mesh.triangles.cols() == 24);
  CHECK(mesh.SurfaceArea() == doctest::Approx(2 * kBoxArea));
  CHECK((mesh.BoundingBox().min() - kLo).norm() < 1e-9);
  CHECK((mesh.BoundingBox().max() - (kLo + kSize + shift)).norm() < 1e-9);
  // Every triangle is a face of one of the two boxes: its vertices share one
  // coordinate that lies on a face plane of that box.
  int on_second_box = 0;
  for (int t = 0; t < 24; ++t) {
    Eigen::Matrix3d corners;
    for (int k = 0; k < 3; ++k) corners.col(k) = mesh.vertices.col(mesh.triangles(k, t));
    const Eigen::Vector3d local = corners.col(0) - (corners(0, 0) > 5 ? shift : Eigen::Vector3d::Zero());
    CHECK((corners.rowwise().maxCoeff() - corners.rowwise().minCoeff()).minCoeff() == 0.0);
    CHECK(((local - kLo).cwiseAbs().minCoeff() < 1e-12 || (local - kLo - kSize).cwiseAbs().minCoeff() < 1e-12));
    on_second_box += corners.row(0).minCoeff() > 5 ? 1 : 0;
    CHECK((corners.row(0).minCoeff() > 5) == (corners.row(0).maxCoeff() > 5));  // not spanning both
  }
  CHECK(on_second_box == 12);
}

TEST_CASE("zero-area triangles are never sampled") {
  Mesh mesh = BoxMesh();
  const int proper = static_cast<int>(mesh.triangles.cols());
  mesh.triangles.conservativeResize(3, proper + 3);
  mesh.triangles.col(proper) = Eigen::Vector3i(0, 0, 1);      // two equal corners
  mesh.triangles.col(proper + 1) = Eigen::Vector3i(3, 3, 3);  // a point
  mesh.triangles.col(proper + 2) = Eigen::Vector3i(0, 1, 1);  // last in the area table
  CHECK(mesh.SurfaceArea() == doctest::Approx(kBoxArea));
  const auto sample = c3po::SampleSurfaceWithTriangles(mesh, 20000, 11);
  CHECK(sample.triangle.maxCoeff() < proper);
  CHECK(sample.points.allFinite());
}

TEST_CASE("Pose composition, inverse and application agree") {
  c3po::Rng rng(45);
  for (int trial = 0; trial < 50; ++trial) {
    c3po::Pose a, b;
    a.R = rng.Rotation();
    b.R = rng.Rotation();
    a.t = rng.UnitVector() * rng.Uniform(0, 3);
    b.t = rng.UnitVector() * rng.Uniform(0, 3);
    PointSet points(3, 10);
    for (int i = 0; i < 10; ++i) points.col(i) = rng.UnitVector() * rng.Uniform(0, 2);
    CHECK(((a * b) * points - a * (b * points)).norm() < 1e-12);
    CHECK((a.Inverse() * (a * points) - points).norm() < 1e-12);
    CHECK((a.InverseApply(points) - a.Inverse() * points).norm() < 1e-12);
    const c3po::Pose identity = a * a.Inverse();
    CHECK((identity.R - Eigen::Matrix3d::Identity()).norm() < 1e-12);
    CHECK(identity.t.norm() < 1e-12);
    const Eigen::Vector3d x = points.col(3);
    CHECK((a * x - (a.R * x + a.t)).norm() < 1e-15);
  }
  c3po::Pose bad;
  bad.t(1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(bad.IsFinite());
  CHECK(c3po::Pose::Identity().IsFinite());
}
