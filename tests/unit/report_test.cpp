// The HTML report: well-formed and self-contained, the table/soundness/plots
// agree with the evaluation, 3D view data decodes to the selected examples,
// training logs are read and plotted, and the file is written atomically.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <cstring>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/eval/evaluation.hpp"
#include "c3po/method/refusal.hpp"
#include "c3po/web/certify_report.hpp"
#include "c3po/web/report.hpp"
#include "evaluation_fixture.hpp"
#include "test_helpers.hpp"

using namespace c3po;
using namespace c3po::test;
namespace fs = std::filesystem;

namespace {

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// A small HTML checker: doctype first, every element closed in order (void
// elements and "/>" excepted), script/style bodies skipped, and no attribute
// src/href pointing anywhere but data: or the page itself. Returns "" when fine.
std::string CheckHtml(const std::string& html) {
  static const std::vector<std::string> kVoid = {"meta", "link", "br", "input", "img", "hr",
                                                 "area", "base", "col", "embed", "source", "wbr"};
  if (Lower(html.substr(0, 15)) != "<!doctype html>") return "no doctype";
  std::vector<std::string> open;
  std::size_t at = 15;
  while ((at = html.find('<', at)) != std::string::npos) {
    if (html.compare(at, 4, "<!--") == 0) {
      at = html.find("-->", at);
      if (at == std::string::npos) return "unterminated comment";
      continue;
    }
    std::size_t end = at + 1;
    char quote = 0;
    for (; end < html.size() && (quote || html[end] != '>'); ++end) {
      if (quote && html[end] == quote) quote = 0;
      else if (!quote && (html[end] == '"' || html[end] == '\'')) quote = html[end];
    }
    if (end >= html.size()) return "unterminated tag at " + std::to_string(at);
    const std::string tag = html.substr(at + 1, end - at - 1);
    at = end + 1;
    if (tag.empty()) return "empty tag";
    if (tag[0] == '/') {
      const std::string name = Lower(tag.substr(1));
      if (open.empty() || open.back() != name) {
        return "unexpected </" + name + "> (open: " + (open.empty() ? "none" : open.back()) + ")";
      }
      open.pop_back();
      continue;
    }
    const std::string name = Lower(tag.substr(0, tag.find_first_of(" \t\n/")));
    for (const char* attribute : {" src=\"", " href=\""}) {
      const std::size_t a = tag.find(attribute);
      if (a == std::string::npos) continue;
      const std::string value = tag.substr(a + std::strlen(attribute), 5);
      if (value.rfind("data:", 0) != 0 && value[0] != '#') return "external reference in <" + tag + ">";
    }
    if (tag.back() == '/' || std::find(kVoid.begin(), kVoid.end(), name) != kVoid.end()) continue;
    if (name == "script" || name == "style") {
      const std::size_t close = Lower(html.substr(at)).find("</" + name + ">");
      if (close == std::string::npos) return "unclosed <" + name + ">";
      at += close + name.size() + 3;
      continue;
    }
    open.push_back(name);
  }
  if (!open.empty()) return "unclosed <" + open.back() + ">";
  return "";
}

std::string ScriptBody(const std::string& html, const std::string& id) {
  const std::string start = "id=\"" + id + "\">";
  const std::size_t a = html.find(start);
  if (a == std::string::npos) return "";
  const std::size_t b = html.find("</script>", a);
  return html.substr(a + start.size(), b - a - start.size());
}

std::size_t Base64Floats(const std::string& text) {
  std::size_t padding = 0;
  if (!text.empty() && text.back() == '=') ++padding;
  if (text.size() > 1 && text[text.size() - 2] == '=') ++padding;
  return (text.size() / 4 * 3 - padding) / 4;
}

struct Fixture {
  ObjectModel object = EvaluationObject();
  TempDir dir{"report_test"};
  Dataset dataset;
  Evaluation evaluation;
  Fixture() {
    WriteEvaluationDataset(object, dir / "data", 8);
    dataset = ReadDataset(dir / "data");
    EvaluationOptions options = EvaluationOptions::Defaults(object);
    options.run_icp = false;
    evaluation = Evaluate(object, dataset, {{"sim", nullptr, false}, {"self", nullptr, true}}, options);
  }
};

}  // namespace

TEST_CASE("the report is well-formed, self-contained HTML with the table, soundness and plots") {
  Fixture f;
  ReportInput input;
  input.evaluation = &f.evaluation;
  input.views = SelectReportViews(f.object, f.dataset, *f.evaluation.MainRow(),
                                  f.evaluation.options.adds_threshold, {2, 2, 300});
  input.command_line = "c3po eval x.json --data <dir> & more";
  const std::string html = ReportHtml(input);
  CHECK(CheckHtml(html) == "");
  // Checker self-test: it notices a broken page.
  CHECK(CheckHtml(html.substr(0, html.size() / 2)) != "");
  CHECK(CheckHtml("<!doctype html><html><body><img src=\"https://example.org/x.png\"></body></html>") != "");

  // Outside the embedded three.js source, no URL at all.
  std::string rest = html;
  const std::string three = ScriptBody(html, "c3po-three");
  CHECK(three.size() > 100000);
  rest.erase(rest.find(three), three.size());
  CHECK(rest.find("http://") == std::string::npos);
  CHECK(rest.find("https://") == std::string::npos);
  CHECK(html.find("<table id=\"results\">") != std::string::npos);

  // One table row per evaluation row (+ header), in order.
  const std::string table = html.substr(html.find("<table id=\"results\">"));
  std::size_t rows = 0, pos = 0;
  while ((pos = table.find("<tr", pos + 1)) != std::string::npos && pos < table.find("</table>")) ++rows;
  CHECK(rows == f.evaluation.rows.size() + 1);
  for (const auto& row : f.evaluation.rows) CHECK(table.find(">" + row.label + "<") != std::string::npos);
  CHECK(html.find("<b id=\"false-certificates\">" + std::to_string(f.evaluation.total_false_certificates()) + "</b>") !=
        std::string::npos);
  CHECK(html.find("<b id=\"false-certificates-hausdorff\">" +
                  std::to_string(f.evaluation.total_false_certificates_hausdorff()) + "</b>") != std::string::npos);
  const bool sound = f.evaluation.total_false_certificates() == 0 && f.evaluation.total_false_certificates_hausdorff() == 0;
  CHECK(html.find(sound ? "<section id=\"soundness\" class=\"sound\">" : "<section id=\"soundness\" class=\"unsound\">") !=
        std::string::npos);
  CHECK(html.find("ADD-S variant: <b>symmetric</b>") != std::string::npos);
  CHECK(html.find("&lt;dir&gt; &amp; more") != std::string::npos);

  // Histogram bars (titles "certified a - b: N") add up to the samples of each row on all clouds.
  // (scanned by hand: std::regex recurses per character and overflows the stack on a 1 MB page)
  int total = 0;
  for (std::size_t at = html.find("<title>"); at != std::string::npos; at = html.find("<title>", at + 1)) {
    const std::size_t end = html.find("</title>", at);
    const std::string text = html.substr(at + 7, end - at - 7);
    if (text.rfind("certified ", 0) != 0 && text.rfind("not certified ", 0) != 0) continue;
    total += std::stoi(text.substr(text.rfind(": ") + 2));
  }
  int expected = 0;
  for (const auto& row : f.evaluation.rows) expected += row.subset == EvalSubset::kAll ? row.summary.n : 0;
  CHECK(total == expected);
}

TEST_CASE("3D views: selected examples decode to the subsampled clouds and posed models") {
  Fixture f;
  const EvaluationRow& row = *f.evaluation.MainRow();
  const double threshold = f.evaluation.options.adds_threshold;
  const std::vector<ReportView> views = SelectReportViews(f.object, f.dataset, row, threshold, {2, 3, 250});
  int certified = 0, rejected = 0, available_certified = 0, available_rejected = 0;
  for (const auto& s : row.samples) {
    if (!s.ok()) continue;
    (s.certified() ? available_certified : available_rejected) += 1;
  }
  for (const auto& v : views) (v.certified ? certified : rejected) += 1;
  CHECK(certified == std::min(2, available_certified));
  CHECK(rejected == std::min(3, available_rejected));
  REQUIRE(!views.empty());
  for (const auto& v : views) {
    CHECK(v.input.cols() <= 250);
    CHECK(v.posed_model.cols() <= 250);
    CHECK(v.keypoints.cols() == f.object.num_keypoints());
  }
  ReportInput input;
  input.evaluation = &f.evaluation;
  input.views = views;
  const std::string html = ReportHtml(input);
  const nlohmann::json data = nlohmann::json::parse(ScriptBody(html, "c3po-views"));
  REQUIRE(data["views"].size() == views.size());
  for (std::size_t k = 0; k < views.size(); ++k) {
    const auto& v = data["views"][k];
    CHECK(v["certified"].get<bool>() == views[k].certified);
    CHECK(Base64Floats(v["input"]) == 3 * static_cast<std::size_t>(views[k].input.cols()));
    CHECK(Base64Floats(v["posed_model"]) == 3 * static_cast<std::size_t>(views[k].posed_model.cols()));
    CHECK(Base64Floats(v["keypoints"]) == 3 * static_cast<std::size_t>(f.object.num_keypoints()));
  }
  // A cloud name that tries to close the script element cannot.
  input.views[0].cloud = "evil</script><b>.ply";
  CHECK(CheckHtml(ReportHtml(input)) == "");
  // Without views no three.js is embedded.
  input.views.clear();
  const std::string plain = ReportHtml(input);
  CHECK(ScriptBody(plain, "c3po-three").empty());
  CHECK(CheckHtml(plain) == "");
}

TEST_CASE("3D views: the outliers of each estimate (input points at >= eps_oc) are a layer of their own") {
  Fixture f;
  // A tight eps_oc so that estimates have outliers; oracle: brute-force
  // distances from each input point to the posed model sample.
  EvaluationOptions options = EvaluationOptions::Defaults(f.object);
  options.run_icp = false;
  options.pipeline.certificate.eps_oc = 0.004 * f.object.diameter();
  const Evaluation evaluation = Evaluate(f.object, f.dataset, {{"sim", nullptr, false}}, options);
  const EvaluationRow& row = *evaluation.MainRow();
  int with_outliers = 0;
  for (const auto& s : row.samples) {
    if (!s.ok()) continue;
    const PointSet cloud = f.dataset.LoadCloud(s.index);
    const PointSet local = s.scene_from_model.InverseApply(cloud);   // model frame, as the certificate
    std::vector<int> expected;
    for (Eigen::Index j = 0; j < cloud.cols(); ++j) {
      const double d = std::sqrt((f.object.sample().colwise() - local.col(j)).colwise().squaredNorm().minCoeff());
      if (!(d < options.pipeline.certificate.eps_oc)) expected.push_back(static_cast<int>(j));
    }
    CHECK(s.outlier_indices == expected);
    with_outliers += !expected.empty();
  }
  REQUIRE(with_outliers > 0);
  const std::vector<ReportView> views = SelectReportViews(f.object, f.dataset, row, options.adds_threshold, {3, 3, 100000});
  REQUIRE(!views.empty());
  ReportInput input;
  input.evaluation = &evaluation;
  input.views = views;
  const std::string html = ReportHtml(input);
  CHECK(CheckHtml(html) == "");
  CHECK(html.find("id=\"layer-outliers\"") != std::string::npos);
  const nlohmann::json data = nlohmann::json::parse(ScriptBody(html, "c3po-views"));
  for (std::size_t k = 0; k < views.size(); ++k) {
    const SampleResult* sample = nullptr;
    for (const auto& s : row.samples) {
      if (s.cloud == views[k].cloud) sample = &s;
    }
    REQUIRE(sample != nullptr);
    const PointSet cloud = f.dataset.LoadCloud(sample->index);
    REQUIRE(views[k].outliers.cols() == static_cast<Eigen::Index>(sample->outlier_indices.size()));
    for (std::size_t i = 0; i < sample->outlier_indices.size(); ++i) {
      CHECK((views[k].outliers.col(static_cast<Eigen::Index>(i)) - cloud.col(sample->outlier_indices[i])).norm() == 0.0);
    }
    CHECK(Base64Floats(data["views"][k]["outliers"]) == 3 * sample->outlier_indices.size());
  }
  // Indices outside the cloud (a stale result) are dropped, not read.
  EvaluationRow stale = row;
  for (auto& s : stale.samples) s.outlier_indices = {-1, 0, 1 << 30};
  for (const ReportView& v : SelectReportViews(f.object, f.dataset, stale, options.adds_threshold, {2, 2, 100})) {
    CHECK(v.outliers.cols() == 1);
  }
}

TEST_CASE("3D views: a rejected example says why and shows the rival pose that refused it") {
  Fixture f;
  const EvaluationRow& row = *f.evaluation.MainRow();
  // Evaluate keeps every sample's refusal (RefusalSummary): empty iff certified.
  int rejected = 0;
  for (const auto& s : row.samples) {
    if (!s.ok()) continue;
    CHECK(s.refusal.empty() == s.certified());
    CHECK((s.rival_scene_from_model.has_value() && s.certified()) == false);
    rejected += !s.certified();
  }
  // A rejected example with a rival (the evidence nd's global search leaves).
  EvaluationRow planted = row;
  SampleResult* target = nullptr;
  for (auto& s : planted.samples) {
    if (s.ok() && !target) target = &s;
  }
  REQUIRE(target != nullptr);
  target->oc = true;
  target->free_space = true;
  target->nd = false;
  target->refusal = "nd_global: a pose 0.05 away (180 deg about axis 0) leaves 3 points at >= eps_oc";
  Pose rival = target->scene_from_model;
  rival.R = rival.R * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  target->rival_scene_from_model = rival;
  const double threshold = f.evaluation.options.adds_threshold;
  const std::vector<ReportView> views = SelectReportViews(f.object, f.dataset, planted, threshold, {0, 100, 300});
  const ReportView* shown = nullptr;
  for (const auto& v : views) {
    if (v.cloud == target->cloud) shown = &v;
  }
  REQUIRE(shown != nullptr);
  CHECK(shown->refusal == target->refusal);
  const PointSet model = StridedColumns(f.object.sample(), 300);
  REQUIRE(shown->rival_model.cols() == model.cols());
  CHECK((shown->rival_model - rival * model).cwiseAbs().maxCoeff() == 0.0);
  for (const auto& v : views) {
    if (&v != shown) CHECK(v.rival_model.cols() == 0);   // no rival, no layer content
  }
  ReportInput input;
  input.evaluation = &f.evaluation;
  input.views = views;
  const std::string html = ReportHtml(input);
  CHECK(CheckHtml(html) == "");
  CHECK(html.find("id=\"layer-rival\"") != std::string::npos);
  const nlohmann::json data = nlohmann::json::parse(ScriptBody(html, "c3po-views"));
  const std::size_t k = static_cast<std::size_t>(shown - views.data());
  CHECK(data["views"][k]["refusal"] == target->refusal);
  CHECK(Base64Floats(data["views"][k]["rival_model"]) == 3 * static_cast<std::size_t>(model.cols()));
  MESSAGE(rejected << " rejected samples in the fixture's main row");
}

TEST_CASE("3D views: a certified pose whose Hausdorff distance is beyond the threshold is a false certificate") {
  Fixture f;
  EvaluationRow row = *f.evaluation.MainRow();
  const double threshold = f.evaluation.options.adds_threshold;
  SampleResult* target = nullptr;
  for (auto& s : row.samples) {
    if (s.ok() && !target) target = &s;
  }
  REQUIRE(target != nullptr);
  // Certified, ADD-S small (a box half-turned about its axis), Hausdorff large.
  target->oc = target->nd = target->free_space = true;
  target->adds = 0.1 * threshold;
  target->hausdorff = 3.0 * threshold;
  CHECK(target->false_certificate(threshold));
  target->hausdorff = 0.5 * threshold;
  CHECK_FALSE(target->false_certificate(threshold));
  target->hausdorff = std::numeric_limits<double>::quiet_NaN();   // unknown counts, as in the summary
  CHECK(target->false_certificate(threshold));
  target->hausdorff = 3.0 * threshold;
  const std::vector<ReportView> views = SelectReportViews(f.object, f.dataset, row, threshold, {1, 0, 100});
  REQUIRE(views.size() == 1);   // false certificates are shown first
  CHECK(views[0].cloud == target->cloud);
  CHECK(views[0].false_certificate);
  CHECK(views[0].title.rfind("FALSE certificate", 0) == 0);
}

namespace {

// An outcome whose certificate fails exactly `parts` (or nothing).
CloudOutcome Refused(const std::vector<CertificatePart>& parts) {
  CloudOutcome outcome;
  Certificate& c = outcome.estimate.certificate;
  c.oc.points_passed = c.oc.keypoints_passed = c.oc.passed = true;
  c.nd.sets_passed = c.nd.passed = true;
  for (const CertificatePart part : parts) {
    switch (part) {
      case CertificatePart::kOcPoints: c.oc.points_passed = c.oc.passed = false; break;
      case CertificatePart::kFreeSpace:
        c.free_space.checked = true;
        c.free_space.silhouette_passed = c.free_space.passed = false;
        break;
      case CertificatePart::kNdGlobal:
        c.nd.global_checked = true;
        c.nd.global.passed = c.nd.passed = false;
        break;
      default: FAIL("not used here");
    }
  }
  return outcome;
}

}  // namespace

TEST_CASE("certify report: examples are the first certified ones and one rejected per first refusing part") {
  using P = CertificatePart;
  std::vector<CloudOutcome> outcomes = {Refused({P::kOcPoints}), Refused({}), Refused({P::kOcPoints, P::kFreeSpace}),
                                        Refused({P::kNdGlobal}), Refused({}), Refused({P::kFreeSpace}),
                                        Refused({P::kOcPoints}), Refused({})};
  outcomes.push_back(Refused({}));
  outcomes.back().failure = CloudOutcome::Failure::kLoad;   // unreadable: never an example
  for (std::size_t i = 0; i < outcomes.size(); ++i) {
    CAPTURE(i);
    CHECK(outcomes[i].certified() == (i == 1 || i == 4 || i == 7));
  }
  // Two certified (in source order); rejected: oc first (0), free space (5), nd_global (3), then source order (2).
  CHECK(SelectCertifyExamples(outcomes, 2, 4) == std::vector<std::size_t>{1, 4, 0, 5, 3, 2});
  CHECK(SelectCertifyExamples(outcomes, 0, 2) == std::vector<std::size_t>{0, 5});
  CHECK(SelectCertifyExamples(outcomes, 5, 9) == std::vector<std::size_t>{1, 4, 7, 0, 5, 3, 2, 6});
  CHECK(SelectCertifyExamples(outcomes, 0, 0).empty());
  // The counts behind the table: `first` sums to the refused poses, `failed` counts every part.
  int first = 0;
  for (const RefusalCount& count : CountRefusals(outcomes)) {
    first += count.first;
    if (count.name == "oc") CHECK((count.first == 3 && count.failed == 3));
    if (count.name == "free_space") CHECK((count.first == 1 && count.failed == 2));
    if (count.name == "nd_global") CHECK((count.first == 1 && count.failed == 1));
  }
  CHECK(first == 5);
}

TEST_CASE("certify report: each example is its source's cloud with the estimate's outliers, reason and rival") {
  Fixture f;
  CertifyBatchOptions options;
  options.pipeline.certificate = CertificateOptions::FromObject(f.object.spec());
  options.pipeline.certificate.eps_oc = 0.004 * f.object.diameter();   // tight: outliers and refusals
  const std::vector<CloudSource> sources = DatasetSources(f.dataset);
  const CertifyBatchResult result = CertifyBatch(f.object, sources, nullptr, options);
  REQUIRE(result.outcomes.size() == sources.size());
  ReportViewOptions view_options;
  view_options.certified = view_options.rejected = 10;
  view_options.max_points = 100000;
  const std::vector<ReportView> views = CertifyReportViews(f.object, sources, result, view_options);
  const std::vector<std::size_t> chosen = SelectCertifyExamples(result.outcomes, 10, 10);
  REQUIRE(views.size() == chosen.size());
  int rejected = 0;
  for (std::size_t k = 0; k < views.size(); ++k) {
    const CloudOutcome& outcome = result.outcomes[chosen[k]];
    const PoseEstimate& e = outcome.estimate;
    const PointSet cloud = f.dataset.LoadCloud(sources[chosen[k]].dataset_index);
    CAPTURE(views[k].cloud);
    CHECK(views[k].cloud == sources[chosen[k]].name);
    CHECK(views[k].certified == e.certified());
    CHECK((views[k].input - cloud).cwiseAbs().maxCoeff() == 0.0);
    REQUIRE(views[k].outliers.cols() == static_cast<Eigen::Index>(e.certificate.oc.outlier_indices.size()));
    for (std::size_t i = 0; i < e.certificate.oc.outlier_indices.size(); ++i) {
      CHECK((views[k].outliers.col(static_cast<Eigen::Index>(i)) - cloud.col(e.certificate.oc.outlier_indices[i]))
                .norm() == 0.0);
    }
    CHECK(views[k].refusal == (e.ok() ? RefusalSummary(e.certificate) : "registration failed"));
    CHECK(views[k].refusal.empty() == e.certified());
    const bool rival = e.certificate.nd.global_checked && !e.certificate.nd.global.passed;
    CHECK((views[k].rival_model.cols() > 0) == rival);
    CHECK(views[k].truth_model.cols() > 0);   // the manifest's ground truth
    CHECK(std::isnan(views[k].adds));
    rejected += !views[k].certified;
  }
  CHECK(rejected > 0);
  CertifyReportInput input;
  input.object_name = f.object.spec().name;
  input.diameter = f.object.diameter();
  input.inputs = "dataset data";
  input.settings = "eps_oc = tight";
  input.result = &result;
  input.views = views;
  const std::string html = CertifyReportHtml(input);
  CHECK(CheckHtml(html) == "");
  CHECK(html.find("<b id=\"certified-count\">" + std::to_string(result.certified) + "</b> of " +
                  std::to_string(sources.size())) != std::string::npos);
  CHECK(html.find("id=\"refusals\"") != std::string::npos);
  for (const RefusalCount& count : CountRefusals(result.outcomes)) {
    const bool listed = html.find("<td>refused by " + count.name + "</td><td>" + std::to_string(count.first) +
                                  "</td><td>" + std::to_string(count.failed) + "</td>") != std::string::npos;
    CHECK(listed == (count.failed > 0));
  }
  const nlohmann::json data = nlohmann::json::parse(ScriptBody(html, "c3po-views"));
  REQUIRE(data["views"].size() == views.size());
  CHECK(data["views"][0]["adds"].is_null());
  CHECK_THROWS_AS(CertifyReportHtml(CertifyReportInput{}), std::invalid_argument);
}

TEST_CASE("training logs are read (numeric fields) and plotted, malformed lines are input errors") {
  TempDir dir("report_test_logs");
  {
    std::ofstream log(dir / "sim.model.log.jsonl");
    for (int e = 1; e <= 5; ++e) {
      log << "{\"epoch\": " << e << ", \"train_loss\": " << 1.0 / e << ", \"val_loss\": " << 1.5 / e
          << ", \"oc_val\": " << 0.2 * e << ", \"note\": \"text\"}\n";
    }
    log << "\n";
  }
  const TrainingLog log = ReadTrainingLog(dir / "sim.model.log.jsonl", "sim");
  REQUIRE(log.epochs.size() == 5);
  CHECK(log.epochs[2].at("train_loss") == doctest::Approx(1.0 / 3));
  CHECK(log.epochs[4].at("oc_val") == doctest::Approx(1.0));
  CHECK(log.epochs[0].count("note") == 0);

  {
    std::ofstream bad(dir / "bad.jsonl");
    bad << "{\"epoch\": 1}\n{\"epoch\": 2}\n[1, 2]\n";
  }
  try {
    ReadTrainingLog(dir / "bad.jsonl", "bad");
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("bad.jsonl: line 3") != std::string::npos);
  }
  CHECK_THROWS_AS(ReadTrainingLog(dir / "missing.jsonl", "x"), InputError);

  const ObjectModel object = EvaluationObject();
  Evaluation evaluation;
  evaluation.object_name = "asym";
  evaluation.diameter = object.diameter();
  evaluation.options = EvaluationOptions::Defaults(object);
  ReportInput input;
  input.evaluation = &evaluation;
  input.training = {log};
  const std::string html = ReportHtml(input);
  CHECK(CheckHtml(html) == "");
  CHECK(html.find("sim: loss per epoch") != std::string::npos);
  CHECK(html.find("sim: certified / observably correct per epoch") != std::string::npos);
  // oc_val is a fraction: plotted as percent, 5 points (one marker per epoch).
  const std::string percent_chart = html.substr(html.find("sim: certified / observably correct per epoch"));
  const std::size_t polyline = percent_chart.find("<polyline");
  const std::string points = percent_chart.substr(polyline, percent_chart.find("\">", polyline) - polyline);
  CHECK(std::count(points.begin(), points.end(), ',') == 5);
}

TEST_CASE("the report is written atomically") {
  TempDir dir("report_test_atomic");
  const ObjectModel object = EvaluationObject();
  Evaluation evaluation;
  evaluation.object_name = "asym";
  evaluation.diameter = object.diameter();
  evaluation.options = EvaluationOptions::Defaults(object);
  ReportInput input;
  input.evaluation = &evaluation;

  const std::string path = dir / "report.html";
  WriteFileAtomically(path, "old report\n");
  ReportInput broken;   // no evaluation: fails before anything is written
  CHECK_THROWS(WriteReport(path, broken));
  CHECK(ReadFileToString(path) == "old report\n");

  WriteReport(path, input);
  CHECK(ReadFileToString(path) == ReportHtml(input));
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(dir.path())) files.push_back(entry.path().filename().string());
  CHECK(files == std::vector<std::string>{"report.html"});   // no temporary left behind

  CHECK_THROWS_AS(WriteReport(dir / "no/such/folder/report.html", input), InputError);
}

TEST_CASE("selftrain-style logs: percent fields are not rescaled and counts are not plotted as percentages") {
  TempDir dir("report_test_selftrain_log");
  {
    std::ofstream log(dir / "self.model.log.jsonl");
    log << "{\"phase\": \"selftrain\", \"epoch\": 1, \"train_percent_oc\": 0.5, \"validation_percent_certified\": 0.25, "
           "\"loss\": 0.3, \"certified_samples\": 7, \"best\": true}\n";
    log << "{\"phase\": \"selftrain\", \"epoch\": 2, \"train_percent_oc\": 0.75, \"validation_percent_certified\": 1.0, "
           "\"loss\": 0.2, \"certified_samples\": 9, \"best\": false}\n";
  }
  const TrainingLog log = ReadTrainingLog(dir / "self.model.log.jsonl", "self");
  REQUIRE(log.epochs.size() == 2);
  CHECK(log.epochs[0].count("best") == 0);   // booleans are not numbers
  const ObjectModel object = EvaluationObject();
  Evaluation evaluation;
  evaluation.object_name = "asym";
  evaluation.diameter = object.diameter();
  evaluation.options = EvaluationOptions::Defaults(object);
  ReportInput input;
  input.evaluation = &evaluation;
  input.training = {log};
  const std::string html = ReportHtml(input);
  const std::size_t start = html.find("self: certified / observably correct per epoch");
  REQUIRE(start != std::string::npos);
  const std::string chart = html.substr(start, html.find("</svg>", start) - start);
  CHECK(chart.find(">train_percent_oc<") != std::string::npos);
  CHECK(chart.find(">validation_percent_certified<") != std::string::npos);
  CHECK(chart.find("certified_samples") == std::string::npos);
  // The percent axis runs 0..100 and the values stay as given (0.5 %, not 50 %): the
  // curve of train_percent_oc hugs the bottom of the plot area.
  const std::size_t polyline = chart.find("<polyline");
  const std::string points = chart.substr(polyline, chart.find("\">", polyline) - polyline);
  const std::size_t comma = points.find(',');
  const double y = std::stod(points.substr(comma + 1));
  CHECK(y > 240.0);   // plot area bottom = height 300 - 40 = 260; 0.5 % of 232 px above it
  // The counts have their own chart, as given (7 and 9 samples, not percentages).
  const std::size_t counts_start = html.find("self: samples per epoch");
  REQUIRE(counts_start != std::string::npos);
  const std::string counts = html.substr(counts_start, html.find("</svg>", counts_start) - counts_start);
  CHECK(counts.find(">certified_samples<") != std::string::npos);
  CHECK(counts.find("train_percent_oc") == std::string::npos);
  CHECK(counts.find(">loss<") == std::string::npos);
}
