// The certify report: counts by refusing part, settings, 3D examples.
#include "c3po/web/certify_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "c3po/base/atomic_file.hpp"
#include "c3po/method/refusal.hpp"
#include "report_views.hpp"
#include "web_text.hpp"

namespace c3po {
namespace {

using web::HtmlEscape;

// The name of the first refusing part (RefusedByNames), "" when certified.
std::string FirstRefusal(const CloudOutcome& outcome) {
  if (outcome.estimate.certified()) return "";
  const std::vector<std::string> names = RefusedByNames(outcome.estimate);
  return names.empty() ? "" : names.front();
}

// One row of the bar table: the bar's length is count / total.
void BarRow(std::ostringstream& out, const std::string& name, int first, const std::string& failed, int total,
            const char* colour) {
  const double percent = total > 0 ? 100.0 * first / total : 0.0;
  char width[32];
  std::snprintf(width, sizeof width, "%.1f", percent);
  out << "<tr><td>" << HtmlEscape(name) << "</td><td>" << first << "</td><td>" << failed << "</td><td>" << width
      << " %</td><td class=\"bar\"><span style=\"width:" << width << "%;background:" << colour
      << "\"></span></td></tr>\n";
}

std::string CountsHtml(const CertifyReportInput& input) {
  const CertifyBatchResult& result = *input.result;
  const int total = static_cast<int>(result.outcomes.size());
  std::ostringstream out;
  out << "<section id=\"summary\">\n<h2>Certified and refused</h2>\n<p><b id=\"certified-count\">" << result.certified
      << "</b> of " << total << " poses certified. A refused pose is counted once under the first certificate part "
      << "that refused it (the order in which they are decided); \"failed\" counts every pose the part refused "
      << "(docs/method.md \"Why a pose was refused\").</p>\n"
      << "<table id=\"refusals\">\n<thead><tr><th>outcome</th><th>poses</th><th>failed</th><th>share</th>"
      << "<th></th></tr></thead>\n<tbody>\n";
  BarRow(out, "certified", result.certified, "-", total, "#2e8b57");
  for (const RefusalCount& count : CountRefusals(result.outcomes)) {
    if (count.failed == 0) continue;
    BarRow(out, "refused by " + count.name, count.first, std::to_string(count.failed), total, "#d04040");
  }
  if (result.errors > 0) BarRow(out, "error (unreadable input or detector failure)", result.errors, "-", total, "#888");
  out << "</tbody>\n</table>\n<p class=\"settings\">" << HtmlEscape(input.settings) << "</p>\n</section>\n";
  return out.str();
}

}  // namespace

std::vector<std::size_t> SelectCertifyExamples(const std::vector<CloudOutcome>& outcomes, int certified,
                                               int rejected) {
  if (certified < 0 || rejected < 0) throw std::invalid_argument("SelectCertifyExamples: counts must be >= 0");
  std::vector<std::size_t> chosen, refused;
  for (std::size_t i = 0; i < outcomes.size(); ++i) {
    if (!outcomes[i].processed()) continue;
    if (outcomes[i].certified()) {
      if (static_cast<int>(chosen.size()) < certified) chosen.push_back(i);
    } else {
      refused.push_back(i);
    }
  }
  // One of each first refusing part, in the parts' order, then the rest in source order.
  std::vector<std::size_t> ordered;
  for (const RefusalCount& count : CountRefusals(outcomes)) {
    const auto first = std::find_if(refused.begin(), refused.end(),
                                    [&](std::size_t i) { return FirstRefusal(outcomes[i]) == count.name; });
    if (first != refused.end()) ordered.push_back(*first);
  }
  for (std::size_t i : refused) {
    if (std::find(ordered.begin(), ordered.end(), i) == ordered.end()) ordered.push_back(i);
  }
  if (static_cast<int>(ordered.size()) > rejected) ordered.resize(static_cast<std::size_t>(rejected));
  chosen.insert(chosen.end(), ordered.begin(), ordered.end());
  return chosen;
}

std::vector<ReportView> CertifyReportViews(const ObjectModel& object, const std::vector<CloudSource>& sources,
                                           const CertifyBatchResult& result, const ReportViewOptions& options) {
  options.Check();
  if (sources.size() != result.outcomes.size()) {
    throw std::invalid_argument("CertifyReportViews: one outcome per source required");
  }
  const PointSet model = StridedColumns(object.sample(), options.max_points);
  std::vector<ReportView> views;
  for (const std::size_t i : SelectCertifyExamples(result.outcomes, options.certified, options.rejected)) {
    const CloudSource& source = sources[i];
    const CloudOutcome& outcome = result.outcomes[i];
    PointSet cloud;
    try {
      std::optional<PointSet> evidence;   // outlier indices refer to the certificate's cloud
      cloud = LoadSourceCloud(source, nullptr, nullptr, &evidence);
      if (evidence) cloud = std::move(*evidence);
    } catch (const std::exception&) {
      continue;
    }
    const PoseEstimate& e = outcome.estimate;
    ReportView view;
    view.cloud = source.name;
    view.certified = e.certified();
    view.title = std::string(view.certified ? "certified" : "rejected") + ": " + source.name;
    view.adds = view.rotation_error = std::numeric_limits<double>::quiet_NaN();
    view.oc_distance = e.certificate.oc.max_point_distance;
    if (outcome.truth_hausdorff) view.truth_hausdorff = *outcome.truth_hausdorff;
    view.input = StridedColumns(cloud, options.max_points);
    view.outliers = web::OutlierPoints(cloud, e.certificate.oc.outlier_indices, options.max_points);
    view.posed_model = e.scene_from_model * model;
    if (source.scene_from_model_truth) view.truth_model = *source.scene_from_model_truth * model;
    view.keypoints = e.keypoints;
    view.detected_keypoints = outcome.detected_keypoints;
    view.refusal = e.ok() ? RefusalSummary(e.certificate) : std::string("registration failed");
    const NonDegeneracy& nd = e.certificate.nd;
    if (nd.global_checked && !nd.global.passed && nd.global.rival_axis >= 0) {
      view.rival_model = nd.global.rival_scene_from_model * model;
    }
    views.push_back(std::move(view));
  }
  return views;
}

std::string CertifyReportHtml(const CertifyReportInput& input) {
  if (!input.result) throw std::invalid_argument("CertifyReportHtml: no result");
  std::ostringstream page;
  page << web::ReportPageStart(input.title + ": " + input.object_name);
  char diameter[32];
  std::snprintf(diameter, sizeof diameter, "%.4g", input.diameter);
  page << "<h1>" << HtmlEscape(input.title) << ": " << HtmlEscape(input.object_name) << "</h1>\n<p class=\"meta\">"
       << HtmlEscape(input.inputs) << ", " << input.result->outcomes.size() << " poses, object diameter d = "
       << diameter << ".";
  if (!input.command_line.empty()) page << "<br>Command: <code>" << HtmlEscape(input.command_line) << "</code>";
  page << "</p>\n" << CountsHtml(input) << web::ReportViewsHtml(input.views) << web::ReportPageEnd(input.views);
  return page.str();
}

void WriteCertifyReport(const std::string& path, const CertifyReportInput& input) {
  WriteFileAtomically(path, CertifyReportHtml(input));
}

}  // namespace c3po
