// Object JSON files: round trip, unit scaling, malformed files (fixtures in
// tests/fixtures/objects/bad_*.json) and threshold parsing.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <tuple>
#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "c3po/base/error.hpp"
#include "c3po/base/json.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/io/mesh_io.hpp"
#include "c3po/object/object_io.hpp"
#include "test_helpers.hpp"

namespace {

namespace fs = std::filesystem;

std::string Fixture(const std::string& name) {
  return c3po::test::SourceDir() + "/tests/fixtures/objects/" + name;
}

// Runs `load` and expects an InputError whose one-line message names `file`
// and, when given, the offending field.
template <class Load>
void ExpectInputError(Load load, const std::string& file, const std::string& field) {
  CAPTURE(file);
  CAPTURE(field);
  try {
    load();
    FAIL_CHECK("accepted " << file);
  } catch (const c3po::InputError& e) {
    const std::string message = e.what();
    CAPTURE(message);
    CHECK(message.find(file) != std::string::npos);
    CHECK(message.find(field) != std::string::npos);
    CHECK(message.find('\n') == std::string::npos);
  }
}

}  // namespace

TEST_CASE("the fixture object loads with every field") {
  const c3po::ObjectSpec spec = c3po::ReadObjectSpec(Fixture("cube.json"));
  CHECK(spec.schema_version == 1);
  CHECK(spec.name == "cube");
  CHECK(fs::equivalent(spec.mesh_path, Fixture("cube.obj")));
  CHECK(fs::path(spec.mesh_path).is_absolute());
  CHECK(spec.units == "m");
  REQUIRE(spec.num_keypoints() == 8);
  for (int i = 0; i < 8; ++i) {  // corner i = (bit0, bit1, bit2), as written in the fixture
    CHECK(spec.keypoints.col(i) == Eigen::Vector3d(i & 1, (i >> 1) & 1, (i >> 2) & 1));
  }
  CHECK(spec.KeypointName(3) == "c110");
  CHECK(spec.indicator_sets == std::vector<std::vector<int>>{{0, 1, 2, 4}, {7, 6, 5, 3}});
  CHECK(spec.eps_oc == 0.05);
  CHECK(spec.delta_nd == 0.02);

  const c3po::ObjectModel model = c3po::LoadObject(Fixture("cube.json"), {500, 1});
  CHECK(model.diameter() == doctest::Approx(std::sqrt(3.0)));
  CHECK(model.sample().cols() == 500);
}

TEST_CASE("write/read round trip keeps every field") {
  c3po::test::TempDir dir("object_io_round_trip");
  c3po::ObjectSpec spec = c3po::ReadObjectSpec(Fixture("cube.json"));
  spec.keypoints(0, 2) = 0.1 + 1e-17 * 3;       // a value with a long decimal expansion
  spec.keypoints(1, 5) = 1.0 / 3.0;
  spec.keypoint_names[0] = "corner \"zero\" ü";  // quotes and UTF-8 survive
  spec.extra_json = R"({"indicator_precision":[0.5,1.0],"note":"auto"})";
  const std::string path = dir / "sub" + "/cube_copy.json";
  fs::create_directories(dir / "sub");
  c3po::WriteObjectSpec(spec, path);

  const c3po::ObjectSpec back = c3po::ReadObjectSpec(path);
  CHECK(back.schema_version == spec.schema_version);
  CHECK(back.name == spec.name);
  CHECK(fs::equivalent(back.mesh_path, spec.mesh_path));
  CHECK(back.units == spec.units);
  CHECK(back.keypoints == spec.keypoints);  // bit-exact
  CHECK(back.keypoint_names == spec.keypoint_names);
  CHECK(back.indicator_sets == spec.indicator_sets);
  CHECK(back.eps_oc == spec.eps_oc);
  CHECK(back.delta_nd == spec.delta_nd);
  CHECK(nlohmann::json::parse(back.extra_json) == nlohmann::json::parse(spec.extra_json));

  // The mesh path is stored relative to the JSON file's folder.
  std::ifstream in(path);
  const fs::path written = nlohmann::json::parse(in).at("mesh").get<std::string>();
  CHECK(written.is_relative());
  CHECK(fs::equivalent(fs::path(path).parent_path() / written, spec.mesh_path));

  // An invalid spec is refused before anything is written.
  c3po::ObjectSpec invalid = spec;
  invalid.indicator_sets = {{0, 99}};
  CHECK_THROWS_AS(c3po::WriteObjectSpec(invalid, dir / "invalid.json"), c3po::InputError);
  CHECK_FALSE(fs::exists(dir / "invalid.json"));
}

TEST_CASE("mesh units scale the mesh into metres") {
  c3po::test::TempDir dir("object_io_units");
  const c3po::Mesh cube = c3po::LoadMesh(Fixture("cube.obj"));
  for (const auto& [units, side] : std::vector<std::pair<std::string, double>>{{"m", 1.0}, {"cm", 100.0}, {"mm", 1000.0}}) {
    const std::string& unit_name = units;  // CAPTURE's lambda may not name a structured binding (C++17)
    CAPTURE(unit_name);
    c3po::Mesh scaled = cube;
    scaled.vertices *= side;
    c3po::WriteObj(scaled, dir / ("cube_" + units + ".obj"));
    c3po::ObjectSpec spec = c3po::ReadObjectSpec(Fixture("cube.json"));
    spec.units = units;
    spec.mesh_path = fs::absolute(dir / ("cube_" + units + ".obj")).string();
    c3po::WriteObjectSpec(spec, dir / ("cube_" + units + ".json"));
    const c3po::ObjectModel model = c3po::LoadObject(dir / ("cube_" + units + ".json"), {200, 1});
    CHECK(model.diameter() == doctest::Approx(std::sqrt(3.0)).epsilon(1e-9));
    CHECK(model.mesh().SurfaceArea() == doctest::Approx(6.0).epsilon(1e-9));
  }
}

TEST_CASE("malformed object files: InputError naming the file and the field") {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"bad_missing_schema_version.json", "schema_version"},
      {"bad_missing_name.json", "name"},
      {"bad_missing_mesh.json", "mesh"},
      {"bad_missing_keypoints.json", "keypoints"},
      {"bad_missing_eps_oc.json", "eps_oc"},
      {"bad_missing_delta_nd.json", "delta_nd"},
      {"bad_schema_version_2.json", "schema_version"},
      // A float where an integer belongs is refused, not converted (1e300 to
      // int is undefined behaviour; a fuzzer found it).
      {"bad_schema_version_huge_float.json", "schema_version"},
      {"bad_schema_version_fraction.json", "schema_version"},
      {"bad_name_not_string.json", "name"},
      {"bad_name_empty.json", "name"},
      {"bad_mesh_not_string.json", "mesh"},
      {"bad_mesh_empty.json", "mesh"},
      {"bad_units_inch.json", "units"},
      {"bad_keypoints_not_list.json", "keypoints"},
      {"bad_keypoints_empty.json", "keypoints"},
      {"bad_keypoint_two_coords.json", "keypoints[1]"},
      {"bad_keypoint_nan_string.json", "keypoints[0]"},
      {"bad_keypoint_null.json", "keypoints[0]"},
      {"bad_keypoint_names_mismatch.json", "keypoint_names"},
      {"bad_keypoint_names_not_strings.json", "keypoint_names"},
      {"bad_indicator_out_of_range.json", "indicator_sets"},
      {"bad_indicator_negative.json", "indicator_sets"},
      {"bad_indicator_duplicate.json", "indicator_sets"},
      {"bad_indicator_empty_set.json", "indicator_sets"},
      {"bad_indicator_not_integer.json", "indicator_sets"},
      {"bad_indicator_huge.json", "indicator_sets"},
      {"bad_indicator_min_int64.json", "indicator_sets"},
      {"bad_indicator_max_uint64.json", "indicator_sets"},
      {"bad_indicator_string.json", "indicator_sets"},
      {"bad_eps_oc_negative.json", "eps_oc"},
      {"bad_eps_oc_string.json", "eps_oc"},
      {"bad_delta_nd_zero.json", "delta_nd"},
      // Not JSON at all: the message names the file.
      {"bad_not_json.json", ""},
      {"bad_empty_file.json", ""},
      {"bad_top_level_array.json", ""},
      {"bad_nan_literal.json", ""},
      {"bad_keypoint_overflow.json", ""},
      {"no_such_file.json", ""},
  };
  for (const auto& [name, field] : cases) {
    const std::string path = Fixture(name);
    ExpectInputError([&] { c3po::ReadObjectSpec(path); }, path, field);
    ExpectInputError([&] { c3po::LoadObject(path); }, path, field);
  }
}

TEST_CASE("a valid object whose mesh is missing or has no triangles") {
  const std::string missing = Fixture("bad_mesh_file_missing.json");
  CHECK_NOTHROW(c3po::ReadObjectSpec(missing));  // the JSON itself is fine
  ExpectInputError([&] { c3po::LoadObject(missing); }, missing, "mesh");
  const std::string no_triangles = Fixture("bad_mesh_without_triangles.json");
  ExpectInputError([&] { c3po::LoadObject(no_triangles); }, "only_vertices.obj", "mesh");
}

TEST_CASE("ParseThreshold: absolute, percent of the diameter, mm, cm") {
  const double d = 2.0;
  CHECK(c3po::ParseThreshold("0.01", d, "--eps-oc") == doctest::Approx(0.01));
  CHECK(c3po::ParseThreshold("1e-3", d, "--eps-oc") == doctest::Approx(0.001));
  CHECK(c3po::ParseThreshold("0.5m", d, "--eps-oc") == doctest::Approx(0.5));
  CHECK(c3po::ParseThreshold("3%d", d, "--eps-oc") == doctest::Approx(0.03 * d));
  CHECK(c3po::ParseThreshold("2.5%d", 0.4, "--eps-oc") == doctest::Approx(0.025 * 0.4));
  CHECK(c3po::ParseThreshold("5mm", d, "--eps-oc") == doctest::Approx(0.005));
  CHECK(c3po::ParseThreshold("1cm", d, "--eps-oc") == doctest::Approx(0.01));
  for (const char* bad : {"abc", "-1", "0", "0%d", "3%x", "3%", "%d", "", "nan", "inf", "1e400", "5 mm", "5mmm", "-2cm"}) {
    CAPTURE(bad);
    ExpectInputError([&] { c3po::ParseThreshold(bad, d, "--delta-nd"); }, "--delta-nd", "");
  }
  // A percentage needs a positive diameter.
  ExpectInputError([&] { c3po::ParseThreshold("3%d", 0.0, "--eps-oc"); }, "--eps-oc", "");
}

TEST_CASE("the CLI turns malformed object and mesh files into exit status 2 and one line") {
  c3po::test::TempDir dir("object_io_cli");
  // (command, file the message must name, field it must name)
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"indicators " + Fixture("bad_indicator_out_of_range.json"), Fixture("bad_indicator_out_of_range.json"), "indicator_sets"},
      {"indicators " + Fixture("bad_keypoint_nan_string.json"), Fixture("bad_keypoint_nan_string.json"), "keypoints"},
      {"indicators " + Fixture("bad_not_json.json"), Fixture("bad_not_json.json"), ""},
      {"indicators " + Fixture("bad_keypoint_overflow.json"), Fixture("bad_keypoint_overflow.json"), ""},
      {"annotate " + Fixture("only_vertices.obj") + " --keypoint 0,0,0 -o " + dir / "out.json", Fixture("only_vertices.obj"), ""},
      {"annotate " + dir / "missing.obj" + " --keypoint 0,0,0 -o " + dir / "out.json", dir / "missing.obj", ""},
  };
  for (const auto& [args, file, field] : cases) {
    const std::string& command = args;  // CAPTURE's lambda may not name a structured binding (C++17)
    CAPTURE(command);
    const auto result = c3po::test::RunC3po(args);
    CAPTURE(result.output);
    CHECK(result.status == 2);
    CHECK(result.output.find(file) != std::string::npos);
    CHECK(result.output.find(field) != std::string::npos);
    CHECK(std::count(result.output.begin(), result.output.end(), '\n') == 1);
  }
  CHECK_FALSE(fs::exists(dir / "out.json"));  // nothing written on failure
}

TEST_CASE("IntegerInRange: JSON integers within the range pass, floats and values outside are refused") {
  using nlohmann::json;
  const auto read = [](const json& value, long long lo, long long hi) {
    return c3po::IntegerInRange(value, lo, hi, "file.json", "field");
  };
  CHECK(read(json(5), 0, 10) == 5);
  CHECK(read(json(-3), -5, 5) == -3);
  CHECK(read(json(10u), 0, 10) == 10);   // unsigned JSON integer at the upper bound
  CHECK(read(json(0u), 0, 10) == 0);
  CHECK(read(json::parse("-9223372036854775808"), std::numeric_limits<long long>::min(), 0) ==
        std::numeric_limits<long long>::min());
  for (const json& bad : {json(5.0), json(1e300), json(-1e300), json(0.5), json("5"), json(nullptr), json::array(),
                          json(11), json(-1), json(11u), json::parse("18446744073709551615"),
                          json::parse("-9223372036854775808")}) {
    CAPTURE(bad.dump());
    try {
      read(bad, 0, 10);
      FAIL_CHECK("accepted");
    } catch (const c3po::InputError& e) {
      const std::string message = e.what();
      CHECK(message.rfind("file.json: field: ", 0) == 0);
      CHECK(message.find('\n') == std::string::npos);
    }
  }
  // The message quotes at most 40 characters of the value.
  try {
    read(json(std::vector<int>(1000, 7)), 0, 10);
    FAIL_CHECK("accepted");
  } catch (const c3po::InputError& e) {
    CHECK(std::string(e.what()).size() < 150);
  }
}
