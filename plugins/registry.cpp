#include "c3po/plugins/registry.hpp"

#include <map>
#include <mutex>
#include <stdexcept>

#include "c3po/base/error.hpp"
#include "registry_internal.hpp"

namespace c3po {
namespace {

struct Entry {
  DetectorInfo info;
  DetectorFactory factory;       // detectors without a model file
  ModelLoader loader;            // detectors loaded from a model file
};

std::mutex& RegistryMutex() {
  static std::mutex mutex;
  return mutex;
}

std::map<std::string, Entry>& Registry() {
  static std::map<std::string, Entry> registry;
  return registry;
}

void EnsureBuiltins() {
  static std::once_flag once;
  std::call_once(once, [] { RegisterBuiltinDetectors(); });
}

std::string KnownNames() {
  std::string names;
  for (const auto& [name, entry] : Registry()) names += (names.empty() ? "" : ", ") + name;
  return names.empty() ? "none" : names;
}

}  // namespace

void RegisterDetector(const DetectorInfo& info, DetectorFactory factory) {
  if (info.name.empty()) throw std::invalid_argument("RegisterDetector: empty name");
  std::lock_guard<std::mutex> lock(RegistryMutex());
  Entry& entry = Registry()[info.name];
  entry.info = info;
  entry.factory = std::move(factory);
}

void RegisterModelLoader(const DetectorInfo& info, ModelLoader loader) {
  if (info.name.empty()) throw std::invalid_argument("RegisterModelLoader: empty name");
  std::lock_guard<std::mutex> lock(RegistryMutex());
  Entry& entry = Registry()[info.name];
  entry.info = info;
  entry.info.needs_model_file = true;
  entry.loader = std::move(loader);
}

std::vector<DetectorInfo> ListDetectors() {
  EnsureBuiltins();
  std::lock_guard<std::mutex> lock(RegistryMutex());
  std::vector<DetectorInfo> infos;
  for (const auto& [name, entry] : Registry()) infos.push_back(entry.info);
  return infos;
}

std::unique_ptr<Detector> CreateDetector(const std::string& name, const ObjectModel& object) {
  EnsureBuiltins();
  DetectorFactory factory;
  {
    std::lock_guard<std::mutex> lock(RegistryMutex());
    const auto it = Registry().find(name);
    if (it == Registry().end()) {
      throw InputError("--detector", "unknown detector '" + name + "' (known: " + KnownNames() + ")");
    }
    if (!it->second.factory) {
      throw InputError("--detector", "detector '" + name + "' needs a trained model: use --model FILE");
    }
    factory = it->second.factory;
  }
  return factory(object);
}

std::unique_ptr<Detector> LoadDetectorModel(const std::string& path, const ObjectModel& object) {
  EnsureBuiltins();
  const std::string detector = ReadModelHeader(path).detector;
  ModelLoader loader;
  {
    std::lock_guard<std::mutex> lock(RegistryMutex());
    const auto it = Registry().find(detector);
    if (it == Registry().end() || !it->second.loader) {
      throw InputError(path, "model of detector '" + detector + "', which this build cannot load (known: " +
                                 KnownNames() + ")");
    }
    loader = it->second.loader;
  }
  return loader(path, object);
}

}  // namespace c3po
