// Text table and JSON document of an evaluation.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "c3po/base/json.hpp"
#include "c3po/eval/evaluation.hpp"

namespace c3po {
namespace {

using nlohmann::json;

constexpr double kDegrees = 180.0 / M_PI;

json Number(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

std::string Format(const char* format, double value) {
  if (!std::isfinite(value)) return std::isnan(value) ? "-" : "inf";
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

std::string PadLeft(const std::string& text, std::size_t width) {
  return text.size() >= width ? text : std::string(width - text.size(), ' ') + text;
}

std::string PadRight(const std::string& text, std::size_t width) {
  return text.size() >= width ? text : text + std::string(width - text.size(), ' ');
}

std::vector<std::string> TableCells(const EvaluationRow& row) {
  const RowSummary& s = row.summary;
  return {row.label,
          std::to_string(s.n),
          Format("%.1f", s.adds_score),
          Format("%.1f", s.adds_auc),
          Format("%.2f", s.median_rotation_error * kDegrees),
          Format("%.4f", s.median_translation_error_over_d),
          Format("%.1f", s.percent_oc),
          Format("%.1f", s.percent_nd),
          Format("%.1f", s.percent_certified),
          std::to_string(s.false_certificates)};
}

std::string Percent(double absolute, double diameter) {
  char text[64];
  std::snprintf(text, sizeof text, "%.3g %% of d", 100.0 * absolute / diameter);
  return text;
}

std::string SettingsLines(const Evaluation& e) {
  const EvaluationOptions& o = e.options;
  std::ostringstream out;
  out << "Columns: ADD-S % = threshold score, AUC = ADD-S AUC (0..100), rot err and t err / d = medians, "
         "% oc / % nd / % cert = certificate rates, false cert = certified with ADD-S >= threshold.\n";
  if (!o.symmetries.empty()) {
    out << "Rotation and translation errors: to the nearest of the truth and its " << o.symmetries.size()
        << " symmetric pose" << (o.symmetries.size() == 1 ? "" : "s") << " (the object's symmetries).\n";
  }
  char line[512];
  std::snprintf(line, sizeof line,
                "ADD-S variant: %s. Threshold score: ADD-S < %.6g (%s); AUC on [0, %.6g] (%s); d = %.6g.\n",
                ToString(o.adds_variant), o.adds_threshold, Percent(o.adds_threshold, e.diameter).c_str(),
                o.auc_max, Percent(o.auc_max, e.diameter).c_str(), e.diameter);
  out << line;
  std::snprintf(line, sizeof line,
                "Certificates: eps_oc = %.6g (%s), delta_nd = %.6g (%s), outlier budget m = %s, local nd %s; "
                "corrector %s solver, %s loss, robust kernel %s; re-estimation %s.\n",
                o.pipeline.certificate.eps_oc, Percent(o.pipeline.certificate.eps_oc, e.diameter).c_str(),
                o.pipeline.certificate.delta_nd, Percent(o.pipeline.certificate.delta_nd, e.diameter).c_str(),
                o.pipeline.certificate.max_outliers.ToString().c_str(),
                o.pipeline.certificate.local_nondegeneracy
                    ? (">= " + std::to_string(o.pipeline.certificate.local.min_eigenvalue)).c_str() : "off",
                ToString(o.pipeline.corrector.solver), ToString(o.pipeline.corrector.loss),
                ToString(o.pipeline.corrector.robust_loss), o.pipeline.certificate.global.reestimate ? "on" : "off");
  out << line;
  return out.str();
}

std::string SoundnessLines(const Evaluation& e) {
  std::ostringstream out;
  out << "Soundness: " << e.total_false_certificates()
      << " false certificates (certified outputs with ADD-S >= " << Format("%.6g", e.options.adds_threshold)
      << ") over all rows.\n";
  for (const auto& row : e.rows) {
    if (row.subset != EvalSubset::kAll || row.summary.false_certificates == 0) continue;
    out << "  " << row.label << ": " << row.summary.false_certificates << " of "
        << row.summary.certified << " certified; worst:";
    for (const auto& f : row.summary.worst_false_certificates) {
      out << " " << f.cloud << " (ADD-S " << Format("%.4g", f.adds) << ", rot "
          << Format("%.1f", f.rotation_error * kDegrees) << " deg)";
    }
    out << "\n";
  }
  out << "Hausdorff check: " << e.total_false_certificates_hausdorff() << " certified outputs over all rows with a Hausdorff distance >= "
      << Format("%.6g", e.options.adds_threshold) << " between the model posed at the truth and at the estimate.\n";
  for (const auto& row : e.rows) {
    if (row.subset != EvalSubset::kAll || row.summary.false_certificates_hausdorff == 0) continue;
    out << "  " << row.label << ": " << row.summary.false_certificates_hausdorff << " of " << row.summary.certified
        << " certified; largest Hausdorff " << Format("%.4g", row.summary.max_certified_hausdorff) << "\n";
  }
  return out.str();
}

// Rows with samples that have no pose (unreadable cloud, detector failure,
// degenerate keypoints): how many, and the first reason.
std::string FailureLines(const Evaluation& e) {
  std::ostringstream out;
  for (const auto& row : e.rows) {
    if (row.subset != EvalSubset::kAll || row.summary.failures == 0) continue;
    const auto first = std::find_if(row.samples.begin(), row.samples.end(),
                                    [](const SampleResult& s) { return !s.ok(); });
    out << "Failures: " << row.label << ": " << row.summary.failures << " of " << row.summary.n
        << " samples without a pose (counted as ADD-S = inf, not certified); first: " << first->cloud << ": "
        << first->error << "\n";
  }
  return out.str();
}

json SampleJson(const SampleResult& s) {
  json j;
  j["cloud"] = s.cloud;
  j["index"] = s.index;
  if (!s.ok()) j["error"] = s.error;
  j["adds"] = Number(s.adds);
  j["rotation_error_deg"] = Number(s.rotation_error * kDegrees);
  j["translation_error"] = Number(s.translation_error);
  j["oc"] = s.oc;
  j["nd"] = s.nd;
  j["free_space"] = s.free_space;
  j["certified"] = s.certified();
  j["oc_distance"] = Number(s.oc_distance);
  if (s.certified()) j["hausdorff"] = Number(s.hausdorff);
  j["ms"] = s.milliseconds;
  if (s.ok()) {
    const Pose& T = s.scene_from_model;
    SetPoseJson(T, &j);
  }
  return j;
}

json SummaryJson(const RowSummary& s, double diameter) {
  json j;
  j["n"] = s.n;
  j["failures"] = s.failures;
  j["adds_score"] = Number(s.adds_score);
  j["adds_auc"] = Number(s.adds_auc);
  j["median_adds"] = Number(s.median_adds);
  j["median_rotation_error_deg"] = Number(s.median_rotation_error * kDegrees);
  j["median_translation_error"] = Number(s.median_translation_error);
  j["median_translation_error_over_d"] = Number(s.median_translation_error / diameter);
  j["percent_oc"] = Number(s.percent_oc);
  j["percent_nd"] = Number(s.percent_nd);
  j["percent_certified"] = Number(s.percent_certified);
  j["certified"] = s.certified;
  j["false_certificates"] = s.false_certificates;
  j["false_certificates_hausdorff"] = s.false_certificates_hausdorff;
  j["max_certified_hausdorff"] = Number(s.max_certified_hausdorff);
  json worst = json::array();
  for (const auto& f : s.worst_false_certificates) {
    worst.push_back({{"cloud", f.cloud}, {"index", f.index}, {"adds", Number(f.adds)},
                     {"rotation_error_deg", Number(f.rotation_error * kDegrees)},
                     {"translation_error", Number(f.translation_error)}});
  }
  j["worst_false_certificates"] = worst;
  return j;
}


// Mixed datasets: per detector and object label, the clouds accepted by
// detector + corrector + certificates.
std::string ObjectLines(const Evaluation& e) {
  if (e.objects.empty()) return "";
  std::ostringstream out;
  out << "Mixed dataset: clouds accepted (certified) by detector + corrector + certificates of " << e.object_name
      << ", per object:\n";
  for (const ObjectAcceptance& a : e.objects) {
    out << "  " << a.detector << ": " << a.object << (a.evaluated_object ? " (this object)" : "") << " "
        << a.certified << " of " << a.clouds << " accepted (oc " << a.observably_correct;
    if (a.failures > 0) out << ", " << a.failures << " without a pose";
    out << ")";
    if (!a.evaluated_object && a.clouds > 0) {
      out << ", rejected " << Format("%.1f", 100.0 * (a.clouds - a.certified) / a.clouds) << " %";
    }
    out << "\n";
  }
  out << "Other objects' clouds accepted: " << e.other_objects_accepted() << "\n";
  return out.str();
}

}  // namespace

std::string EvaluationTable(const Evaluation& e) {
  const std::vector<std::string> header = {"Method", "n", "ADD-S %", "AUC", "rot err (deg)", "t err / d",
                                           "% oc", "% nd", "% cert", "false cert"};
  std::vector<std::vector<std::string>> cells = {header};
  for (const auto& row : e.rows) cells.push_back(TableCells(row));
  std::vector<std::size_t> width(header.size(), 0);
  for (const auto& line : cells) {
    for (std::size_t c = 0; c < line.size(); ++c) width[c] = std::max(width[c], line[c].size());
  }
  std::ostringstream out;
  out << e.object_name << " on " << e.dataset_dir << " (" << e.clouds << " clouds)\n";
  for (std::size_t r = 0; r < cells.size(); ++r) {
    for (std::size_t c = 0; c < cells[r].size(); ++c) {
      out << (c == 0 ? PadRight(cells[r][c], width[c]) : "  " + PadLeft(cells[r][c], width[c]));
    }
    out << "\n";
    if (r == 0) {
      std::size_t total = 0;
      for (std::size_t w : width) total += w + 2;
      out << std::string(total - 2, '-') << "\n";
    }
  }
  out << SettingsLines(e) << FailureLines(e) << SoundnessLines(e) << ObjectLines(e);
  return out.str();
}

std::string EvaluationJson(const Evaluation& e) {
  const EvaluationOptions& o = e.options;
  json j;
  j["object"] = e.object_name;
  j["dataset"] = e.dataset_dir;
  j["clouds"] = e.clouds;
  j["diameter"] = e.diameter;
  j["adds_variant"] = ToString(o.adds_variant);
  j["symmetries"] = o.symmetries.size();
  j["adds_threshold"] = o.adds_threshold;
  j["adds_threshold_fraction_of_d"] = o.adds_threshold / e.diameter;
  j["auc_max"] = o.auc_max;
  j["auc_max_fraction_of_d"] = o.auc_max / e.diameter;
  j["eps_oc"] = o.pipeline.certificate.eps_oc;
  j["delta_nd"] = o.pipeline.certificate.delta_nd;
  j["corrector"] = {{"solver", ToString(o.pipeline.corrector.solver)},
                    {"loss", ToString(o.pipeline.corrector.loss)},
                    {"kappa", o.pipeline.corrector.kappa},
                    {"theta", o.pipeline.corrector.theta}};
  j["icp"] = {{"enabled", o.run_icp},
              {"max_iterations", o.icp.max_iterations},
              {"max_correspondence_distance", Number(o.icp.max_correspondence_distance)},
              {"trim_fraction", o.icp.trim_fraction}};
  j["false_certificates"] = e.total_false_certificates();
  j["false_certificates_hausdorff"] = e.total_false_certificates_hausdorff();
  json rows = json::array();
  for (const auto& row : e.rows) {
    json r;
    r["label"] = row.label;
    r["detector"] = row.detector;
    r["method"] = ToString(row.method);
    r["subset"] = ToString(row.subset);
    r["summary"] = SummaryJson(row.summary, e.diameter);
    if (row.subset == EvalSubset::kAll) {
      json samples = json::array();
      for (const auto& s : row.samples) samples.push_back(SampleJson(s));
      r["samples"] = samples;
    }
    rows.push_back(r);
  }
  j["rows"] = rows;
  if (!e.objects.empty()) {
    json objects = json::array();
    for (const ObjectAcceptance& a : e.objects) {
      objects.push_back({{"detector", a.detector}, {"object", a.object}, {"evaluated_object", a.evaluated_object},
                         {"clouds", a.clouds}, {"failures", a.failures},
                         {"observably_correct", a.observably_correct}, {"certified", a.certified}});
    }
    j["objects"] = objects;
    j["other_objects_accepted"] = e.other_objects_accepted();
  }
  return j.dump(1) + "\n";
}

}  // namespace c3po
