#pragma once
// Files embedded at build time by cmake/EmbedResource.cmake (generated .cpp in
// the build folder).
#include <string>

namespace c3po::resources {

// three.js r170 ES module build (build/three.module.min.js, MIT licence header
// kept; third_party_notes/three.js.md).
std::string ThreeJsModule();

}  // namespace c3po::resources
