#pragma once
// The evaluation report (`c3po eval --report report.html`): ONE self-contained
// HTML file, no network access when opened. It holds
//   - the results table (id "results") with the settings used (ADD-S variant,
//     thresholds, certificate thresholds) and the soundness figure (false
//     certificates, worst ones listed);
//   - ADD-S distribution plots (accuracy-vs-threshold curve of every row, and
//     a histogram per row) as inline SVG;
//   - training curves (loss and % certified per epoch) from training logs, as
//     inline SVG;
//   - an interactive 3D view (three.js, the copy embedded for the annotation
//     page; drag to orbit, wheel to zoom) of a few certified and a few
//     rejected examples: input cloud, its outliers under the estimate (points
//     at >= eps_oc, which oc_m tolerates up to the budget m) in another
//     colour, posed model sample, ground-truth posed model sample, detected
//     and output keypoints; for a rejected example, why (the failed parts
//     and their evidence) and, when a rival pose explains the points too,
//     that pose's model sample.
// Test hooks: document.body.dataset.ready = "1" once the page has set up,
// window.c3poReport = {views (count), webgl (bool), shown (index), show(i),
// frames (renders so far), orbit ({theta, phi, distance}), measure (set true
// to make each render count into `coloured` the non-background pixels)}.
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "c3po/eval/evaluation.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

// One training log: JSON lines, one object per epoch with numeric fields
// (e.g. epoch, train_loss, val_loss, val_keypoint_error, oc_train, oc_val).
// Fields named *loss* or *error* are plotted as losses; fields named
// *percent*, oc*, nd*, *_oc, *_nd or *certified as percentages (without
// "percent" in the name and every value in [0, 1]: fractions, scaled by 100).
// The logs of `c3po train` / `c3po selftrain` (MODEL.log.jsonl) qualify.
struct TrainingLog {
  std::string label;
  std::string path;
  std::vector<std::map<std::string, double>> epochs;   // numeric fields of each line
};
// Throws InputError("path: line N: problem") for an unreadable file or a line
// that is not a JSON object; non-numeric fields are ignored.
TrainingLog ReadTrainingLog(const std::string& path, const std::string& label);

// One example for the 3D view.
struct ReportView {
  std::string title;            // "certified: 000012.ply"
  std::string cloud;
  std::string row;              // row label the estimate comes from
  bool certified = false;
  bool false_certificate = false;
  double adds = 0.0;
  double rotation_error = 0.0;  // radians
  double oc_distance = 0.0;
  // Hausdorff(T*·B̂, T̂·B̂) when known (eval: certified samples; certify: sources with a truth), else NaN.
  double truth_hausdorff = std::numeric_limits<double>::quiet_NaN();
  PointSet input;               // the input cloud (subsampled)
  PointSet outliers;            // its points at >= eps_oc from T̂·B̂ (subsampled)
  PointSet posed_model;         // T̂·B̂ (subsampled)
  PointSet truth_model;         // T*·B̂ (subsampled)
  std::string refusal;          // rejected: the failed parts and their evidence (RefusalSummary)
  PointSet rival_model;         // rejected by nd's rival search: the rival pose T'·B̂ (subsampled), else empty
  PointSet keypoints;           // output keypoints
  PointSet detected_keypoints;  // ỹ
};

struct ReportViewOptions {
  int certified = 3;            // certified examples (false certificates first)
  int rejected = 3;             // rejected examples
  int max_points = 1500;        // per point set, by a deterministic stride
  void Check() const;
};

// Picks examples with a pose from `row`: false certificates (ADD-S or
// Hausdorff distance >= adds_threshold, SampleResult::false_certificate)
// first, worst ADD-S first, then certified ones in dataset order;
// rejected ones in dataset order. Reloads their clouds (unreadable ones are
// skipped).
std::vector<ReportView> SelectReportViews(const ObjectModel& object, const Dataset& dataset,
                                          const EvaluationRow& row, double adds_threshold,
                                          const ReportViewOptions& options = {});

struct ReportInput {
  std::string title = "c3po evaluation";
  const Evaluation* evaluation = nullptr;   // required
  std::vector<TrainingLog> training;
  std::vector<ReportView> views;
  std::string command_line;                 // shown verbatim, may be empty
};

std::string ReportHtml(const ReportInput& input);
// Writes ReportHtml atomically.
void WriteReport(const std::string& path, const ReportInput& input);

}  // namespace c3po
