#pragma once
// Strict JSON input helpers shared by the io readers (camera JSON, BOP JSON):
// every problem is an InputError naming the file.
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "c3po/base/error.hpp"

namespace c3po::io_detail {

inline nlohmann::json ParseJson(const std::string& text, const std::string& name) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(name, std::string("not valid JSON: ") + e.what());
  }
}

inline double FiniteNumber(const nlohmann::json& value, const std::string& name, const std::string& field) {
  if (!value.is_number()) throw InputError(name, field + ": expected a number");
  const double number = value.get<double>();
  if (!std::isfinite(number)) throw InputError(name, field + ": not a finite number");
  return number;
}

}  // namespace c3po::io_detail
