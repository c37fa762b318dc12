// The real YCB meshes in ../shared/data/ycb (skipped when absent): assimp's
// loading checked against a minimal OBJ reader written here, the diameter
// against the bounding box, the README's sizes, and the PVN3D keypoints
// against the surface.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "c3po/geometry/mesh.hpp"
#include "c3po/io/mesh_io.hpp"
#include "c3po/object/object_model.hpp"
#include "test_helpers.hpp"

namespace {

namespace fs = std::filesystem;

struct ObjCounts {
  Eigen::AlignedBox3d box;
  int faces = 0;
  int vertices = 0;
  int encoder_vertices = -1;   // the encoder's "# Vertices: N" comment
};

// Only "v x y z" and "f ..." lines: all a bounding box and a face count need.
ObjCounts ReadObjCounts(const std::string& path) {
  ObjCounts counts;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("# Vertices: ", 0) == 0) counts.encoder_vertices = std::stoi(line.substr(12));
    if (line.rfind("v ", 0) == 0) {
      ++counts.vertices;
      std::istringstream fields(line.substr(2));
      Eigen::Vector3d v;
      fields >> v.x() >> v.y() >> v.z();
      counts.box.extend(v);
    } else if (line.rfind("f ", 0) == 0) {
      ++counts.faces;
    }
  }
  return counts;
}

// README table rows: "| 003_cracker_box | box | 72 × 164 × 213 | ..." (mm).
std::map<std::string, Eigen::Vector3d> ReadmeSizes(const std::string& path) {
  std::map<std::string, Eigen::Vector3d> sizes;
  std::ifstream in(path);
  std::string line;
  const std::regex row(R"(^\|\s*(\S+)\s*\|[^|]*\|\s*([0-9.]+)\s*×\s*([0-9.]+)\s*×\s*([0-9.]+)\s*\|)");
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_search(line, m, row)) {
      sizes[m[1]] = Eigen::Vector3d(std::stod(m[2]), std::stod(m[3]), std::stod(m[4]));
    }
  }
  return sizes;
}

std::vector<std::string> ObjectFolders(const std::string& root) {
  std::vector<std::string> folders;
  for (const auto& entry : fs::directory_iterator(root)) {
    if (fs::exists(entry.path() / "textured.obj")) folders.push_back(entry.path().string());
  }
  std::sort(folders.begin(), folders.end());
  return folders;
}

}  // namespace

TEST_CASE("YCB meshes: load, sample, diameter, README sizes, keypoints on the surface") {
  if (!c3po::test::HaveSharedYcb()) {
    MESSAGE("skipped: " << c3po::test::SharedData() << "/ycb is absent");
    return;
  }
  const std::string root = c3po::test::SharedData() + "/ycb";
  const auto readme = ReadmeSizes(c3po::test::SharedData() + "/README.md");
  const auto folders = ObjectFolders(root);
  REQUIRE_FALSE(folders.empty());
  for (const std::string& folder : folders) {
    const std::string name = fs::path(folder).filename().string();
    CAPTURE(name);
    const std::string obj = folder + "/textured.obj";
    const ObjCounts counts = ReadObjCounts(obj);
    const c3po::Mesh mesh = c3po::LoadMesh(obj);

    // c3po's OBJ reader sees every face (all are triangles), every vertex the
    // encoder says it wrote (all are used), and the same extent in doubles.
    CHECK(mesh.triangles.cols() == counts.faces);
    CHECK(mesh.vertices.cols() == counts.vertices);
    CHECK(counts.vertices == counts.encoder_vertices);
    const Eigen::AlignedBox3d box = mesh.BoundingBox();
    CHECK((box.min() - counts.box.min()).cwiseAbs().maxCoeff() < 1e-15);
    CHECK((box.max() - counts.box.max()).cwiseAbs().maxCoeff() < 1e-15);

    c3po::ObjectSpec spec;
    spec.name = name;
    spec.mesh_path = obj;
    const c3po::ObjectModel model(spec, mesh, {5000, 1});
    CHECK(model.diameter() == doctest::Approx(box.diagonal().norm()).epsilon(1e-12));
    CHECK(model.diameter() == doctest::Approx(counts.box.diagonal().norm()).epsilon(1e-5));

    const auto size = readme.find(name);
    if (size == readme.end()) {
      FAIL_CHECK("no bounding-box row for " << name << " in the data README");
    } else {
      CHECK((1000.0 * counts.box.sizes() - size->second).cwiseAbs().maxCoeff() < 2.0);
    }

    // Samples lie on the surface, inside the bounding box.
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d p = model.sample().col(i * 25);
      CHECK(c3po::ClosestSurfacePoint(mesh, p).distance < 1e-9 * model.diameter());
      CHECK(box.exteriorDistance(p) < 1e-12);
    }

    // The PVN3D farthest-point keypoints sit on the surface (README: 0.1-0.5 mm).
    std::ifstream in(folder + "/keypoints.json");
    const nlohmann::json keypoints = nlohmann::json::parse(in);
    const auto& farthest8 = keypoints.at("keypoints").at("farthest8");
    REQUIRE(farthest8.size() == 8);
    for (const auto& k : farthest8) {
      const Eigen::Vector3d p(k.at(0).get<double>(), k.at(1).get<double>(), k.at(2).get<double>());
      CHECK(c3po::ClosestSurfacePoint(mesh, p).distance < 1e-3);
    }
  }
}
