#pragma once
// Registry internals shared by registry.cpp, plugin_loader.cpp and builtins.cpp.
#include <functional>
#include <memory>
#include <string>

#include "c3po/plugins/registry.hpp"

namespace c3po {

using ModelLoader =
    std::function<std::unique_ptr<Detector>(const std::string& path, const ObjectModel&)>;

void RegisterModelLoader(const DetectorInfo& info, ModelLoader loader);
// Registers svd, pointnet (when built), ...; called once on first registry use.
void RegisterBuiltinDetectors();

}  // namespace c3po
