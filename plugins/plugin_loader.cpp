// Loads detectors from shared libraries through the C entry point of
// c3po/plugins/plugin_api.h.
#include <dlfcn.h>

#include <filesystem>
#include <string>

#include "c3po/base/error.hpp"
#include "c3po/base/version.hpp"
#include "c3po/plugins/plugin_api.h"
#include "registry_internal.hpp"

// c3po --version reports the ABI from the generated version header; it must be
// the one of the header this loader compiles against.
static_assert(C3PO_BUILD_PLUGIN_ABI_VERSION == C3PO_PLUGIN_ABI_VERSION,
              "c3po/base/version.hpp is stale: re-run cmake");

namespace c3po {
namespace {

class PluginDetector : public Detector {
 public:
  PluginDetector(const c3po_detector_plugin* table, void* instance, int num_keypoints)
      : table_(table), instance_(instance), num_keypoints_(num_keypoints) {}
  ~PluginDetector() override {
    if (instance_ && table_->destroy) table_->destroy(instance_);
  }
  std::string name() const override { return table_->name; }
  int num_keypoints() const override { return num_keypoints_; }

  PointSet Detect(const PointSet& cloud) const override {
    PointSet keypoints(3, num_keypoints_);
    const int status = table_->detect(instance_, cloud.data(), static_cast<int>(cloud.cols()),
                                      keypoints.data());
    if (status != 0) {
      const char* why = table_->last_error ? table_->last_error(instance_) : nullptr;
      throw InputError(std::string("plugin ") + table_->name,
                       std::string("detect failed: ") + (why ? why : "no reason given"));
    }
    return keypoints;
  }

 private:
  const c3po_detector_plugin* table_;
  void* instance_;
  int num_keypoints_;
};

std::string DlError() {
  const char* error = dlerror();
  return error ? error : "unknown error";
}

}  // namespace

void LoadPlugin(const std::string& path) {
  // dlopen searches the system library path for a name without '/': a plugin
  // named on the command line is a file, so make it a path.
  const std::string file = path.find('/') == std::string::npos ? "./" + path : path;
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) throw InputError(path, "no such plugin file");
  // RTLD_NODELETE keeps the code mapped for detectors that outlive this call.
  void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
  if (!handle) throw InputError(path, "cannot load plugin: " + DlError());
  auto entry = reinterpret_cast<c3po_detector_plugin_entry>(dlsym(handle, "c3po_detector_plugin_v1"));
  if (!entry) throw InputError(path, "not a c3po plugin: no symbol c3po_detector_plugin_v1");
  const c3po_detector_plugin* table = entry();
  if (!table) throw InputError(path, "plugin entry point returned no table");
  if (table->abi_version != C3PO_PLUGIN_ABI_VERSION) {
    throw InputError(path, "plugin built for c3po plugin ABI version " + std::to_string(table->abi_version) +
                               ", this c3po " C3PO_VERSION " loads ABI version " +
                               std::to_string(C3PO_PLUGIN_ABI_VERSION) +
                               " (rebuild the plugin against this c3po's plugin_api.h)");
  }
  if (!table->name || !*table->name || !table->create || !table->detect) {
    throw InputError(path, "plugin table lacks a name, create or detect");
  }
  // Built-ins register lazily on first registry use; do it now, or they would
  // later silently replace a plugin of the same name (the plugin must win).
  (void)ListDetectors();
  DetectorInfo info{table->name, table->description ? table->description : "plugin", false};
  info.description += " (plugin " + path + ")";
  RegisterDetector(info, [table, path](const ObjectModel& object) -> std::unique_ptr<Detector> {
    const PointSet& keypoints = object.keypoints();
    void* instance = table->create(keypoints.data(), static_cast<int>(keypoints.cols()),
                                   object.diameter(), nullptr);
    if (!instance) throw InputError(path, "plugin could not create a detector for this object");
    return std::make_unique<PluginDetector>(table, instance, static_cast<int>(keypoints.cols()));
  });
}

}  // namespace c3po
