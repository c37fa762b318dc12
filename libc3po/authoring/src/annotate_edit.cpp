// Keypoint imports (JSON point lists, KeypointNet), "X,Y,Z" parsing and
// editing of an object's keypoint list with indicator-set remapping.
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <vector>

#include "c3po/authoring/annotate.hpp"
#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"

namespace c3po {
namespace {

using nlohmann::json;

json ParseJsonFile(const std::string& path) {
  const std::string text = ReadFileToString(path);
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(path, "not valid JSON (byte " + std::to_string(e.byte) + ")");
  } catch (const json::exception& e) {   // e.g. a number out of range (1e400)
    throw InputError(path, std::string("not valid JSON: ") + e.what());
  }
}

Eigen::Vector3d JsonPoint(const json& value, const std::string& path, const std::string& field) {
  if (!value.is_array() || value.size() != 3) {
    throw InputError(path, field + ": expected [x, y, z]");
  }
  Eigen::Vector3d p;
  for (int k = 0; k < 3; ++k) {
    if (!value[k].is_number()) throw InputError(path, field + ": coordinate is not a number");
    p(k) = value[k].get<double>();
  }
  if (!p.allFinite()) throw InputError(path, field + ": non-finite coordinate");
  return p;
}

bool IsSinglePoint(const json& value) {
  return value.is_array() && value.size() == 3 && value[0].is_number();
}

PointSet JsonPointList(const json& value, const std::string& path, const std::string& field) {
  if (IsSinglePoint(value)) return JsonPoint(value, path, field);
  if (!value.is_array()) throw InputError(path, field + ": expected a list of [x, y, z]");
  if (value.empty()) throw InputError(path, field + ": empty list");
  PointSet points(3, static_cast<Eigen::Index>(value.size()));
  for (std::size_t i = 0; i < value.size(); ++i) {
    points.col(static_cast<Eigen::Index>(i)) =
        JsonPoint(value[i], path, field + "[" + std::to_string(i) + "]");
  }
  return points;
}

std::string KeyList(const json& object) {
  std::string keys;
  for (const auto& item : object.items()) keys += (keys.empty() ? "" : ", ") + item.key();
  return keys.empty() ? "none" : keys;
}

std::string JsonIdText(const json& value) {
  return value.is_string() ? value.get<std::string>() : value.dump();
}

}  // namespace

Eigen::Vector3d ParsePointText(const std::string& text, const std::string& what) {
  const auto fail = [&]() -> InputError {
    return InputError(what, "'" + text + "' is not three finite numbers X,Y,Z");
  };
  std::vector<std::string> fields;
  std::stringstream stream(text);
  std::string field;
  while (std::getline(stream, field, ',')) fields.push_back(field);
  if (fields.size() != 3 || text.empty() || text.back() == ',') throw fail();
  Eigen::Vector3d p;
  for (int k = 0; k < 3; ++k) {
    const char* begin = fields[k].c_str();
    char* end = nullptr;
    p(k) = std::strtod(begin, &end);
    if (end == begin) throw fail();
    while (*end == ' ') ++end;
    if (*end != '\0') throw fail();
  }
  if (!p.allFinite()) throw fail();
  return p;
}

PointSet ReadPointListJson(const std::string& path, const std::string& key) {
  const json doc = ParseJsonFile(path);
  if (!doc.is_object()) throw InputError(path, "expected a JSON object");
  if (doc.contains("keypoints") && doc["keypoints"].is_object() && doc["keypoints"].contains(key)) {
    return JsonPointList(doc["keypoints"][key], path, "keypoints." + key);
  }
  if (doc.contains(key)) return JsonPointList(doc[key], path, key);
  const std::string available = doc.contains("keypoints") && doc["keypoints"].is_object()
                                    ? KeyList(doc["keypoints"])
                                    : KeyList(doc);
  throw InputError(path, "key '" + key + "' not found (available: " + available + ")");
}

std::vector<std::string> KeypointNetModel::Names() const {
  std::vector<std::string> names;
  for (int id : semantic_ids) names.push_back("semantic" + std::to_string(id));
  return names;
}

KeypointNetModel ReadKeypointNet(const std::string& path, const std::string& model_id) {
  const json doc = ParseJsonFile(path);
  if (!doc.is_array()) throw InputError(path, "expected a KeypointNet list of models");
  for (std::size_t m = 0; m < doc.size(); ++m) {
    const json& entry = doc[m];
    if (!entry.is_object() || !entry.contains("model_id")) continue;
    if (JsonIdText(entry["model_id"]) != model_id) continue;
    const std::string where = "[" + std::to_string(m) + "]";
    if (!entry.contains("keypoints") || !entry["keypoints"].is_array() || entry["keypoints"].empty()) {
      throw InputError(path, where + ".keypoints: missing or empty for model '" + model_id + "'");
    }
    KeypointNetModel model;
    model.model_id = model_id;
    if (entry.contains("class_id")) model.class_id = JsonIdText(entry["class_id"]);
    const json& keypoints = entry["keypoints"];
    model.points.resize(3, static_cast<Eigen::Index>(keypoints.size()));
    for (std::size_t i = 0; i < keypoints.size(); ++i) {
      const std::string field = where + ".keypoints[" + std::to_string(i) + "]";
      const json& kp = keypoints[i];
      if (!kp.is_object() || !kp.contains("xyz")) throw InputError(path, field + ".xyz: missing");
      model.points.col(static_cast<Eigen::Index>(i)) = JsonPoint(kp["xyz"], path, field + ".xyz");
      if (!kp.contains("semantic_id") || !kp["semantic_id"].is_number_integer()) {
        throw InputError(path, field + ".semantic_id: missing or not an integer");
      }
      model.semantic_ids.push_back(kp["semantic_id"].get<int>());
    }
    return model;
  }
  throw InputError(path, "model id '" + model_id + "' not found (" + std::to_string(doc.size()) +
                             " models in the file)");
}

KeypointRemoval RemoveKeypoints(const ObjectSpec& spec, const std::vector<int>& remove,
                                bool drop_sets, const std::string& where) {
  const int n = spec.num_keypoints();
  std::set<int> removed;
  for (int index : remove) {
    if (index < 0 || index >= n) {
      throw InputError(where, "--remove " + std::to_string(index) + ": no such keypoint (the object has " +
                                  std::to_string(n) + ", indices 0.." + std::to_string(n - 1) + ")");
    }
    removed.insert(index);
  }
  KeypointRemoval result;
  result.spec = spec;
  result.new_index_of_old.assign(n, -1);
  int kept = 0;
  for (int i = 0; i < n; ++i) {
    if (!removed.count(i)) result.new_index_of_old[i] = kept++;
  }
  result.spec.keypoints.resize(3, kept);
  result.spec.keypoint_names.clear();
  for (int i = 0; i < n; ++i) {
    const int j = result.new_index_of_old[i];
    if (j < 0) continue;
    result.spec.keypoints.col(j) = spec.keypoints.col(i);
    if (!spec.keypoint_names.empty()) result.spec.keypoint_names.push_back(spec.keypoint_names[i]);
  }
  result.spec.indicator_sets.clear();
  for (std::size_t s = 0; s < spec.indicator_sets.size(); ++s) {
    const auto& set = spec.indicator_sets[s];
    std::vector<int> remapped;
    for (int index : set) {
      if (result.new_index_of_old.at(index) >= 0) remapped.push_back(result.new_index_of_old[index]);
    }
    if (remapped.size() == set.size()) {
      result.spec.indicator_sets.push_back(remapped);
      continue;
    }
    if (!drop_sets) {
      std::ostringstream text;
      text << "indicator set " << s << " {";
      for (std::size_t k = 0; k < set.size(); ++k) text << (k ? "," : "") << set[k];
      text << "} contains a removed keypoint; pass --drop-sets to drop such sets";
      throw InputError(where, text.str());
    }
    result.dropped_sets.push_back(set);
  }
  return result;
}

void AppendKeypoints(ObjectSpec* spec, const PointSet& points, const std::vector<std::string>& names) {
  if (!names.empty() && names.size() != static_cast<std::size_t>(points.cols())) {
    throw std::invalid_argument("AppendKeypoints: names must be empty or one per point");
  }
  const Eigen::Index old_count = spec->keypoints.cols();
  if (spec->keypoint_names.empty()) spec->keypoint_names.assign(old_count, "");
  spec->keypoints.conservativeResize(3, old_count + points.cols());
  spec->keypoints.rightCols(points.cols()) = points;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    spec->keypoint_names.push_back(names.empty() ? "" : names[i]);
  }
  bool any_name = false;
  for (const auto& name : spec->keypoint_names) any_name = any_name || !name.empty();
  if (!any_name) spec->keypoint_names.clear();
}

std::string UnusedName(const ObjectSpec& spec, const std::string& prefix, int* next_index) {
  std::set<std::string> used(spec.keypoint_names.begin(), spec.keypoint_names.end());
  while (used.count(prefix + std::to_string(*next_index))) ++*next_index;
  return prefix + std::to_string((*next_index)++);
}

}  // namespace c3po
