// The self-contained evaluation report: table, soundness, ADD-S plots,
// training curves (inline SVG) and the 3D example view (embedded three.js).
#include "c3po/web/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "report_svg.hpp"
#include "report_views.hpp"
#include "web_text.hpp"

namespace c3po {
namespace {

using nlohmann::json;
using web::HtmlEscape;

constexpr double kDegrees = 180.0 / M_PI;
const char* const kPalette[] = {"#4363d8", "#e6194b", "#3cb44b", "#f58231", "#911eb4", "#42d4f4",
                                "#f032e6", "#9a6324", "#469990", "#800000", "#000075", "#808000"};

std::string Colour(std::size_t i) { return kPalette[i % (sizeof kPalette / sizeof kPalette[0])]; }

std::string Number(const char* format, double value) {
  if (!std::isfinite(value)) return std::isnan(value) ? "-" : "inf";
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

// ---- page sections ----

std::string Percent(double absolute, double diameter) {
  return Number("%.3g", 100.0 * absolute / diameter) + " % of d";
}

std::string SettingsHtml(const Evaluation& e) {
  const EvaluationOptions& o = e.options;
  std::ostringstream out;
  out << "<p class=\"settings\" id=\"settings\">ADD-S variant: <b>" << ToString(o.adds_variant) << "</b>"
      << (o.adds_variant == AddSVariant::kSymmetric
              ? " (mean distance GT-posed to estimate-posed model sample plus the reverse direction)"
              : " (mean distance from the GT-posed model sample to the estimate-posed one)")
      << ". ADD-S score: % of samples with ADD-S &lt; " << Number("%.4g", o.adds_threshold) << " ("
      << Percent(o.adds_threshold, e.diameter) << "); AUC of the accuracy curve on [0, "
      << Number("%.4g", o.auc_max) << "] (" << Percent(o.auc_max, e.diameter) << "), 0..100. d = "
      << Number("%.4g", e.diameter) << ". Certificates: &epsilon;<sub>oc</sub> = "
      << Number("%.4g", o.pipeline.certificate.eps_oc) << " (" << Percent(o.pipeline.certificate.eps_oc, e.diameter)
      << "), &delta;<sub>nd</sub> = " << Number("%.4g", o.pipeline.certificate.delta_nd) << " ("
      << Percent(o.pipeline.certificate.delta_nd, e.diameter) << "). Corrector: "
      << ToString(o.pipeline.corrector.solver) << " solver, " << ToString(o.pipeline.corrector.loss)
      << " point-cloud loss. Rotation and translation errors are medians; t / d is the translation error "
         "divided by d.</p>\n";
  return out.str();
}

std::string TableHtml(const Evaluation& e) {
  std::ostringstream out;
  out << "<table id=\"results\">\n<thead><tr><th>Method</th><th>n</th><th>ADD-S % (&lt; "
      << Number("%.3g", e.options.adds_threshold) << ")</th><th>ADD-S AUC</th><th>rot. error (deg)</th>"
      << "<th>t error / d</th><th>% oc</th><th>% nd</th><th>% certified</th><th>false cert.</th></tr></thead>\n<tbody>\n";
  for (const auto& row : e.rows) {
    const RowSummary& s = row.summary;
    out << "<tr" << (row.subset != EvalSubset::kAll ? " class=\"subset\"" : "") << "><td>" << HtmlEscape(row.label)
        << "</td><td>" << s.n << "</td><td>" << Number("%.1f", s.adds_score) << "</td><td>"
        << Number("%.1f", s.adds_auc) << "</td><td>" << Number("%.2f", s.median_rotation_error * kDegrees)
        << "</td><td>" << Number("%.4f", s.median_translation_error_over_d) << "</td><td>"
        << Number("%.1f", s.percent_oc) << "</td><td>" << Number("%.1f", s.percent_nd) << "</td><td>"
        << Number("%.1f", s.percent_certified) << "</td><td" << (s.false_certificates > 0 ? " class=\"bad\"" : "")
        << ">" << s.false_certificates << "</td></tr>\n";
  }
  out << "</tbody>\n</table>\n";
  return out.str();
}

std::string SoundnessHtml(const Evaluation& e) {
  const int total = e.total_false_certificates();
  const int hausdorff_total = e.total_false_certificates_hausdorff();
  std::ostringstream out;
  out << "<section id=\"soundness\" class=\"" << (total == 0 && hausdorff_total == 0 ? "sound" : "unsound")
      << "\">\n<h2>Soundness</h2>\n"
      << "<p><b id=\"false-certificates\">" << total << "</b> false certificate" << (total == 1 ? "" : "s")
      << ": certified outputs whose ADD-S is not below the threshold " << Number("%.4g", e.options.adds_threshold)
      << " (" << ToString(e.options.adds_variant) << " ADD-S), over every method on all "
      << e.clouds << " clouds.</p>\n";
  for (const auto& row : e.rows) {
    if (row.subset != EvalSubset::kAll || row.summary.false_certificates == 0) continue;
    out << "<p>" << HtmlEscape(row.label) << ": " << row.summary.false_certificates << " of "
        << row.summary.certified << " certified. Worst:</p>\n<ul>\n";
    for (const auto& f : row.summary.worst_false_certificates) {
      out << "<li><code>" << HtmlEscape(f.cloud) << "</code>: ADD-S " << Number("%.4g", f.adds) << ", rotation error "
          << Number("%.1f", f.rotation_error * kDegrees) << " deg, translation error "
          << Number("%.4g", f.translation_error) << "</li>\n";
    }
    out << "</ul>\n";
  }
  out << "<p><b id=\"false-certificates-hausdorff\">" << hausdorff_total << "</b> certified output"
      << (hausdorff_total == 1 ? "" : "s") << " with a Hausdorff distance not below "
      << Number("%.4g", e.options.adds_threshold)
      << " between the model posed at the truth and at the estimate (symmetries cost nothing).</p>\n";
  for (const auto& row : e.rows) {
    if (row.subset != EvalSubset::kAll || row.summary.false_certificates_hausdorff == 0) continue;
    out << "<p>" << HtmlEscape(row.label) << ": " << row.summary.false_certificates_hausdorff << " of "
        << row.summary.certified << " certified; largest Hausdorff "
        << Number("%.4g", row.summary.max_certified_hausdorff) << ".</p>\n";
  }
  out << "</section>\n";
  return out.str();
}

std::vector<double> AddsOf(const std::vector<SampleResult>& samples, int certified) {
  std::vector<double> values;
  for (const auto& s : samples) {
    if (certified < 0 || s.certified() == (certified == 1)) values.push_back(s.adds);
  }
  return values;
}

// Accuracy-vs-threshold curve: the fraction of samples with ADD-S < x, a step function.
svg::Series AccuracyCurve(const EvaluationRow& row, const std::string& colour, double x_max) {
  svg::Series series;
  series.name = row.label;
  series.colour = colour;
  series.dashed = row.subset != EvalSubset::kAll;
  std::vector<double> adds = AddsOf(row.samples, -1);
  std::sort(adds.begin(), adds.end());
  const double n = static_cast<double>(adds.size());
  series.points.push_back({0.0, 0.0});
  for (std::size_t k = 0; k < adds.size() && adds[k] <= x_max; ++k) {
    series.points.push_back({adds[k], 100.0 * k / n});
    series.points.push_back({adds[k], 100.0 * (k + 1) / n});
  }
  const double final = 100.0 * std::count_if(adds.begin(), adds.end(), [&](double a) { return a <= x_max; }) / n;
  series.points.push_back({x_max, final});
  return series;
}

std::string AddsPlotsHtml(const Evaluation& e) {
  const double x_max = 2.0 * std::max(e.options.auc_max, e.options.adds_threshold);
  const std::vector<svg::Marker> markers = {{e.options.adds_threshold, "threshold"},
                                            {e.options.auc_max, "AUC max"}};
  svg::LineChart chart;
  chart.title = "Accuracy vs ADD-S threshold (" + std::string(ToString(e.options.adds_variant)) + " ADD-S)";
  chart.x_label = "ADD-S threshold (object units)";
  chart.y_label = "% of samples with ADD-S < threshold";
  chart.x_max = x_max;
  chart.y_max = 100.0;
  chart.markers = markers;
  chart.width = 900;
  chart.height = 360;
  for (std::size_t r = 0; r < e.rows.size(); ++r) {
    if (!e.rows[r].samples.empty()) chart.series.push_back(AccuracyCurve(e.rows[r], Colour(r), x_max));
  }
  std::ostringstream out;
  out << "<section id=\"adds-plots\">\n<h2>ADD-S distribution</h2>\n" << svg::Render(chart)
      << "<p class=\"note\">Histograms of ADD-S per method on all clouds: certified samples (green) stacked "
         "under rejected ones (grey); the last bar holds every ADD-S &ge; "
      << Number("%.3g", x_max) << " and failures.</p>\n<div class=\"charts\">\n";
  for (const auto& row : e.rows) {
    if (row.subset != EvalSubset::kAll) continue;
    svg::Histogram h;
    h.title = row.label;
    h.x_label = "ADD-S";
    h.x_max = x_max;
    h.markers = {markers[0]};
    h.first = AddsOf(row.samples, 1);
    h.second = AddsOf(row.samples, 0);
    h.first_name = "certified";
    h.second_name = "not certified";
    out << svg::Render(h);
  }
  out << "</div>\n</section>\n";
  return out.str();
}

// Losses, errors, and self-training's fit residual quantiles and Hausdorff
// distances (one chart; log scale when the ranges differ).
bool IsLossField(const std::string& name) {
  return name.find("loss") != std::string::npos || name.find("error") != std::string::npos ||
         name.find("residual") != std::string::npos || name.find("hausdorff") != std::string::npos;
}
bool EndsWith(const std::string& name, const std::string& suffix) {
  return name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}
// "validation_percent_oc", "oc_val", "train_oc", "validation_percent_certified"
// (not "certified_samples", a count).
bool IsPercentField(const std::string& name) {
  return name.find("percent") != std::string::npos || name.rfind("oc", 0) == 0 || name.rfind("nd", 0) == 0 ||
         EndsWith(name, "_oc") || EndsWith(name, "_nd") || EndsWith(name, "certified");
}
// Sample counts of self-training: "certified_samples", "ambiguous_skipped",
// "symmetric_trained", "labelling_switched", "validation_ambiguous".
bool IsCountField(const std::string& name) {
  return EndsWith(name, "_samples") || EndsWith(name, "_skipped") || EndsWith(name, "_trained") ||
         EndsWith(name, "_switched") || name == "validation_ambiguous";
}

enum class ChartKind { kLoss, kPercent, kCount };

bool Selects(ChartKind kind, const std::string& name) {
  switch (kind) {
    case ChartKind::kLoss: return IsLossField(name);
    case ChartKind::kPercent: return IsPercentField(name);
    case ChartKind::kCount: return IsCountField(name);
  }
  return false;
}

std::string ChartTitle(ChartKind kind) {
  switch (kind) {
    case ChartKind::kLoss: return ": loss per epoch";
    case ChartKind::kPercent: return ": certified / observably correct per epoch";
    case ChartKind::kCount: return ": samples per epoch (certified, ambiguous skipped, symmetric)";
  }
  return "";
}

// One chart of the fields of `kind`; percentages scaled to 0..100 when
// every value is a fraction.
std::string TrainingChart(const TrainingLog& log, ChartKind kind) {
  const bool percent = kind == ChartKind::kPercent;
  std::vector<std::string> fields;
  for (const auto& epoch : log.epochs) {
    for (const auto& [name, value] : epoch) {
      if (name == "epoch" || !Selects(kind, name)) continue;
      if (std::find(fields.begin(), fields.end(), name) == fields.end()) fields.push_back(name);
    }
  }
  if (fields.empty()) return "";
  svg::LineChart chart;
  chart.title = log.label + ChartTitle(kind);
  chart.x_label = "epoch";
  chart.y_label = percent ? "%" : kind == ChartKind::kCount ? "samples" : "value";
  double x_max = 1.0, y_low = INFINITY, y_high = -INFINITY;
  for (std::size_t f = 0; f < fields.size(); ++f) {
    svg::Series series;
    series.name = fields[f];
    series.colour = Colour(f);
    series.markers = log.epochs.size() <= 60;
    bool fractions = fields[f].find("percent") == std::string::npos;
    for (const auto& epoch : log.epochs) {
      auto it = epoch.find(fields[f]);
      if (it != epoch.end() && std::isfinite(it->second) && std::abs(it->second) > 1.0) fractions = false;
    }
    for (std::size_t k = 0; k < log.epochs.size(); ++k) {
      auto it = log.epochs[k].find(fields[f]);
      if (it == log.epochs[k].end() || !std::isfinite(it->second)) continue;
      auto x_it = log.epochs[k].find("epoch");
      const double x = x_it != log.epochs[k].end() ? x_it->second : static_cast<double>(k + 1);
      const double y = percent && fractions ? 100.0 * it->second : it->second;
      series.points.push_back({x, y});
      x_max = std::max(x_max, x);
      y_low = std::min(y_low, y);
      y_high = std::max(y_high, y);
    }
    chart.series.push_back(series);
  }
  chart.x_min = 0.0;
  chart.x_max = x_max;
  if (percent) {
    chart.y_min = 0.0;
    chart.y_max = 100.0;
  } else if (kind == ChartKind::kLoss && std::isfinite(y_low) && y_low > 0 && y_high / y_low > 20.0) {
    chart.log_y = true;
    chart.y_min = y_low;
    chart.y_max = y_high;
  } else {
    chart.y_min = std::isfinite(y_low) ? std::min(0.0, y_low) : 0.0;
    chart.y_max = std::isfinite(y_high) && y_high > chart.y_min ? y_high : chart.y_min + 1.0;
  }
  chart.width = 540;
  chart.height = 300;
  return svg::Render(chart);
}

std::string TrainingHtml(const std::vector<TrainingLog>& logs) {
  std::ostringstream out;
  out << "<section id=\"training\">\n<h2>Training curves</h2>\n";
  if (logs.empty()) out << "<p class=\"note\">No training logs given (<code>--training-log FILE</code>).</p>\n";
  for (const auto& log : logs) {
    out << "<h3>" << HtmlEscape(log.label) << " <span class=\"note\">(" << HtmlEscape(log.path) << ", "
        << log.epochs.size() << " epochs)</span></h3>\n<div class=\"charts\">\n"
        << TrainingChart(log, ChartKind::kLoss) << TrainingChart(log, ChartKind::kPercent)
        << TrainingChart(log, ChartKind::kCount) << "</div>\n";
  }
  out << "</section>\n";
  return out.str();
}

}  // namespace

TrainingLog ReadTrainingLog(const std::string& path, const std::string& label) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot read training log");
  TrainingLog log;
  log.label = label;
  log.path = path;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    json object = json::parse(line, nullptr, false);
    if (object.is_discarded() || !object.is_object()) {
      throw InputError(path, "line " + std::to_string(number) + ": not a JSON object");
    }
    std::map<std::string, double> epoch;
    for (const auto& [key, value] : object.items()) {
      if (value.is_number()) epoch[key] = value.get<double>();
    }
    log.epochs.push_back(std::move(epoch));
  }
  return log;
}

void ReportViewOptions::Check() const {
  if (certified < 0 || rejected < 0) throw std::invalid_argument("ReportViewOptions: counts must be >= 0");
  if (max_points < 1) throw std::invalid_argument("ReportViewOptions: max_points must be >= 1");
}

std::vector<ReportView> SelectReportViews(const ObjectModel& object, const Dataset& dataset,
                                          const EvaluationRow& row, double adds_threshold,
                                          const ReportViewOptions& options) {
  options.Check();
  std::vector<const SampleResult*> false_certified, certified, rejected;
  for (const auto& s : row.samples) {
    if (!s.ok()) continue;
    if (s.certified()) (s.false_certificate(adds_threshold) ? false_certified : certified).push_back(&s);
    else rejected.push_back(&s);
  }
  std::stable_sort(false_certified.begin(), false_certified.end(),
                   [](const SampleResult* a, const SampleResult* b) { return a->adds > b->adds; });
  certified.insert(certified.begin(), false_certified.begin(), false_certified.end());
  if (static_cast<int>(certified.size()) > options.certified) certified.resize(options.certified);
  if (static_cast<int>(rejected.size()) > options.rejected) rejected.resize(options.rejected);

  std::vector<ReportView> views;
  for (const auto* list : {&certified, &rejected}) {
    for (const SampleResult* s : *list) {
      PointSet cloud;
      try {
        cloud = dataset.LoadCloud(s->index);
      } catch (const std::exception&) {
        continue;
      }
      ReportView view;
      view.cloud = s->cloud;
      view.row = row.label;
      view.certified = s->certified();
      view.false_certificate = s->false_certificate(adds_threshold);
      view.title = std::string(view.false_certificate ? "FALSE certificate" : view.certified ? "certified" : "rejected") +
                   ": " + s->cloud;
      view.adds = s->adds;
      view.rotation_error = s->rotation_error;
      view.oc_distance = s->oc_distance;
      view.input = StridedColumns(cloud, options.max_points);
      view.outliers = web::OutlierPoints(cloud, s->outlier_indices, options.max_points);
      const PointSet model = StridedColumns(object.sample(), options.max_points);
      view.posed_model = s->scene_from_model * model;
      const auto& truth = dataset.entries[s->index].pose;
      if (truth) view.truth_model = *truth * model;
      view.refusal = s->refusal;
      view.truth_hausdorff = s->hausdorff;
      if (s->rival_scene_from_model) view.rival_model = *s->rival_scene_from_model * model;
      view.keypoints = s->keypoints;
      view.detected_keypoints = s->detected_keypoints;
      views.push_back(std::move(view));
    }
  }
  return views;
}

std::string ReportHtml(const ReportInput& input) {
  if (!input.evaluation) throw std::invalid_argument("ReportHtml: no evaluation");
  const Evaluation& e = *input.evaluation;
  std::ostringstream page;
  page << web::ReportPageStart(input.title + ": " + e.object_name);
  page << "<h1>" << HtmlEscape(input.title) << ": " << HtmlEscape(e.object_name) << "</h1>\n<p class=\"meta\">Dataset <code>"
       << HtmlEscape(e.dataset_dir) << "</code>, " << e.clouds << " clouds, object diameter d = "
       << Number("%.4g", e.diameter) << ".";
  if (!input.command_line.empty()) page << "<br>Command: <code>" << HtmlEscape(input.command_line) << "</code>";
  page << "</p>\n" << SoundnessHtml(e) << "<section id=\"table\">\n<h2>Results</h2>\n" << TableHtml(e)
       << SettingsHtml(e) << "</section>\n" << AddsPlotsHtml(e) << TrainingHtml(input.training)
       << web::ReportViewsHtml(input.views) << web::ReportPageEnd(input.views);
  return page.str();
}

void WriteReport(const std::string& path, const ReportInput& input) {
  WriteFileAtomically(path, ReportHtml(input));
}

}  // namespace c3po
