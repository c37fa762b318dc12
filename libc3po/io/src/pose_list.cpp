#include "c3po/io/pose_list.hpp"

#include <Eigen/SVD>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "c3po/base/error.hpp"

namespace c3po {
namespace {

constexpr double kPoseRotationTolerance = 1e-4;
constexpr std::size_t kMaxLineLength = 1 << 16;

std::string Printable(const std::string& text) {
  std::string printable = text.substr(0, 80);
  for (char& c : printable) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return printable;
}

std::string Trim(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  const auto end = text.find_last_not_of(" \t\r\n");
  return text.substr(begin, end - begin + 1);
}

[[noreturn]] void Fail(const std::string& where, int line, const std::string& field, const std::string& problem) {
  throw InputError(where + ": line " + std::to_string(line) + ": " + field + ": " + problem);
}

// Checks R against SO(3) and returns the nearest rotation.
Eigen::Matrix3d CheckedRotation(Eigen::Matrix3d R, const std::string& where, int line) {
  if (!R.allFinite()) Fail(where, line, "R", "non-finite number");
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(error <= kPoseRotationTolerance)) {
    Fail(where, line, "R", "not a rotation (max |R^T R - I| = " + std::to_string(error) + ")");
  }
  if (R.determinant() < 0) Fail(where, line, "R", "determinant is -1 (a reflection, not a rotation)");
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

// Whitespace-separated finite numbers, exactly `count` of them.
std::vector<double> Numbers(const std::string& text, std::size_t count, const std::string& where, int line,
                            const std::string& field) {
  std::vector<double> values;
  const char* p = text.c_str();
  while (true) {
    while (*p == ' ' || *p == '\t') ++p;
    if (*p == '\0') break;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(p, &end);
    if (end == p) Fail(where, line, field, "not a number: '" + Printable(p) + "'");
    if (!std::isfinite(v)) Fail(where, line, field, "non-finite number");
    values.push_back(v);
    if (values.size() > count) break;
    p = end;
  }
  if (values.size() != count) {
    Fail(where, line, field, "expected " + std::to_string(count) + " numbers separated by spaces");
  }
  return values;
}

int Integer(const std::string& text, const std::string& where, int line, const std::string& field) {
  const std::string trimmed = Trim(text);
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(trimmed.c_str(), &end, 10);
  if (trimmed.empty() || *end != '\0' || errno == ERANGE || v < 0 || v > 2147483647L) {
    Fail(where, line, field, "expected a non-negative integer, found '" + Printable(trimmed) + "'");
  }
  return static_cast<int>(v);
}

std::vector<PoseHypothesis> ParseCsv(std::istringstream& in, const std::string& where) {
  std::vector<PoseHypothesis> poses;
  std::string raw;
  int line = 0;
  bool header = false;
  while (std::getline(in, raw)) {
    ++line;
    if (raw.size() > kMaxLineLength) Fail(where, line, "line", "longer than 65536 characters");
    const std::string text = Trim(raw);
    if (text.empty()) continue;
    std::vector<std::string> fields;
    std::stringstream split(text);
    std::string field;
    while (std::getline(split, field, ',')) fields.push_back(field);
    if (!text.empty() && text.back() == ',') fields.push_back("");
    if (!header) {
      std::string joined;
      for (const auto& f : fields) joined += (joined.empty() ? "" : ",") + Trim(f);
      if (joined != "scene_id,im_id,obj_id,score,R,t,time") {
        Fail(where, line, "header", "expected 'scene_id,im_id,obj_id,score,R,t,time' (BOP results CSV), found '" +
                                        Printable(text) + "'");
      }
      header = true;
      continue;
    }
    if (fields.size() != 7) Fail(where, line, "row", "expected 7 comma-separated fields, found " + std::to_string(fields.size()));
    PoseHypothesis pose;
    pose.line = line;
    pose.scene_id = Integer(fields[0], where, line, "scene_id");
    pose.im_id = Integer(fields[1], where, line, "im_id");
    pose.obj_id = Integer(fields[2], where, line, "obj_id");
    pose.score = Numbers(fields[3], 1, where, line, "score")[0];
    const std::vector<double> r = Numbers(fields[4], 9, where, line, "R");
    Eigen::Matrix3d R;
    R << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
    pose.scene_from_model.R = CheckedRotation(R, where, line);
    const std::vector<double> t = Numbers(fields[5], 3, where, line, "t");
    pose.scene_from_model.t = Eigen::Vector3d(t[0], t[1], t[2]) / 1000.0;   // mm -> m
    pose.time = Numbers(fields[6], 1, where, line, "time")[0];
    poses.push_back(pose);
  }
  if (!header) throw InputError(where, "empty pose file");
  if (poses.empty()) throw InputError(where, "empty pose file (a header and no pose line)");
  return poses;
}

std::optional<int> OptionalId(const nlohmann::json& object, const char* field, const std::string& where, int line) {
  const auto it = object.find(field);
  if (it == object.end()) return std::nullopt;
  if (!it->is_number_integer() || it->get<long long>() < 0 || it->get<long long>() > 2147483647LL) {
    Fail(where, line, field, "expected a non-negative integer");
  }
  return static_cast<int>(it->get<long long>());
}

std::vector<PoseHypothesis> ParseJsonLines(std::istringstream& in, const std::string& where) {
  std::vector<PoseHypothesis> poses;
  std::string raw;
  int line = 0;
  while (std::getline(in, raw)) {
    ++line;
    if (raw.size() > kMaxLineLength) Fail(where, line, "line", "longer than 65536 characters");
    const std::string text = Trim(raw);
    if (text.empty()) continue;
    nlohmann::json object;
    try {
      object = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception&) {
      Fail(where, line, "line", "not valid JSON");
    }
    if (!object.is_object()) Fail(where, line, "line", "expected a JSON object");
    PoseHypothesis pose;
    pose.line = line;
    const auto cloud = object.find("cloud");
    if (cloud != object.end()) {
      if (!cloud->is_string() || cloud->get<std::string>().empty()) Fail(where, line, "cloud", "expected a non-empty string");
      pose.cloud = cloud->get<std::string>();
    }
    pose.scene_id = OptionalId(object, "scene_id", where, line);
    pose.im_id = OptionalId(object, "im_id", where, line);
    pose.obj_id = OptionalId(object, "obj_id", where, line);
    if (pose.cloud.empty() && !(pose.scene_id && pose.im_id)) {
      Fail(where, line, "cloud", "missing (give \"cloud\" or \"scene_id\" and \"im_id\")");
    }
    auto number = [&](const nlohmann::json& v, const char* field) {
      if (!v.is_number()) Fail(where, line, field, "expected a number");
      const double x = v.get<double>();
      if (!std::isfinite(x)) Fail(where, line, field, "non-finite number");
      return x;
    };
    const auto R = object.find("R");
    if (R == object.end()) Fail(where, line, "R", "missing (required)");
    if (!R->is_array() || R->size() != 3) Fail(where, line, "R", "expected 3 rows of 3 numbers");
    Eigen::Matrix3d rotation;
    for (std::size_t r = 0; r < 3; ++r) {
      const auto& row = (*R)[r];
      if (!row.is_array() || row.size() != 3) Fail(where, line, "R", "expected 3 rows of 3 numbers");
      for (std::size_t c = 0; c < 3; ++c) rotation(r, c) = number(row[c], "R");
    }
    pose.scene_from_model.R = CheckedRotation(rotation, where, line);
    const auto t = object.find("t");
    if (t == object.end()) Fail(where, line, "t", "missing (required)");
    if (!t->is_array() || t->size() != 3) Fail(where, line, "t", "expected an array of 3 numbers");
    for (std::size_t k = 0; k < 3; ++k) pose.scene_from_model.t(k) = number((*t)[k], "t");
    const auto score = object.find("score");
    if (score != object.end()) pose.score = number(*score, "score");
    poses.push_back(pose);
  }
  if (poses.empty()) throw InputError(where, "empty pose file");
  return poses;
}

}  // namespace

std::vector<PoseHypothesis> ParsePoseList(const std::string& text, const std::string& where) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) throw InputError(where, "empty pose file");
  std::istringstream in(text);
  return text[first] == '{' ? ParseJsonLines(in, where) : ParseCsv(in, where);
}

std::vector<PoseHypothesis> ReadPoseList(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) throw InputError(path, "is a directory, not a pose file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path, "read error");
  return ParsePoseList(text.str(), path);
}

}  // namespace c3po
