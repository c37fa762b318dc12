#pragma once
// The certify report (`c3po certify --report report.html`): ONE
// self-contained HTML page for a certify run, no ground truth needed:
//   - the counts as a bar table (id "refusals"): certified poses, and for
//     every certificate part the poses it refused first and the poses it
//     failed (method/refusal.hpp), registration failures, unreadable inputs;
//   - the settings the decisions used;
//   - the 3D examples of the evaluation report (report.hpp): certified and
//     rejected poses with the input cloud, its outliers, the posed model,
//     the rival pose that refused one, the reason, and the ground-truth
//     posed model and Hausdorff distance when the source has a truth (BOP).
// The page's test hooks are the evaluation report's.
#include <string>
#include <vector>

#include "c3po/method/certify_batch.hpp"
#include "c3po/object/object_model.hpp"
#include "c3po/web/report.hpp"

namespace c3po {

// Source indices of the examples: the first `certified` certified outcomes in
// source order; then `rejected` processed, uncertified ones: first, in source
// order, the first pose refused first by each part (registration, then the
// parts' order), so different reasons are shown; then the rest in source
// order.
std::vector<std::size_t> SelectCertifyExamples(const std::vector<CloudOutcome>& outcomes, int certified,
                                               int rejected);

// The examples (SelectCertifyExamples with the options' counts), each cloud
// read again from its source (deterministic: the same points the batch
// certified); sources that cannot be read again are skipped.
std::vector<ReportView> CertifyReportViews(const ObjectModel& object, const std::vector<CloudSource>& sources,
                                           const CertifyBatchResult& result, const ReportViewOptions& options = {});

struct CertifyReportInput {
  std::string title = "c3po certify";
  std::string object_name;
  double diameter = 0.0;
  std::string inputs;                           // what was certified, e.g. "BOP folder ..., obj_id 10"
  std::string settings;                         // the thresholds (certify's summary line)
  std::string command_line;                     // shown verbatim, may be empty
  const CertifyBatchResult* result = nullptr;   // required
  std::vector<ReportView> views;
};

std::string CertifyReportHtml(const CertifyReportInput& input);
// Writes CertifyReportHtml atomically.
void WriteCertifyReport(const std::string& path, const CertifyReportInput& input);

}  // namespace c3po
