// Model files start with one line of JSON: {"magic": "c3po-model", "detector": NAME, ...}.
// The one reader of that line (registry.hpp: ReadModelHeader); bounded to 1 MiB.
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "c3po/base/error.hpp"
#include "registry_internal.hpp"

namespace c3po {

ModelHeader ReadModelHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open model file");
  std::string line;
  line.reserve(4096);
  char c;
  while (in.get(c) && c != '\n') {
    line.push_back(c);
    if (line.size() > (1u << 20)) throw InputError(path, "not a c3po model file (no header line)");
  }
  nlohmann::json header;
  try {
    header = nlohmann::json::parse(line);
  } catch (const nlohmann::json::exception&) {
    throw InputError(path, "not a c3po model file (header is not JSON)");
  }
  // json::value() throws type_error for a non-string "magic": test the type first.
  if (!header.is_object() || !header.contains("magic") || !header["magic"].is_string() ||
      header["magic"].get<std::string>() != "c3po-model") {
    throw InputError(path, "not a c3po model file (missing magic \"c3po-model\")");
  }
  if (!header.contains("detector") || !header["detector"].is_string()) {
    throw InputError(path, "model header has no detector name");
  }
  ModelHeader result;
  result.detector = header["detector"].get<std::string>();
  for (const char* key : {"selftrained", "self_trained"}) {
    if (header.contains(key) && header[key].is_boolean() && header[key].get<bool>()) result.self_trained = true;
  }
  result.json = header.dump();
  return result;
}

}  // namespace c3po
