#pragma once
// Object JSON files (schema: annotations/README.md).
#include <string>

#include "c3po/object/object_model.hpp"

namespace c3po {

// Reads and validates an object JSON; the mesh path is resolved relative to
// the JSON file. Throws InputError("file: field: problem").
ObjectSpec ReadObjectSpec(const std::string& path);
// Writes atomically; the mesh path is written relative to the JSON's folder.
void WriteObjectSpec(const ObjectSpec& spec, const std::string& path);
// ReadObjectSpec + LoadMesh (in spec.units) + ObjectModel.
ObjectModel LoadObject(const std::string& path, const ObjectModelOptions& options = {});

// Parses a threshold: "0.01" (object units), "3%d" (3 % of the diameter).
// Throws InputError(what + ": ...") on anything else or a non-positive value.
double ParseThreshold(const std::string& text, double diameter, const std::string& what);

}  // namespace c3po
