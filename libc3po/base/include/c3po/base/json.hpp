#pragma once
// JSON of c3po's value types, written once for every output schema
// (certify lines, manifests, object files, evaluation JSON, pages): a point
// set is a list of [x, y, z] rows, a pose is "R" (three rows) and "t".
// Json is nlohmann::json or nlohmann::ordered_json (key order of a schema).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "c3po/base/error.hpp"
#include "c3po/base/types.hpp"

namespace c3po {

// [[x, y, z], ...], one row per column of `points`.
template <class Json = nlohmann::json>
Json PointsToJson(const PointSet& points) {
  Json rows = Json::array();
  for (Eigen::Index i = 0; i < points.cols(); ++i) rows.push_back({points(0, i), points(1, i), points(2, i)});
  return rows;
}

// The rotation's rows: [[r00, r01, r02], [r10, ...], [r20, ...]].
template <class Json = nlohmann::json>
Json RotationToJson(const Eigen::Matrix3d& R) {
  return {{R(0, 0), R(0, 1), R(0, 2)}, {R(1, 0), R(1, 1), R(1, 2)}, {R(2, 0), R(2, 1), R(2, 2)}};
}

// [x, y, z].
template <class Json = nlohmann::json>
Json VectorToJson(const Eigen::Vector3d& v) {
  return {v(0), v(1), v(2)};
}

// Sets json["R"] and json["t"] of a pose.
template <class Json>
void SetPoseJson(const Pose& pose, Json* json) {
  (*json)["R"] = RotationToJson<Json>(pose.R);
  (*json)["t"] = VectorToJson<Json>(pose.t);
}

// A JSON integer within [lo, hi], else InputError(where, "field: ..."). JSON
// floats are refused, not converted: 1e300 converted to int is undefined
// behaviour, and 1.5 must not be truncated silently.
template <class Json = nlohmann::json>
long long IntegerInRange(const Json& value, long long lo, long long hi, const std::string& where,
                         const std::string& field) {
  const auto shown = [&value] {   // one line; a huge value is cut
    const std::string text = value.dump();
    return text.size() > 40 ? text.substr(0, 37) + "..." : text;
  };
  const auto range = [lo, hi] { return "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]"; };
  if (!value.is_number_integer()) {
    throw InputError(where, field + ": " + shown() + " is not an integer (expected one in " + range() + ")");
  }
  const bool in_range = value.is_number_unsigned()
                            ? hi >= 0 && value.template get<std::uint64_t>() <= static_cast<std::uint64_t>(hi) &&
                                  (lo <= 0 || value.template get<std::uint64_t>() >= static_cast<std::uint64_t>(lo))
                            : value.template get<std::int64_t>() >= lo && value.template get<std::int64_t>() <= hi;
  if (!in_range) throw InputError(where, field + ": " + shown() + " out of range " + range());
  return value.template get<long long>();
}

}  // namespace c3po
