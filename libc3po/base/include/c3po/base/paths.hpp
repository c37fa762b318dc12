#pragma once
// Path strings split at the last '/', without touching the file system.
#include <string>

namespace c3po {

// "a/b/c" -> "a/b"; "c" -> "."; "/c" -> "/".
std::string ParentOf(const std::string& path);
// "a/b/c" -> "c"; "c" -> "c"; "a/b/" -> "".
std::string LeafOf(const std::string& path);

// "a/b//" -> "a/b"; "/" stays "/".
std::string StripTrailingSlashes(std::string path);

}  // namespace c3po
