#pragma once
// Detector registry: names -> factories. Built-in detectors register here;
// outside detectors come from shared libraries through the C entry point in
// c3po/plugins/plugin_api.h (see LoadPlugin).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "c3po/method/detector.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct DetectorInfo {
  std::string name;
  std::string description;
  bool needs_model_file = false;   // true: trained, loaded with --model
};

using DetectorFactory = std::function<std::unique_ptr<Detector>(const ObjectModel&)>;

std::vector<DetectorInfo> ListDetectors();
// Registers a factory for detectors that need no model file; replaces one of
// the same name. Throws std::invalid_argument for an empty name.
void RegisterDetector(const DetectorInfo& info, DetectorFactory factory);
// A detector that needs no model file (e.g. "svd"). Throws InputError for an
// unknown name, listing the known ones.
std::unique_ptr<Detector> CreateDetector(const std::string& name, const ObjectModel& object);
// Loads a trained model file (self-describing: detector name, object, weights).
// Throws InputError("path: ...") when it is unreadable or for another object.
std::unique_ptr<Detector> LoadDetectorModel(const std::string& path, const ObjectModel& object);
// The JSON header line of a model file: {"magic": "c3po-model", "detector":
// NAME, ...}, read with a bound on its length and checked (magic, detector
// name). Throws InputError("path: ...") when the file is not a c3po model.
struct ModelHeader {
  std::string detector;          // "detector"
  bool self_trained = false;     // "selftrained" (or "self_trained") is true
  std::string json;              // the whole header
};
ModelHeader ReadModelHeader(const std::string& path);
// Loads a detector plugin from a shared library and registers it. Throws
// InputError("path: ...") when it cannot be loaded or lacks the entry point.
void LoadPlugin(const std::string& path);

}  // namespace c3po
