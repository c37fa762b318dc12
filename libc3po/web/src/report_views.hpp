#pragma once
// The parts every report page shares (evaluation report, certify report):
// the page frame (head with the stylesheet; the 3D view's scripts at the
// end) and the 3D example section. Private to libc3po/web.
#include <string>
#include <vector>

#include "c3po/web/report.hpp"

namespace c3po::web {

// The columns `indices` of `cloud` (indices outside it are dropped: a stale
// result is not read), subsampled to `max_points`: an example's outliers.
PointSet OutlierPoints(const PointSet& cloud, const std::vector<int>& indices, int max_points);

// "<!doctype html> ... <body>" with `title` and the report stylesheet.
std::string ReportPageStart(const std::string& title);
// The "Examples in 3D" section: example buttons, layer toggles, the view.
std::string ReportViewsHtml(const std::vector<ReportView>& views);
// The views' data, three.js (only with views) and the view script, then "</html>".
std::string ReportPageEnd(const std::vector<ReportView>& views);

}  // namespace c3po::web
