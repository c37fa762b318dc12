// eval --samples / c3po merge --eval (evaluation_samples.hpp): an evaluation
// cut into contiguous parts, written as sample files and merged, gives the
// same table and JSON as the whole (exact numbers, failures with inf,
// self-trained subset rows, false certificates with their global indices);
// malformed, reordered, incomplete or mismatched parts are InputErrors.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/eval/evaluation_samples.hpp"

using namespace c3po;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

EvaluationOptions Options() {
  EvaluationOptions o;
  o.adds_threshold = 0.0123456789;
  o.auc_max = 0.0246913578;
  o.pipeline.certificate.eps_oc = 0.01 / 3.0;
  o.pipeline.certificate.delta_nd = 0.02 / 7.0;
  o.pipeline.certificate.max_outliers.fraction = 0.02;
  o.pipeline.certificate.global.reestimate = true;   // not the default: the settings line must carry it
  o.icp.max_correspondence_distance = kInf;
  o.ransac.inlier_threshold = 0.0123456789;
  o.ransac.seed = 42;
  o.worst_listed = 3;
  Pose symmetry;   // carried bit for bit (the merged table names it)
  symmetry.R = Eigen::AngleAxisd(M_PI, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  symmetry.t = Eigen::Vector3d(0.01, -0.02, 0.03) / 3.0;
  o.symmetries = {symmetry};
  return o;
}

// Random samples of one row on clouds [first, first + n) (index = local position).
std::vector<SampleResult> Samples(std::uint64_t seed, int n) {
  Rng rng(seed);
  std::vector<SampleResult> out;
  for (int i = 0; i < n; ++i) {
    SampleResult s;
    s.index = static_cast<std::size_t>(i);
    s.cloud = "cloud_" + std::to_string(i) + ".ply";
    if (rng.Uniform(0.0, 1.0) < 0.15) {
      s.error = "detector: no keypoints";
      s.adds = kInf;
      s.rotation_error = M_PI;
      s.translation_error = kInf;
      s.oc_distance = kInf;
    } else {
      s.adds = rng.Uniform(0.0, 0.06) / 3.0;   // non-terminating binary fractions
      s.rotation_error = rng.Uniform(0.0, 3.0);
      s.translation_error = rng.Uniform(0.0, 0.1);
      s.oc = rng.Uniform(0.0, 1.0) < 0.6;
      s.nd = rng.Uniform(0.0, 1.0) < 0.7;
      s.oc_distance = rng.Uniform(0.0, 0.02);
      if (s.oc && s.nd) s.hausdorff = rng.Uniform(0.0, 0.06) / 3.0;   // some at or above adds_threshold
      s.scene_from_model.R = Eigen::AngleAxisd(rng.Uniform(0.0, 3.0), Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
      s.scene_from_model.t = Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(0.5, 2)) / 3.0;
    }
    s.milliseconds = rng.Uniform(0.0, 10.0);
    out.push_back(s);
  }
  return out;
}

// An evaluation of two detectors ("svd": KeyPo + corrector rows; "self":
// self-trained, its three C-3PO rows) on clouds [first, last) of `all`.
Evaluation Slice(const std::vector<std::vector<SampleResult>>& all, std::size_t first, std::size_t last) {
  Evaluation e;
  e.object_name = "mug";
  e.dataset_dir = "data";
  e.clouds = last - first;
  e.diameter = 0.123456789;
  e.options = Options();
  const auto part = [&](int r) {
    std::vector<SampleResult> samples(all[r].begin() + first, all[r].begin() + last);
    for (auto& s : samples) s.index -= first;
    return samples;
  };
  e.rows.push_back(MakeEvaluationRow(EvalMethod::kKeyPo, EvalSubset::kAll, "svd", part(0), e.options, e.diameter));
  e.rows.push_back(MakeEvaluationRow(EvalMethod::kKeyPoCorrector, EvalSubset::kAll, "svd", part(1), e.options, e.diameter));
  for (EvalSubset subset : {EvalSubset::kAll, EvalSubset::kObservablyCorrect, EvalSubset::kCertified}) {
    e.rows.push_back(MakeEvaluationRow(EvalMethod::kC3po, subset, "self", part(2), e.options, e.diameter));
  }
  return e;
}

std::string ErrorOf(const std::vector<std::pair<std::string, std::string>>& parts) {
  try {
    MergeEvaluationSamples(parts);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("merged sample files of contiguous parts give the whole evaluation's table and JSON") {
  const int n = 23;
  const std::vector<std::vector<SampleResult>> all = {Samples(1, n), Samples(2, n), Samples(3, n)};
  const Evaluation whole = Slice(all, 0, n);
  REQUIRE(whole.total_false_certificates() > 0);   // the listing with global indices is exercised
  REQUIRE(whole.total_false_certificates_hausdorff() > 0);   // and the Hausdorff check
  for (const std::vector<std::size_t>& cuts : std::vector<std::vector<std::size_t>>{{0, 23}, {0, 8, 23}, {0, 1, 9, 22, 23}}) {
    std::vector<std::pair<std::string, std::string>> parts;
    const int count = static_cast<int>(cuts.size()) - 1;
    for (int k = 0; k < count; ++k) {
      const std::string shard = std::to_string(k + 1) + "/" + std::to_string(count);
      parts.emplace_back("s" + std::to_string(k + 1) + ".jsonl",
                         EvaluationSamplesJsonl(Slice(all, cuts[k], cuts[k + 1]), shard));
    }
    CHECK(IsEvaluationSamples(parts.front().second));
    const Evaluation merged = MergeEvaluationSamples(parts);
    CHECK(EvaluationTable(merged) == EvaluationTable(whole));
    CHECK(merged.options.pipeline.certificate.global.reestimate);
    REQUIRE(merged.options.symmetries.size() == 1);
    CHECK(merged.options.symmetries[0].R == whole.options.symmetries[0].R);
    CHECK(merged.options.symmetries[0].t == whole.options.symmetries[0].t);
    CHECK(EvaluationJson(merged) == EvaluationJson(whole));   // even the timings: they are carried exactly
    REQUIRE(merged.rows.size() == whole.rows.size());
    for (std::size_t r = 0; r < merged.rows.size(); ++r) {
      REQUIRE(merged.rows[r].samples.size() == whole.rows[r].samples.size());
      for (std::size_t i = 0; i < merged.rows[r].samples.size(); ++i) {
        const SampleResult& a = merged.rows[r].samples[i];
        const SampleResult& b = whole.rows[r].samples[i];
        CHECK(a.index == b.index);
        CHECK(a.adds == b.adds);   // bit for bit
        CHECK(a.rotation_error == b.rotation_error);
        CHECK(a.scene_from_model.R == b.scene_from_model.R);
        CHECK(a.scene_from_model.t == b.scene_from_model.t);
      }
    }
  }
}

TEST_CASE("merge --eval refuses parts out of order, missing, of another run, truncated or malformed") {
  const int n = 10;
  const std::vector<std::vector<SampleResult>> all = {Samples(4, n), Samples(5, n), Samples(6, n)};
  const std::string a = EvaluationSamplesJsonl(Slice(all, 0, 4), "1/2");
  const std::string b = EvaluationSamplesJsonl(Slice(all, 4, n), "2/2");
  CHECK_NOTHROW(MergeEvaluationSamples({{"a", a}, {"b", b}}));
  CHECK(ErrorOf({{"b", b}, {"a", a}}).find("b: shard 2/2 given as part 1 of 2") == 0);
  CHECK(ErrorOf({{"a", a}}).find("a: shard 1/2 given as part 1 of 1") == 0);
  Evaluation other = Slice(all, 4, n);
  other.options.pipeline.certificate.eps_oc *= 2;
  CHECK(ErrorOf({{"a", a}, {"o", EvaluationSamplesJsonl(other, "2/2")}}).find("o: object, dataset or settings differ") == 0);
  const std::string truncated = b.substr(0, b.rfind('\n', b.size() - 2) + 1);
  CHECK(ErrorOf({{"a", a}, {"t", truncated}}).find("t: row 2 has 5 samples, not 6") == 0);
  CHECK(ErrorOf({{"a", a}, {"e", ""}}).find("e: empty") == 0);
  CHECK(ErrorOf({{"a", a}, {"x", "{\"cloud\": 1}\n"}}).find("x: line 1: not an eval samples file") == 0);
  CHECK(ErrorOf({{"a", a}, {"j", b.substr(0, b.size() / 2)}}).find("j: line") == 0);
  std::string bad_row = b;
  bad_row.replace(bad_row.find("\"row\":0"), 7, "\"row\":9");
  CHECK(ErrorOf({{"a", a}, {"r", bad_row}}).find("not in the header's rows") != std::string::npos);
  std::string swapped = b;   // a sample out of dataset order
  swapped.replace(swapped.find("\"index\":0"), 9, "\"index\":3");
  CHECK(ErrorOf({{"a", a}, {"s", swapped}}).find("index 3: expected 0") != std::string::npos);
  std::string bad_symmetry = b;   // a symmetry that is not 12 numbers
  const std::size_t at = bad_symmetry.find("\"symmetries\":[[");
  REQUIRE(at != std::string::npos);
  bad_symmetry.replace(at, 16, "\"symmetries\":[[1],[");
  CHECK(ErrorOf({{"a", a}, {"y", bad_symmetry}}).find("y: line 1: symmetries: each pose is 12 numbers") != std::string::npos);
  CHECK_FALSE(IsEvaluationSamples("{\"cloud\": \"x.ply\"}\n"));
  CHECK(ErrorOf({}) == "c3po merge: no parts");
}

TEST_CASE("merge --eval: a sample file written before re-estimation was recorded reads as without it") {
  const std::vector<std::vector<SampleResult>> all = {Samples(4, 5), Samples(5, 5), Samples(6, 5)};
  std::string part = EvaluationSamplesJsonl(Slice(all, 0, 5), "1/1");
  const std::string key = "\"reestimate\":true,";
  const std::size_t at = part.find(key);
  REQUIRE(at != std::string::npos);
  part.erase(at, key.size());
  const Evaluation merged = MergeEvaluationSamples({{"old.jsonl", part}});
  CHECK(!merged.options.pipeline.certificate.global.reestimate);
  CHECK(EvaluationTable(merged).find("re-estimation off") != std::string::npos);
}
