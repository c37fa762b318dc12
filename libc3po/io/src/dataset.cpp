// Dataset folders: manifest.jsonl (one JSON object per cloud) + cloud files.
// Reading validates every field. The manifest line schema (ParseManifestLine,
// ManifestLine) lives here; DatasetWriter is dataset_writer.cpp.
#include "c3po/io/dataset.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <map>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>

#include "c3po/base/lines.hpp"
#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/json.hpp"
#include "c3po/base/paths.hpp"
#include "c3po/io/cloud_io.hpp"
#include "c3po/geometry/rotation.hpp"

namespace c3po {
namespace fs = std::filesystem;
namespace {

constexpr int kMaxJsonDepth = 16;

// `text` with control characters replaced, so messages stay on one line.
constexpr std::size_t kMaxObjectLabel = 256;

std::string Printable(const std::string& text) {
  std::string printable = text.substr(0, 200);
  for (char& c : printable) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return printable;
}

// Why `cloud` is not a safe path inside the dataset folder, or nullopt.
std::optional<std::string> CloudPathProblem(const std::string& cloud) {
  if (cloud.empty()) return "empty path";
  if (cloud.find('\0') != std::string::npos) return "path contains a NUL character";
  if (cloud.front() == '/') return "absolute path '" + Printable(cloud) + "' (must be relative to the dataset folder)";
  int depth = 0;
  std::size_t start = 0;
  while (start <= cloud.size()) {
    std::size_t end = cloud.find('/', start);
    if (end == std::string::npos) end = cloud.size();
    const std::string part = cloud.substr(start, end - start);
    if (part == "..") {
      if (--depth < 0) return "path '" + Printable(cloud) + "' escapes the dataset folder";
    } else if (!part.empty() && part != ".") {
      ++depth;
    }
    start = end + 1;
  }
  if (depth == 0 || cloud.back() == '/') return "path '" + Printable(cloud) + "' does not name a file";
  return std::nullopt;
}

// Rejects pathological nesting before handing the text to the JSON parser.
bool NestingWithin(const std::string& text, int max_depth) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return false;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return true;
}

class LineParser {
 public:
  LineParser(const nlohmann::json& object, const std::string& where) : object_(object), where_(where) {}

  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const {
    throw InputError(where_ + ": " + field + ": " + problem);
  }

  const nlohmann::json* Find(const char* field) const {
    const auto it = object_.find(field);
    return it == object_.end() ? nullptr : &*it;
  }

  std::string Cloud() const {
    const nlohmann::json* value = Find("cloud");
    if (!value) Fail("cloud", "missing (required)");
    if (!value->is_string()) Fail("cloud", "expected a string");
    const std::string cloud = value->get<std::string>();
    if (const auto problem = CloudPathProblem(cloud)) Fail("cloud", *problem);
    return cloud;
  }

  double Number(const nlohmann::json& value, const char* field) const {
    if (!value.is_number()) Fail(field, "expected a number, found " + std::string(value.type_name()));
    const double number = value.get<double>();
    if (!std::isfinite(number)) Fail(field, "non-finite number");
    return number;
  }

  Eigen::Vector3d Triple(const nlohmann::json& value, const char* field, const std::string& what) const {
    if (!value.is_array() || value.size() != 3) Fail(field, what + "expected an array of 3 numbers");
    return {Number(value[0], field), Number(value[1], field), Number(value[2], field)};
  }

  std::optional<Eigen::Matrix3d> Rotation() const {
    const nlohmann::json* value = Find("R");
    if (!value) return std::nullopt;
    if (!value->is_array() || value->size() != 3) Fail("R", "expected 3 rows of 3 numbers");
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r) R.row(r) = Triple((*value)[static_cast<std::size_t>(r)], "R", "row " + std::to_string(r) + ": ").transpose();
    std::string problem;
    const std::optional<Eigen::Matrix3d> rotation = NearestRotation(R, &problem);
    if (!rotation) Fail("R", problem);
    R = *rotation;
    return R;
  }

  std::optional<Eigen::Vector3d> Translation() const {
    const nlohmann::json* value = Find("t");
    if (!value) return std::nullopt;
    return Triple(*value, "t", "");
  }

  std::optional<PointSet> Points(const char* field) const {
    const nlohmann::json* value = Find(field);
    if (!value) return std::nullopt;
    if (!value->is_array() || value->empty()) Fail(field, "expected a non-empty array of [x, y, z]");
    PointSet points(3, static_cast<Eigen::Index>(value->size()));
    for (std::size_t i = 0; i < value->size(); ++i) {
      points.col(static_cast<Eigen::Index>(i)) = Triple((*value)[i], field, "item " + std::to_string(i) + ": ");
    }
    return points;
  }

  std::optional<std::string> ObjectLabel() const {
    const nlohmann::json* value = Find("object");
    if (!value) return std::nullopt;
    if (!value->is_string()) Fail("object", "expected a string (the object's name)");
    const std::string label = value->get<std::string>();
    if (label.empty() || label.size() > kMaxObjectLabel) {
      Fail("object", "expected 1 to " + std::to_string(kMaxObjectLabel) + " characters");
    }
    for (unsigned char c : label) {
      if (c < 0x20 || c == 0x7f) Fail("object", "control character in '" + Printable(label) + "'");
    }
    return label;
  }

  std::optional<std::vector<bool>> Visible() const {
    const nlohmann::json* value = Find("visible");
    if (!value) return std::nullopt;
    if (!value->is_array() || value->empty()) Fail("visible", "expected a non-empty array of booleans");
    std::vector<bool> visible;
    for (const auto& item : *value) {
      if (!item.is_boolean()) Fail("visible", "expected booleans, found " + std::string(item.type_name()));
      visible.push_back(item.get<bool>());
    }
    return visible;
  }

 private:
  const nlohmann::json& object_;
  const std::string& where_;
};

// Number of keypoints an entry talks about (0 when it has none) and the field
// that says so; throws if its fields disagree.
std::pair<std::size_t, const char*> KeypointCount(const DatasetEntry& entry, const std::string& where) {
  std::size_t count = 0;
  const char* source = nullptr;
  const auto agree = [&](std::size_t n, const char* field) {
    if (source && n != count) {
      throw InputError(where + ": " + field + ": " + std::to_string(n) + " entries, but " + source +
                       " has " + std::to_string(count));
    }
    count = n;
    if (!source) source = field;
  };
  if (entry.keypoints) agree(static_cast<std::size_t>(entry.keypoints->cols()), "keypoints");
  if (entry.detected_keypoints) agree(static_cast<std::size_t>(entry.detected_keypoints->cols()), "detected_keypoints");
  if (entry.visible) agree(entry.visible->size(), "visible");
  return {count, source};
}

nlohmann::ordered_json PointsJson(const PointSet& points, const char* field) {
  if (!points.allFinite()) throw std::invalid_argument(std::string("ManifestLine: non-finite ") + field);
  return PointsToJson<nlohmann::ordered_json>(points);
}

}  // namespace

std::string Dataset::CloudPath(std::size_t i) const { return dir + "/" + entries.at(i).cloud; }

PointSet Dataset::LoadCloud(std::size_t i) const { return ReadCloud(CloudPath(i)); }

bool Dataset::Shows(std::size_t i, const std::string& object_name) const {
  const DatasetEntry& entry = entries.at(i);
  return !entry.object || *entry.object == object_name;
}

bool Dataset::HasGroundTruth() const {
  return !entries.empty() && std::all_of(entries.begin(), entries.end(), [](const DatasetEntry& e) {
           return e.pose.has_value() && e.keypoints.has_value();
         });
}

DatasetEntry ParseManifestLine(const std::string& line, const std::string& where, bool ground_truth) {
  if (!NestingWithin(line, kMaxJsonDepth)) throw InputError(where + ": JSON nested too deeply");
  nlohmann::json object;
  try {
    object = nlohmann::json::parse(line);
  } catch (const nlohmann::json::exception& error) {   // parse_error, number overflow
    std::string message = error.what();
    const std::size_t bracket = message.find("] ");
    if (bracket != std::string::npos) message = message.substr(bracket + 2);
    throw InputError(where + ": not valid JSON: " + message);
  }
  if (!object.is_object()) throw InputError(where + ": expected a JSON object");
  const LineParser parser(object, where);
  DatasetEntry entry;
  entry.cloud = parser.Cloud();
  if (ground_truth) {
    const auto R = parser.Rotation();
    const auto t = parser.Translation();
    if (R.has_value() != t.has_value()) parser.Fail(R ? "t" : "R", "missing (\"R\" and \"t\" go together)");
    if (R) entry.pose = Pose{*R, *t};
    entry.keypoints = parser.Points("keypoints");
    entry.visible = parser.Visible();
  }
  entry.detected_keypoints = parser.Points("detected_keypoints");
  entry.object = parser.ObjectLabel();
  KeypointCount(entry, where);
  return entry;
}

std::string ManifestLine(const DatasetEntry& entry) {
  if (const auto problem = CloudPathProblem(entry.cloud)) throw std::invalid_argument("ManifestLine: cloud: " + *problem);
  nlohmann::ordered_json line;
  line["cloud"] = entry.cloud;
  if (entry.pose) {
    if (!entry.pose->IsFinite()) throw std::invalid_argument("ManifestLine: non-finite pose");
    SetPoseJson(*entry.pose, &line);
  }
  if (entry.keypoints) line["keypoints"] = PointsJson(*entry.keypoints, "keypoints");
  if (entry.detected_keypoints) line["detected_keypoints"] = PointsJson(*entry.detected_keypoints, "detected_keypoints");
  if (entry.visible) {
    if (entry.keypoints && static_cast<Eigen::Index>(entry.visible->size()) != entry.keypoints->cols()) {
      throw std::invalid_argument("ManifestLine: visible and keypoints differ in size");
    }
    nlohmann::ordered_json flags = nlohmann::ordered_json::array();
    for (bool v : *entry.visible) flags.push_back(v);
    line["visible"] = flags;
  }
  if (entry.object) {
    const bool printable = std::none_of(entry.object->begin(), entry.object->end(), [](char c) {
      return static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
    });
    if (entry.object->empty() || entry.object->size() > kMaxObjectLabel || !printable) {
      throw std::invalid_argument("ManifestLine: object label must be 1-256 printable characters");
    }
    line["object"] = *entry.object;
  }
  return line.dump();
}

Dataset ReadDataset(const std::string& dir_argument, bool ground_truth) {
  const std::string dir = StripTrailingSlashes(dir_argument);
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (!fs::exists(status)) throw InputError(dir, "no such folder");
  if (!fs::is_directory(status)) throw InputError(dir, "not a folder (expected a dataset folder with manifest.jsonl)");
  const std::string manifest = dir + "/manifest.jsonl";
  if (!fs::exists(manifest, ec)) throw InputError(dir, "no manifest.jsonl (not a c3po dataset)");
  const std::string text = ReadFileToString(manifest);

  Dataset dataset;
  dataset.dir = dir;
  // The keypoint count of each object label ("" = unlabelled lines) and the line that set it.
  std::map<std::string, std::pair<std::size_t, std::size_t>> keypoint_counts;
  std::size_t line_number = 0;
  for (const std::string_view view : SplitLines(text)) {
    std::string line(view);
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    const std::string where = manifest + ": line " + std::to_string(line_number);
    DatasetEntry entry = ParseManifestLine(line, where, ground_truth);
    const auto [count, field] = KeypointCount(entry, where);
    auto& [keypoints, keypoints_line] = keypoint_counts[entry.object.value_or("")];
    if (count > 0 && keypoints > 0 && count != keypoints) {
      throw InputError(where + ": " + field + ": " + std::to_string(count) + " keypoints, but line " +
                       std::to_string(keypoints_line) + " has " + std::to_string(keypoints) +
                       (entry.object ? " (object " + Printable(*entry.object) + ")" : std::string()));
    }
    if (count > 0 && keypoints == 0) {
      keypoints = count;
      keypoints_line = line_number;
    }
    if (!fs::is_regular_file(dir + "/" + entry.cloud, ec)) {
      throw InputError(where + ": cloud: no such file '" + dir + "/" + Printable(entry.cloud) + "'");
    }
    dataset.entries.push_back(std::move(entry));
  }
  if (dataset.entries.empty()) throw InputError(manifest, "no entries");
  return dataset;
}

}  // namespace c3po
