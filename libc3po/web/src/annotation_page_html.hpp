#pragma once
// Static parts of the annotation page (CSS, layout, the page's JavaScript).
#include <string>

namespace c3po::page {

// <!doctype html> ... <body> with the layout; `title` already HTML-escaped.
std::string Head(const std::string& title);
// The <script type="module"> that loads three.js from #c3po-three and the
// data from #c3po-data.
std::string AppScript();

}  // namespace c3po::page
