// The page frame and the 3D example section shared by the report pages.
#include "report_views.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "embedded_resources.hpp"
#include "three_js.hpp"
#include "web_text.hpp"

namespace c3po::web {
namespace {

using nlohmann::json;

constexpr double kDegrees = 180.0 / M_PI;

json JsonNumber(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

// One example's data: little-endian float32 xyz, base64; unknown numbers null.
json ViewJson(const ReportView& v) {
  return {{"title", v.title},
          {"cloud", v.cloud},
          {"row", v.row},
          {"certified", v.certified},
          {"false_certificate", v.false_certificate},
          {"adds", JsonNumber(v.adds)},
          {"rotation_error_deg", JsonNumber(v.rotation_error * kDegrees)},
          {"oc_distance", JsonNumber(v.oc_distance)},
          {"input", PointsFloat32Base64(v.input)},
          {"outliers", PointsFloat32Base64(v.outliers)},
          {"posed_model", PointsFloat32Base64(v.posed_model)},
          {"truth_model", PointsFloat32Base64(v.truth_model)},
          {"refusal", v.refusal},
          {"truth_hausdorff", JsonNumber(v.truth_hausdorff)},
          {"rival_model", PointsFloat32Base64(v.rival_model)},
          {"keypoints", PointsFloat32Base64(v.keypoints)},
          {"detected_keypoints", PointsFloat32Base64(v.detected_keypoints)}};
}

}  // namespace

PointSet OutlierPoints(const PointSet& cloud, const std::vector<int>& indices, int max_points) {
  PointSet outliers(3, static_cast<Eigen::Index>(indices.size()));
  Eigen::Index kept = 0;
  for (int j : indices) {
    if (j >= 0 && j < cloud.cols()) outliers.col(kept++) = cloud.col(j);
  }
  return StridedColumns(outliers.leftCols(kept), max_points);
}

std::string ReportPageStart(const std::string& title) {
  std::ostringstream page;
  page << "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
       << "<link rel=\"icon\" href=\"data:,\">\n<title>" << HtmlEscape(title) << "</title>\n<style>\n"
       << resources::ReportCss() << "</style>\n</head>\n<body>\n";
  return page.str();
}

std::string ReportViewsHtml(const std::vector<ReportView>& views) {
  std::ostringstream out;
  out << "<section id=\"views\">\n<h2>Examples in 3D</h2>\n";
  if (views.empty()) {
    out << "<p class=\"note\">No examples to show.</p>\n</section>\n";
    return out.str();
  }
  out << "<p class=\"note\">Drag to orbit, wheel to zoom. Pick an example:</p>\n<div id=\"view-buttons\"></div>\n"
      << "<div class=\"legend\">"
      << "<span><label><input type=\"checkbox\" id=\"layer-input\" checked><span class=\"swatch\" "
         "style=\"background:#1f5fd6\"></span>input cloud</label></span>"
      << "<span><label><input type=\"checkbox\" id=\"layer-outliers\" checked><span class=\"swatch\" "
         "style=\"background:#e6194b\"></span>outliers (input points at &ge; &epsilon;<sub>oc</sub>)</label></span>"
      << "<span><label><input type=\"checkbox\" id=\"layer-posed\" checked><span class=\"swatch\" "
         "style=\"background:#2e8b57\"></span>posed model (red when rejected)</label></span>"
      << "<span><label><input type=\"checkbox\" id=\"layer-rival\" checked><span class=\"swatch\" "
         "style=\"background:#17becf\"></span>rival pose (a second explanation that refused it)</label></span>"
      << "<span><label><input type=\"checkbox\" id=\"layer-truth\"><span class=\"swatch\" "
         "style=\"background:#888\"></span>ground-truth posed model</label></span>"
      << "<span><label><input type=\"checkbox\" id=\"layer-keypoints\" checked><span class=\"swatch\" "
         "style=\"background:#f58231\"></span>output keypoints</label></span>"
      << "<span><label><input type=\"checkbox\" id=\"layer-detected\" checked><span class=\"swatch\" "
         "style=\"background:#911eb4\"></span>detected keypoints</label></span>"
      << "</div>\n<div id=\"view3d\"></div>\n<div id=\"view-info\"></div>\n</section>\n";
  return out.str();
}

std::string ReportPageEnd(const std::vector<ReportView>& views) {
  json data = json::array();
  for (const auto& view : views) data.push_back(ViewJson(view));
  std::ostringstream page;
  page << "<script type=\"text/plain\" id=\"c3po-three\">" << (views.empty() ? std::string() : ThreeJsForPage())
       << "</script>\n";
  page << "<script type=\"application/json\" id=\"c3po-views\">" << ScriptSafe(json{{"views", data}}.dump())
       << "</script>\n";
  page << "<script type=\"module\">\n" << resources::ReportViewJs() << "</script>\n</body>\n</html>\n";
  return page.str();
}

}  // namespace c3po::web
