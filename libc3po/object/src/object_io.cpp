#include "c3po/io/mesh_io.hpp"
#include "c3po/object/object_io.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/json.hpp"

namespace c3po {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

double UnitScale(const std::string& units) {
  if (units == "mm") return 1e-3;
  if (units == "cm") return 1e-2;
  return 1.0;
}

PointSet ParsePointList(const json& value, const std::string& where, const std::string& field) {
  if (!value.is_array()) throw InputError(where, field + ": expected a list of [x, y, z]");
  PointSet points(3, static_cast<Eigen::Index>(value.size()));
  for (std::size_t i = 0; i < value.size(); ++i) {
    const json& p = value[i];
    if (!p.is_array() || p.size() != 3) {
      throw InputError(where, field + "[" + std::to_string(i) + "]: expected 3 coordinates");
    }
    for (int k = 0; k < 3; ++k) {
      if (!p[k].is_number()) {
        throw InputError(where, field + "[" + std::to_string(i) + "]: coordinate is not a number");
      }
      points(k, static_cast<Eigen::Index>(i)) = p[k].get<double>();
    }
  }
  if (!points.allFinite()) throw InputError(where, field + ": non-finite coordinate");
  return points;
}

template <class T>
T Required(const json& doc, const char* key, const std::string& where) {
  if (!doc.contains(key)) throw InputError(where, std::string(key) + ": missing");
  try {
    return doc.at(key).get<T>();
  } catch (const json::exception&) {
    throw InputError(where, std::string(key) + ": wrong type");
  }
}

// Indices must be JSON integers (1.5 or 1e20 must not be truncated silently);
// ObjectSpec::Validate checks the range against the keypoint count.
std::vector<std::vector<int>> ParseIndicatorSets(const json& value, const std::string& where) {
  const std::string field = "indicator_sets";
  if (!value.is_array()) throw InputError(where, field + ": expected a list of lists of keypoint indices");
  std::vector<std::vector<int>> sets;
  for (std::size_t s = 0; s < value.size(); ++s) {
    const std::string name = field + "[" + std::to_string(s) + "]";
    if (!value[s].is_array()) throw InputError(where, name + ": expected a list of keypoint indices");
    std::vector<int> set;
    for (const json& index : value[s]) {
      set.push_back(static_cast<int>(IntegerInRange(index, -1000000000LL, 1000000000LL, where, name + ": keypoint index")));
    }
    sets.push_back(std::move(set));
  }
  return sets;
}

json PointListJson(const PointSet& points) {
  return PointsToJson(points);
}

}  // namespace

ObjectSpec ReadObjectSpec(const std::string& path) {
  const std::string text = ReadFileToString(path);
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(path, std::string("not valid JSON (byte ") + std::to_string(e.byte) + ")");
  } catch (const json::exception& e) {  // e.g. out_of_range.406: a number like 1e400
    throw InputError(path, std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object()) throw InputError(path, "expected a JSON object");
  ObjectSpec spec;
  if (!doc.contains("schema_version")) throw InputError(path, "schema_version: missing");
  spec.schema_version = static_cast<int>(IntegerInRange(doc["schema_version"], 0, 1000000, path, "schema_version"));
  spec.name = Required<std::string>(doc, "name", path);
  const std::string mesh = Required<std::string>(doc, "mesh", path);
  if (mesh.empty()) throw InputError(path, "mesh: empty path");
  const fs::path mesh_path = fs::path(mesh).is_absolute()
                                 ? fs::path(mesh)
                                 : fs::absolute(path).parent_path() / mesh;
  spec.mesh_path = mesh_path.lexically_normal().string();
  if (doc.contains("units")) spec.units = Required<std::string>(doc, "units", path);
  if (!doc.contains("keypoints")) throw InputError(path, "keypoints: missing");
  spec.keypoints = ParsePointList(doc["keypoints"], path, "keypoints");
  if (doc.contains("keypoint_names")) {
    spec.keypoint_names = Required<std::vector<std::string>>(doc, "keypoint_names", path);
  }
  if (doc.contains("indicator_sets")) {
    spec.indicator_sets = ParseIndicatorSets(doc["indicator_sets"], path);
  }
  spec.eps_oc = Required<double>(doc, "eps_oc", path);
  spec.delta_nd = Required<double>(doc, "delta_nd", path);
  if (doc.contains("extra")) spec.extra_json = doc["extra"].dump();
  spec.Validate(path);
  return spec;
}

void WriteObjectSpec(const ObjectSpec& spec, const std::string& path) {
  spec.Validate(path);
  const fs::path json_dir = fs::absolute(path).parent_path();
  const fs::path mesh_relative = fs::path(spec.mesh_path).is_absolute()
                                     ? fs::relative(spec.mesh_path, json_dir)
                                     : fs::path(spec.mesh_path);
  json doc;
  doc["schema_version"] = spec.schema_version;
  doc["name"] = spec.name;
  doc["mesh"] = mesh_relative.generic_string();
  doc["units"] = spec.units;
  doc["keypoints"] = PointListJson(spec.keypoints);
  if (!spec.keypoint_names.empty()) doc["keypoint_names"] = spec.keypoint_names;
  doc["indicator_sets"] = spec.indicator_sets;
  doc["eps_oc"] = spec.eps_oc;
  doc["delta_nd"] = spec.delta_nd;
  if (!spec.extra_json.empty()) doc["extra"] = json::parse(spec.extra_json);
  WriteFileAtomically(path, doc.dump(2) + "\n");
}

ObjectModel LoadObject(const std::string& path, const ObjectModelOptions& options) {
  ObjectSpec spec = ReadObjectSpec(path);
  if (!fs::is_regular_file(spec.mesh_path)) {
    throw InputError(path, "mesh: file not found: " + spec.mesh_path);
  }
  Mesh mesh = LoadMesh(spec.mesh_path, UnitScale(spec.units));
  return ObjectModel(std::move(spec), std::move(mesh), options);
}

double ParseThreshold(const std::string& text, double diameter, const std::string& what) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double value = std::strtod(begin, &end);
  if (end == begin) throw InputError(what, "'" + text + "' is not a distance (e.g. 0.01 or 3%d)");
  const std::string suffix(end);
  double result = value;
  if (suffix == "%d") {
    result = value / 100.0 * diameter;
  } else if (suffix == "mm") {
    result = value * 1e-3;
  } else if (suffix == "cm") {
    result = value * 1e-2;
  } else if (!suffix.empty() && suffix != "m") {
    throw InputError(what, "'" + text + "': unknown suffix '" + suffix + "' (use 3%d, 5mm, 1cm or a number)");
  }
  if (!(std::isfinite(result) && result > 0)) {
    throw InputError(what, "'" + text + "' must be a positive distance");
  }
  return result;
}

}  // namespace c3po
