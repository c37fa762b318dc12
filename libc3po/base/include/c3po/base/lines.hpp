#pragma once
// The lines of a text file read whole (JSON lines, BOP CSV): one loop for
// every line-oriented reader.
#include <string_view>
#include <vector>

namespace c3po {

// The lines of `text` without their '\n' (a '\r' before it is kept: callers
// decide), in order; a last line without '\n' counts, a trailing '\n' adds no
// empty line. The views point into `text`.
inline std::vector<std::string_view> SplitLines(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    lines.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return lines;
}

}  // namespace c3po
