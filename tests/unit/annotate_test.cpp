// c3po annotate: snapping against an analytic box, automatic keypoints, imports,
// editing with indicator-set remapping, the HTML page, and the CLI end to end.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "c3po/authoring/annotate.hpp"
#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/io/mesh_io.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/web/annotation_page.hpp"
#include "test_helpers.hpp"

namespace {

using c3po::Mesh;
using c3po::PointSet;
using nlohmann::json;

// Axis-aligned box [0, size] with outward triangles (12 of them).
Mesh MakeBox(const Eigen::Vector3d& size) {
  Mesh mesh;
  mesh.vertices.resize(3, 8);
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.col(i) << (i & 1 ? size.x() : 0.0), (i & 2 ? size.y() : 0.0), (i & 4 ? size.z() : 0.0);
  }
  const int faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                            {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  mesh.triangles.resize(3, 12);
  for (int t = 0; t < 12; ++t) mesh.triangles.col(t) << faces[t][0], faces[t][1], faces[t][2];
  return mesh;
}

// Exact distance from p to the surface of the box [0, size] (inside or out).
double BoxSurfaceDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& size) {
  const Eigen::Vector3d half = size / 2;
  const Eigen::Vector3d q = (p - half).cwiseAbs() - half;
  if ((q.array() > 0).any()) return q.cwiseMax(0.0).norm();
  return -q.maxCoeff();
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

void WriteBoxObj(const std::string& path, const Eigen::Vector3d& size) {
  c3po::WriteObj(MakeBox(size), path);
}

c3po::ObjectSpec SpecWith(int count, const std::vector<std::vector<int>>& sets) {
  c3po::ObjectSpec spec;
  spec.name = "thing";
  spec.mesh_path = "/nonexistent/thing.obj";
  spec.keypoints = PointSet::Random(3, count);
  for (int i = 0; i < count; ++i) spec.keypoint_names.push_back("n" + std::to_string(i));
  spec.indicator_sets = sets;
  spec.eps_oc = 0.01;
  spec.delta_nd = 0.01;
  return spec;
}

}  // namespace

TEST_CASE("snapping equals the exact distance to an analytic box and projects face points orthogonally") {
  const Eigen::Vector3d size(0.3, 0.2, 0.1);
  const Mesh box = MakeBox(size);
  c3po::Rng rng(7);
  PointSet points(3, 300);
  for (int i = 0; i < points.cols(); ++i) {
    points.col(i) << rng.Uniform(-0.1, 0.4), rng.Uniform(-0.1, 0.3), rng.Uniform(-0.1, 0.2);
  }
  const auto snaps = c3po::SnapToSurface(box, points);
  REQUIRE(snaps.size() == 300);
  for (int i = 0; i < points.cols(); ++i) {
    CHECK(snaps[i].distance == doctest::Approx(BoxSurfaceDistance(points.col(i), size)).epsilon(1e-9));
    CHECK(BoxSurfaceDistance(snaps[i].point, size) < 1e-12);
    CHECK((snaps[i].point - points.col(i)).norm() == doctest::Approx(snaps[i].distance).epsilon(1e-9));
  }
  // A point above the top face (within its extent) snaps to its orthogonal projection.
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d p(rng.Uniform(0, 0.3), rng.Uniform(0, 0.2), 0.1 + rng.Uniform(0.001, 0.05));
    const c3po::SnapResult snap = c3po::SnapToSurface(box, p)[0];
    CHECK((snap.point - Eigen::Vector3d(p.x(), p.y(), 0.1)).norm() < 1e-12);
    CHECK(snap.distance == doctest::Approx(p.z() - 0.1));
  }
  // Degenerate: nothing to snap.
  CHECK(c3po::SnapToSurface(box, PointSet(3, 0)).empty());
}

TEST_CASE("surface variation is zero on a plane and largest at a box corner") {
  c3po::Rng rng(1);
  PointSet plane(3, 500);
  for (int i = 0; i < 500; ++i) plane.col(i) << rng.Uniform(), rng.Uniform(), 0.0;
  for (double v : c3po::SurfaceVariation(plane, 16)) CHECK(v < 1e-12);

  const Mesh box = MakeBox(Eigen::Vector3d(1, 1, 1));
  const PointSet sample = c3po::SampleSurface(box, 6000, 3);
  const std::vector<double> variation = c3po::SurfaceVariation(sample, 32);
  // Mean variation near corners (within 0.05) beats that of face interiors.
  double corner = 0, face = 0;
  int corners = 0, faces = 0;
  for (int i = 0; i < sample.cols(); ++i) {
    const Eigen::Vector3d p = sample.col(i);
    const Eigen::Vector3d to_edge = p.cwiseMin(Eigen::Vector3d::Ones() - p);
    std::array<double, 3> sorted = {to_edge.x(), to_edge.y(), to_edge.z()};
    std::sort(sorted.begin(), sorted.end());   // sorted[0] == 0 on the surface
    if (sorted[2] < 0.05) { corner += variation[i]; ++corners; }
    if (sorted[1] > 0.3) { face += variation[i]; ++faces; }
  }
  REQUIRE(corners > 0);
  REQUIRE(faces > 0);
  CHECK(corner / corners > 5 * (face / faces + 1e-6));
}

TEST_CASE("--auto keypoints lie on the surface, are distinct, spread out and deterministic") {
  const Eigen::Vector3d size(0.4, 0.2, 0.1);
  const Mesh box = MakeBox(size);
  c3po::AutoKeypointOptions options;
  options.count = 6;
  options.sample_size = 4000;
  options.seed = 11;
  const c3po::AutoKeypoints a = c3po::ProposeKeypoints(box, options);
  REQUIRE(a.points.cols() == 6);
  for (int k = 0; k < 6; ++k) {
    CHECK(BoxSurfaceDistance(a.points.col(k), size) < 1e-12);
    CHECK(a.triangle[k] >= 0);
  }
  double min_separation = 1e9;
  for (int i = 0; i < 6; ++i) {
    for (int j = i + 1; j < 6; ++j) min_separation = std::min(min_separation, (a.points.col(i) - a.points.col(j)).norm());
  }
  CHECK(min_separation == doctest::Approx(a.min_separation));
  CHECK(min_separation > 0.02 * size.norm());

  const c3po::AutoKeypoints again = c3po::ProposeKeypoints(box, options);
  CHECK(again.points == a.points);
  options.seed = 12;
  const c3po::AutoKeypoints other = c3po::ProposeKeypoints(box, options);
  CHECK(other.points != a.points);

  // Two keypoints on a long bar go to its two ends (farthest-point sampling).
  const Eigen::Vector3d bar(1.0, 0.1, 0.1);
  options.count = 2;
  const c3po::AutoKeypoints ends = c3po::ProposeKeypoints(MakeBox(bar), options);
  CHECK(std::abs(ends.points(0, 0) - ends.points(0, 1)) > 0.9);

  // New keypoints keep away from existing ones.
  PointSet existing(3, 1);
  existing.col(0) = Eigen::Vector3d(0, 0, 0);
  options.count = 1;
  const c3po::AutoKeypoints away = c3po::ProposeKeypoints(MakeBox(bar), options, existing);
  CHECK(away.points(0, 0) > 0.9);

  options.count = 0;
  CHECK_THROWS_AS(c3po::ProposeKeypoints(box, options), std::invalid_argument);
}

TEST_CASE("X,Y,Z parsing accepts three finite numbers only") {
  CHECK(c3po::ParsePointText("1,-2.5, 3e-2", "--keypoint").isApprox(Eigen::Vector3d(1, -2.5, 0.03)));
  for (const char* bad : {"", "1,2", "1,2,3,4", "a,b,c", "1,,3", "1,2,3x", "nan,0,0", "1,2,", "1;2;3"}) {
    CAPTURE(bad);
    CHECK_THROWS_AS(c3po::ParsePointText(bad, "--keypoint"), c3po::InputError);
  }
}

TEST_CASE("JSON point lists round-trip") {
  c3po::test::TempDir dir("annotate_json");
  c3po::Rng rng(3);
  PointSet points(3, 5);
  for (int i = 0; i < 5; ++i) points.col(i) = rng.UnitVector();
  json list = json::array();
  for (int i = 0; i < 5; ++i) list.push_back({points(0, i), points(1, i), points(2, i)});
  WriteText(dir / "nested.json", json{{"keypoints", {{"fps", list}, {"origin", {1.0, 2.0, 3.0}}}}}.dump());
  WriteText(dir / "flat.json", json{{"fps", list}}.dump());

  CHECK(c3po::ReadPointListJson(dir / "nested.json", "fps") == points);
  CHECK(c3po::ReadPointListJson(dir / "flat.json", "fps") == points);
  const PointSet origin = c3po::ReadPointListJson(dir / "nested.json", "origin");
  REQUIRE(origin.cols() == 1);
  CHECK(origin.col(0) == Eigen::Vector3d(1, 2, 3));

  try {
    c3po::ReadPointListJson(dir / "nested.json", "missing");
    FAIL("expected an InputError");
  } catch (const c3po::InputError& e) {
    CHECK(std::string(e.what()).find("fps, origin") != std::string::npos);
  }
  WriteText(dir / "bad.json", R"({"fps": [[1, 2, "x"]]})");
  CHECK_THROWS_AS(c3po::ReadPointListJson(dir / "bad.json", "fps"), c3po::InputError);
  WriteText(dir / "truncated.json", R"({"fps": [[1, 2)");
  CHECK_THROWS_AS(c3po::ReadPointListJson(dir / "truncated.json", "fps"), c3po::InputError);
  CHECK_THROWS_AS(c3po::ReadPointListJson(dir / "absent.json", "fps"), c3po::InputError);
}

TEST_CASE("KeypointNet import picks the model and names keypoints by semantic id") {
  c3po::test::TempDir dir("annotate_kpnet");
  json doc = json::array();
  doc.push_back({{"class_id", "03001627"}, {"model_id", "aaa"},
                 {"keypoints", {{{"xyz", {0.1, 0.2, 0.3}}, {"semantic_id", 4}, {"pcd_info", {{"point_index", 7}}}}}}});
  doc.push_back({{"class_id", "03001627"}, {"model_id", "bbb"},
                 {"keypoints", {{{"xyz", {1, 2, 3}}, {"semantic_id", 0}}, {{"xyz", {-1, -2, -3}}, {"semantic_id", 2}}}}});
  WriteText(dir / "chair.json", doc.dump());
  const c3po::KeypointNetModel model = c3po::ReadKeypointNet(dir / "chair.json", "bbb");
  REQUIRE(model.points.cols() == 2);
  CHECK(model.points.col(1) == Eigen::Vector3d(-1, -2, -3));
  CHECK(model.Names() == std::vector<std::string>{"semantic0", "semantic2"});
  CHECK(model.class_id == "03001627");
  try {
    c3po::ReadKeypointNet(dir / "chair.json", "zzz");
    FAIL("expected an InputError");
  } catch (const c3po::InputError& e) {
    CHECK(std::string(e.what()).find("model id 'zzz' not found") != std::string::npos);
  }
}

TEST_CASE("removing keypoints remaps indicator sets to the same points") {
  c3po::Rng rng(5);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 4 + rng.UniformInt(8);
    std::vector<std::vector<int>> sets;
    for (int s = 0; s < 4; ++s) {
      std::set<int> members;
      for (int k = 0; k < 1 + rng.UniformInt(3); ++k) members.insert(rng.UniformInt(n));
      sets.emplace_back(members.begin(), members.end());
    }
    const c3po::ObjectSpec spec = SpecWith(n, sets);
    std::vector<int> remove = {rng.UniformInt(n), rng.UniformInt(n)};
    const std::set<int> removed(remove.begin(), remove.end());
    std::vector<std::vector<int>> hit;
    for (const auto& set : sets) {
      if (std::any_of(set.begin(), set.end(), [&](int i) { return removed.count(i) > 0; })) hit.push_back(set);
    }
    if (!hit.empty()) CHECK_THROWS_AS(c3po::RemoveKeypoints(spec, remove, false, "x.json"), c3po::InputError);
    const c3po::KeypointRemoval result = c3po::RemoveKeypoints(spec, remove, true, "x.json");
    CHECK(result.spec.num_keypoints() == n - static_cast<int>(removed.size()));
    CHECK(result.dropped_sets == hit);
    CHECK(result.spec.indicator_sets.size() + hit.size() == sets.size());
    // Oracle: every remapped set names the same points and names as before.
    std::size_t kept_set = 0;
    for (const auto& set : sets) {
      if (std::find(hit.begin(), hit.end(), set) != hit.end()) continue;
      const auto& now = result.spec.indicator_sets.at(kept_set++);
      REQUIRE(now.size() == set.size());
      for (std::size_t k = 0; k < set.size(); ++k) {
        CHECK(result.spec.keypoints.col(now[k]) == spec.keypoints.col(set[k]));
        CHECK(result.spec.keypoint_names[now[k]] == spec.keypoint_names[set[k]]);
      }
    }
    result.spec.Validate("after removal");
  }
  CHECK_THROWS_AS(c3po::RemoveKeypoints(SpecWith(3, {}), {3}, false, "x.json"), c3po::InputError);
  CHECK_THROWS_AS(c3po::RemoveKeypoints(SpecWith(3, {}), {-1}, false, "x.json"), c3po::InputError);
}

TEST_CASE("AnnotateObject snaps, refuses far points, keeps them with no-snap, and names auto keypoints") {
  const Eigen::Vector3d size(0.2, 0.2, 0.2);
  const Mesh box = MakeBox(size);
  c3po::ObjectSpec base = SpecWith(0, {});
  base.keypoint_names.clear();
  c3po::KeypointSource near{"--keypoint", PointSet(3, 2), {"a", ""}};
  near.points.col(0) << 0.1, 0.1, 0.205;
  near.points.col(1) << 0.1, -0.003, 0.1;
  c3po::AnnotationOptions options;
  options.max_snap_distance = 0.01;
  options.auto_count = 2;
  options.auto_options.sample_size = 2000;
  const c3po::AnnotationResult result = c3po::AnnotateObject(box, base, {near}, options, "box.obj");
  REQUIRE(result.spec.num_keypoints() == 4);
  CHECK((result.spec.keypoints.col(0) - Eigen::Vector3d(0.1, 0.1, 0.2)).norm() < 1e-12);
  CHECK(result.added[0].snap.distance == doctest::Approx(0.005));
  CHECK(result.added[1].snap.distance == doctest::Approx(0.003));
  CHECK(result.spec.KeypointName(0) == "a");
  CHECK(result.spec.KeypointName(1) == "kp1");
  CHECK(result.spec.KeypointName(2) == "auto0");
  CHECK(result.spec.KeypointName(3) == "auto1");

  c3po::KeypointSource far{"far.json", PointSet(3, 1), {}};
  far.points.col(0) << 0.1, 0.1, 0.3;
  CHECK_THROWS_AS(c3po::AnnotateObject(box, base, {far}, options, "box.obj"), c3po::InputError);
  options.snap = false;
  options.auto_count = 0;
  const c3po::AnnotationResult kept = c3po::AnnotateObject(box, base, {far}, options, "box.obj");
  CHECK(kept.spec.keypoints.col(0) == far.points.col(0));
  CHECK(kept.added[0].snap.distance == doctest::Approx(0.1));
}

TEST_CASE("the HTML page embeds three.js and the mesh, and escapes script endings") {
  const Mesh box = MakeBox(Eigen::Vector3d(0.3, 0.2, 0.1));
  c3po::ObjectSpec spec = SpecWith(3, {{0, 2}});
  spec.name = "odd</script><b>";
  spec.mesh_path = "/data/meshes/box.obj";
  const std::string html = c3po::AnnotationPageHtml(spec, box, "/data/objects/box.json");
  CHECK(html.find("Copyright 2010-") != std::string::npos);        // three.js licence header
  CHECK(html.find("SPDX-License-Identifier: MIT") != std::string::npos);
  CHECK(html.find("odd</script>") == std::string::npos);
  CHECK(html.find("<script src") == std::string::npos);   // nothing loaded from outside
  // Pull the data element back out and check it against the inputs.
  const std::string open = "<script type=\"application/json\" id=\"c3po-data\">";
  const std::size_t begin = html.find(open) + open.size();
  const json data = json::parse(html.substr(begin, html.find("</script>", begin) - begin));
  CHECK(data["object"]["name"] == spec.name);
  CHECK(data["object"]["mesh"] == "../meshes/box.obj");
  CHECK(data["object"]["keypoints"].size() == 3);
  CHECK(data["object"]["indicator_sets"] == json::parse("[[0,2]]"));
  CHECK(data["triangle_count"] == 12);
  CHECK(data["vertices_f32"].get<std::string>().size() == 4 * ((8 * 3 * 4 + 2) / 3));
  CHECK(data["diameter"].get<double>() == doctest::Approx(box.Diameter()));
}

TEST_CASE("c3po annotate writes an object that round-trips, and --edit remaps sets") {
  c3po::test::TempDir dir("annotate_cli");
  const Eigen::Vector3d size(0.2, 0.1, 0.05);
  WriteBoxObj(dir / "box.obj", size);
  const auto run = c3po::test::RunC3po(
      "annotate " + dir / "box.obj" + " -o " + dir / "box.json" +
      " --keypoint 0.1,0.05,0.06 --name top --keypoint=-0.002,0.05,0.02 --auto 3 --seed 2 --html " +
      dir / "view.html");
  INFO(run.output);
  REQUIRE(run.status == 0);
  CHECK(run.output.find("snapped 0.01 ") != std::string::npos);
  CHECK(run.output.find("snapped 0.002 ") != std::string::npos);
  const c3po::ObjectSpec spec = c3po::ReadObjectSpec(dir / "box.json");
  REQUIRE(spec.num_keypoints() == 5);
  CHECK(spec.name == "box");
  CHECK(spec.KeypointName(0) == "top");
  CHECK(spec.KeypointName(4) == "auto2");
  for (int i = 0; i < 5; ++i) CHECK(BoxSurfaceDistance(spec.keypoints.col(i), size) < 1e-6);   // float mesh
  CHECK(spec.eps_oc == doctest::Approx(0.03 * size.norm()));
  CHECK(spec.delta_nd == doctest::Approx(0.015 * size.norm()));
  CHECK(json::parse(c3po::ReadFileToString(dir / "box.json"))["mesh"] == "box.obj");
  CHECK(std::filesystem::file_size(dir / "view.html") > 300000);

  // Give it indicator sets, then remove keypoint 1 with and without --drop-sets.
  json doc = json::parse(c3po::ReadFileToString(dir / "box.json"));
  doc["indicator_sets"] = json::parse("[[0, 2], [1, 3], [4]]");
  c3po::WriteFileAtomically(dir / "box.json", doc.dump());
  const auto refused = c3po::test::RunC3po("annotate --edit " + dir / "box.json" + " --remove 1 -o " + dir / "e.json");
  CHECK(refused.status == 2);
  CHECK(refused.output.find("--drop-sets") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir / "e.json"));
  const auto edited = c3po::test::RunC3po("annotate --edit " + dir / "box.json" +
                                          " --remove 1 --drop-sets --eps-oc 0.004 -o " + dir / "e.json");
  INFO(edited.output);
  REQUIRE(edited.status == 0);
  const c3po::ObjectSpec after = c3po::ReadObjectSpec(dir / "e.json");
  CHECK(after.num_keypoints() == 4);
  CHECK(after.indicator_sets == std::vector<std::vector<int>>{{0, 1}, {3}});
  CHECK(after.keypoints.col(1) == spec.keypoints.col(2));
  CHECK(after.eps_oc == doctest::Approx(0.004));
  CHECK(after.delta_nd == doctest::Approx(spec.delta_nd));
}

TEST_CASE("c3po annotate: bad input exits 2 with one line and writes nothing") {
  c3po::test::TempDir dir("annotate_bad");
  WriteBoxObj(dir / "box.obj", Eigen::Vector3d(0.2, 0.1, 0.05));
  WriteText(dir / "empty.obj", "# no faces\nv 0 0 0\nv 1 0 0\n");
  WriteText(dir / "kpnet.json", R"([{"class_id": "1", "model_id": "m1", "keypoints": [{"xyz": [0.1, 0.05, 0.05], "semantic_id": 3}]}])");
  const std::string out = " -o " + dir / "out.json";
  const std::vector<std::string> bad = {
      "annotate " + dir / "box.obj" + out + " --keypoint 0.1,abc,0",
      "annotate " + dir / "empty.obj" + out + " --keypoint 0,0,0",
      "annotate " + dir / "missing.obj" + out + " --keypoint 0,0,0",
      "annotate " + dir / "box.obj" + out + " --from-keypointnet " + dir / "kpnet.json" + " --model-id nope",
      "annotate " + dir / "box.obj" + out + " --from-json " + dir / "absent.json" + " --key k",
      "annotate " + dir / "box.obj" + out + " --keypoint 0.1,0.05,0.5",
      "annotate " + dir / "box.obj" + out,
      "annotate " + dir / "box.obj" + out + " --keypoint 0.1,0.05,0.05 --name a --name b",
      "annotate " + dir / "box.obj" + out + " --keypoint 0.1,0.05,0.05 --eps-oc 3%x",
  };
  for (const std::string& args : bad) {
    const auto result = c3po::test::RunC3po(args);
    INFO(args);
    INFO(result.output);
    CHECK(result.status == 2);
    CHECK_FALSE(std::filesystem::exists(dir / "out.json"));
  }
  const auto unknown = c3po::test::RunC3po(bad[3]);
  CHECK(unknown.output.find("model id 'nope' not found") != std::string::npos);
  const auto good = c3po::test::RunC3po("annotate " + dir / "box.obj" + out + " --from-keypointnet " +
                                        dir / "kpnet.json" + " --model-id m1");
  INFO(good.output);
  CHECK(good.status == 0);
  CHECK(c3po::ReadObjectSpec(dir / "out.json").KeypointName(0) == "semantic3");
}
