#pragma once
// Text for self-contained HTML pages (report, annotation page): the one set
// of escapers and encoders of the web layer. Private to libc3po/web.
#include <cstddef>
#include <string>

#include "c3po/base/types.hpp"

namespace c3po::web {

// For HTML text content and attribute values (double- or single-quoted):
// & < > " ' become entities.
std::string HtmlEscape(const std::string& text);
// JSON (or any text) safe inside <script>: "</" is written "<\/", so the
// text cannot close the element.
std::string ScriptSafe(std::string text);
// Standard base64 with padding.
std::string Base64(const unsigned char* bytes, std::size_t size);
// The finite columns of `points` as little-endian float32 x, y, z, base64
// (pages decode them with a DataView).
std::string PointsFloat32Base64(const PointSet& points);

}  // namespace c3po::web
