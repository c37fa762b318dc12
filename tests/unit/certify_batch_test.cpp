// CertifyBatch (the one batch loop of certify, eval and self-training) against
// independent oracles: EstimateAndCertify called cloud by cloud, EstimateEpsOc
// called on the clouds and distances by hand, and the JSON-lines schema read
// back field by field.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <cmath>
#include <fstream>
#include <limits>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/io/cloud_io.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/method/auto_threshold.hpp"
#include "c3po/method/certify_batch.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/method/refusal.hpp"
#include "evaluation_fixture.hpp"
#include "test_helpers.hpp"

using namespace c3po;

namespace {

constexpr int kClouds = 12;

struct Fixture {
  ObjectModel object = test::EvaluationObject();
  std::vector<Pose> poses = test::EvaluationPoses(kClouds);
  std::vector<PointSet> clouds, detected;
  Fixture() {
    for (int i = 0; i < kClouds; ++i) {
      clouds.push_back(test::EvaluationCloud(object, poses[i], i));
      detected.push_back(test::DetectedKeypoints(object, poses[i], i));
    }
  }
  CertifyBatchOptions Options(bool correct = true) const {
    CertifyBatchOptions options;
    options.pipeline.certificate = CertificateOptions::FromObject(object.spec());
    options.pipeline.correct = correct;
    return options;
  }
};

// The oracle of one cloud: the pipeline called directly.
void CheckSameEstimate(const PoseEstimate& batch, const PoseEstimate& direct) {
  CHECK(batch.ok() == direct.ok());
  CHECK(batch.certified() == direct.certified());
  CHECK(batch.certificate.oc.passed == direct.certificate.oc.passed);
  CHECK(batch.certificate.nd.passed == direct.certificate.nd.passed);
  CHECK(batch.correction.iterations == direct.correction.iterations);
  if (direct.ok()) {
    CHECK((batch.scene_from_model.R - direct.scene_from_model.R).norm() == 0.0);
    CHECK((batch.scene_from_model.t - direct.scene_from_model.t).norm() == 0.0);
    CHECK((batch.keypoints - direct.keypoints).norm() == 0.0);
    CHECK(batch.certificate.oc.max_point_distance == direct.certificate.oc.max_point_distance);
  }
}

// A detector that returns the fixture's detections of the cloud it recognises
// (by size and first point, up to float32 rounding of a file), or a wrong
// number of keypoints for cloud `wrong_index`.
class TableDetector : public Detector {
 public:
  TableDetector(const std::vector<PointSet>& clouds, const std::vector<PointSet>& keypoints, int wrong_index)
      : clouds_(clouds), keypoints_(keypoints), wrong_index_(wrong_index) {}
  std::string name() const override { return "table"; }
  int num_keypoints() const override { return static_cast<int>(keypoints_.front().cols()); }
  PointSet Detect(const PointSet& cloud) const override {
    ++calls;
    for (std::size_t i = 0; i < clouds_.size(); ++i) {
      if (clouds_[i].cols() == cloud.cols() && (clouds_[i].col(0) - cloud.col(0)).norm() < 1e-5) {
        if (static_cast<int>(i) == wrong_index_) return PointSet::Zero(3, 2);
        return keypoints_[i];
      }
    }
    throw std::runtime_error("unknown cloud");
  }
  mutable std::atomic<int> calls{0};

 private:
  const std::vector<PointSet>& clouds_;
  const std::vector<PointSet>& keypoints_;
  int wrong_index_;
};

}  // namespace

TEST_CASE("CertifyBatch with given keypoints equals EstimateAndCertify cloud by cloud") {
  const Fixture f;
  for (bool correct : {true, false}) {
    CAPTURE(correct);
    const CertifyBatchOptions options = f.Options(correct);
    std::atomic<std::size_t> progress_calls{0};
    std::size_t last_total = 0;
    const CertifyBatchResult result =
        CertifyBatch(f.object, InMemorySources(f.clouds, f.detected), nullptr, options,
                     [&](std::size_t, std::size_t total) { ++progress_calls; last_total = total; });
    REQUIRE(result.outcomes.size() == f.clouds.size());
    CHECK(progress_calls == f.clouds.size());
    CHECK(last_total == f.clouds.size());
    CHECK_FALSE(result.auto_eps_oc.has_value());
    CHECK(result.certificate.eps_oc == options.pipeline.certificate.eps_oc);
    int certified = 0, oc = 0, nd = 0;
    for (int i = 0; i < kClouds; ++i) {
      CAPTURE(i);
      const CloudOutcome& outcome = result.outcomes[i];
      REQUIRE(outcome.processed());
      CHECK((outcome.detected_keypoints - f.detected[i]).norm() == 0.0);
      CHECK_FALSE(outcome.uncorrected.has_value());
      const PoseEstimate direct = EstimateAndCertify(f.object, f.clouds[i], f.detected[i], options.pipeline);
      CheckSameEstimate(outcome.estimate, direct);
      // The stages are disjoint parts of the measured times: the estimate's
      // within `ms`, all of them within the outcome's seconds.
      const StageTimes& t = outcome.estimate.ms_stages;
      for (double stage : {t.load, t.detect, t.corrector, t.certificate, t.free_space, t.weak_motion, t.rival_search,
                           t.reestimation, t.centring, t.identity}) {
        CHECK(stage >= 0.0);
      }
      CHECK(t.Total() - t.load - t.detect <= outcome.estimate.milliseconds + 1e-9);
      CHECK(t.Total() <= 1000.0 * outcome.seconds + 1e-9);
      if (outcome.estimate.restart_axis < 0 && !outcome.estimate.centred) {   // else the replacement's search
        CHECK((t.rival_search > 0.0) == outcome.estimate.certificate.nd.global_checked);
      }
      certified += direct.certified();
      oc += direct.certificate.oc.passed;
      nd += direct.certificate.nd.passed;
    }
    CHECK(result.certified == certified);
    CHECK(result.oc == oc);
    CHECK(result.nd == nd);
    CHECK(result.errors == 0);
    // The fixture has certifiable and uncertifiable clouds: the check can fail.
    CHECK(certified > 0);
    CHECK(certified < kClouds);
  }
}

TEST_CASE("CertifyBatch: also_uncorrected certifies T(y~) as well, the visitor sees every processed cloud") {
  const Fixture f;
  CertifyBatchOptions options = f.Options(true);
  options.also_uncorrected = true;
  std::mutex mutex;
  std::set<std::size_t> visited;
  const CertifyBatchResult result =
      CertifyBatch(f.object, InMemorySources(f.clouds, f.detected), nullptr, options, {},
                   [&](std::size_t i, const PointSet& cloud, const FreeSpaceTest* free_space, CloudOutcome* outcome) {
                     CHECK((cloud - f.clouds[i]).norm() == 0.0);
                     CHECK(free_space == nullptr);   // no frames
                     CHECK(outcome->processed());
                     std::lock_guard<std::mutex> lock(mutex);
                     CHECK(visited.insert(i).second);
                   });
  CHECK(visited.size() == f.clouds.size());
  PipelineOptions plain = options.pipeline;
  plain.correct = false;
  for (int i = 0; i < kClouds; ++i) {
    CAPTURE(i);
    REQUIRE(result.outcomes[i].uncorrected.has_value());
    CheckSameEstimate(*result.outcomes[i].uncorrected, EstimateAndCertify(f.object, f.clouds[i], f.detected[i], plain));
    CheckSameEstimate(result.outcomes[i].estimate,
                      EstimateAndCertify(f.object, f.clouds[i], f.detected[i], options.pipeline));
  }
}

TEST_CASE("CertifyBatch: unreadable clouds and failing detections are per-cloud failures") {
  const Fixture f;
  test::TempDir dir("certify_batch_files");
  std::vector<std::string> paths;
  for (int i = 0; i < 4; ++i) {
    paths.push_back(dir / ("cloud" + std::to_string(i) + ".ply"));
    WritePly(paths.back(), f.clouds[i]);
  }
  paths[1] = dir / "missing.ply";                        // cannot be read
  {
    std::ofstream broken(dir / "broken.ply");
    broken << "ply\nformat ascii 1.0\nelement vertex 5\n";   // truncated header
  }
  paths.push_back(dir / "broken.ply");
  // The detector returns 2 keypoints for cloud 2 (the object has 10).
  const TableDetector detector(f.clouds, f.detected, 2);
  const CertifyBatchResult result = CertifyBatch(f.object, CloudFileSources(paths), &detector, f.Options());
  REQUIRE(result.outcomes.size() == 5);
  CHECK(result.errors == 3);
  CHECK(result.outcomes[0].processed());
  CHECK(result.outcomes[3].processed());
  CHECK(result.outcomes[1].failure == CloudOutcome::Failure::kLoad);
  CHECK(result.outcomes[1].error.find("missing.ply") != std::string::npos);
  CHECK(result.outcomes[4].failure == CloudOutcome::Failure::kLoad);
  CHECK(result.outcomes[4].error.find("broken.ply") != std::string::npos);
  CHECK(result.outcomes[2].failure == CloudOutcome::Failure::kDetect);
  CHECK(result.outcomes[2].error.find("detected 2 keypoints") != std::string::npos);
  CHECK_FALSE(result.outcomes[2].certified());
  // Detection ran on the three readable clouds only.
  CHECK(detector.calls == 3);
  for (int i : {0, 3}) {
    CheckSameEstimate(result.outcomes[i].estimate,
                      EstimateAndCertify(f.object, ReadCloud(paths[i]), f.detected[i], f.Options().pipeline));
  }
}

TEST_CASE("CertifyBatch without a detector needs given keypoints for every cloud") {
  const Fixture f;
  CHECK_THROWS_AS(CertifyBatch(f.object, InMemorySources(f.clouds), nullptr, f.Options()), InputError);
  CHECK_THROWS_AS(InMemorySources(f.clouds, {f.detected[0]}), std::invalid_argument);
  // An empty batch is an empty result.
  const CertifyBatchResult empty = CertifyBatch(f.object, {}, nullptr, f.Options());
  CHECK(empty.outcomes.empty());
  CHECK(empty.certified == 0);
}

TEST_CASE("CertifyBatch reads dataset entries with their detected keypoints and ground truth") {
  const Fixture f;
  test::TempDir dir("certify_batch_dataset");
  test::WriteEvaluationDataset(f.object, dir / "data", kClouds);
  const Dataset dataset = ReadDataset(dir / "data");
  const std::vector<CloudSource> sources = DatasetSources(dataset);
  REQUIRE(sources.size() == static_cast<std::size_t>(kClouds));
  for (int i = 0; i < kClouds; ++i) {
    CHECK(sources[i].name == dataset.entries[i].cloud);
    CHECK(sources[i].path == dataset.CloudPath(i));
    CHECK(sources[i].dataset_index == static_cast<std::size_t>(i));
    REQUIRE(sources[i].scene_from_model_truth.has_value());
    CHECK((sources[i].scene_from_model_truth->R - f.poses[i].R).norm() < 1e-12);
  }
  const CertifyBatchResult result = CertifyBatch(f.object, sources, nullptr, f.Options());
  for (int i = 0; i < kClouds; ++i) {
    CAPTURE(i);
    REQUIRE(result.outcomes[i].processed());
    // The clouds went through a PLY file (float32): the oracle reads them back too.
    const PointSet cloud = dataset.LoadCloud(i);
    CheckSameEstimate(result.outcomes[i].estimate,
                      EstimateAndCertify(f.object, cloud, *dataset.entries[i].detected_keypoints, f.Options().pipeline));
  }
}

TEST_CASE("--eps-oc auto: eps_oc from the clouds and the oc distances, every oc decided again with it") {
  const Fixture f;
  CertifyBatchOptions options = f.Options();
  options.auto_eps_oc = true;
  options.also_uncorrected = true;
  const CertifyBatchResult result = CertifyBatch(f.object, InMemorySources(f.clouds, f.detected), nullptr, options);
  REQUIRE(result.auto_eps_oc.has_value());
  // Oracle: the distances of the estimates at the object's threshold, and
  // EstimateEpsOc called by hand.
  std::vector<double> distances;
  for (int i = 0; i < kClouds; ++i) {
    const PoseEstimate e = EstimateAndCertify(f.object, f.clouds[i], f.detected[i], f.Options().pipeline);
    if (e.ok()) distances.push_back(e.certificate.oc.budget_distance);   // m = 0: the maximum
    if (e.ok()) CHECK(e.certificate.oc.budget_distance == e.certificate.oc.max_point_distance);
  }
  const AutoEpsOcResult expected = EstimateEpsOc(f.object, f.clouds, AutoEpsOcOptions{}, &distances);
  CHECK(result.auto_eps_oc->eps_oc == expected.eps_oc);
  CHECK(result.certificate.eps_oc == expected.eps_oc);
  CHECK(expected.eps_oc != f.object.spec().eps_oc);   // the decision changed something to check
  // Each decision equals a run with eps_oc fixed to the chosen value.
  CertifyBatchOptions fixed = f.Options();
  fixed.pipeline.certificate.eps_oc = expected.eps_oc;
  fixed.also_uncorrected = true;
  const CertifyBatchResult again = CertifyBatch(f.object, InMemorySources(f.clouds, f.detected), nullptr, fixed);
  for (int i = 0; i < kClouds; ++i) {
    CAPTURE(i);
    CHECK(result.outcomes[i].estimate.certificate.oc.passed == again.outcomes[i].estimate.certificate.oc.passed);
    CHECK(result.outcomes[i].estimate.certificate.oc.eps_oc == expected.eps_oc);
    CHECK(result.outcomes[i].uncorrected->certificate.oc.passed ==
          again.outcomes[i].uncorrected->certificate.oc.passed);
  }
  CHECK(result.certified == again.certified);
  CHECK(result.oc == again.oc);
}

TEST_CASE("--eps-oc auto with a budget m: the m farthest points never set eps_oc, oc_m and nd_m decided again") {
  const Fixture f;
  constexpr int kStray = 3;
  // Every cloud gets kStray points moved one diameter away (stray pixels).
  std::vector<PointSet> clouds = f.clouds;
  for (PointSet& cloud : clouds) {
    for (int j = 0; j < kStray; ++j) cloud.col(j * 7) += Eigen::Vector3d(1.0, 0.5 * j, -0.3) * f.object.diameter();
  }
  CertifyBatchOptions options = f.Options();
  options.pipeline.certificate.max_outliers.count = kStray;
  // The corrector's restart distance defaults to eps_oc: fixed here so that the
  // estimates do not depend on the eps_oc being decided.
  options.pipeline.corrector.fast_restart_distance = f.object.spec().eps_oc;
  CertifyBatchOptions automatic = options;
  automatic.auto_eps_oc = true;
  const CertifyBatchResult result = CertifyBatch(f.object, InMemorySources(clouds, f.detected), nullptr, automatic);
  REQUIRE(result.auto_eps_oc.has_value());
  // Oracle: the (m+1)-th largest point distance of each estimate, sorted by hand.
  std::vector<double> budget_distances, max_distances;
  for (int i = 0; i < kClouds; ++i) {
    const PoseEstimate e = EstimateAndCertify(f.object, clouds[i], f.detected[i], options.pipeline);
    if (!e.ok()) continue;
    std::vector<double> d(e.certificate.oc.point_distances.data(),
                          e.certificate.oc.point_distances.data() + e.certificate.oc.point_distances.size());
    std::sort(d.begin(), d.end(), std::greater<double>());
    budget_distances.push_back(d[kStray]);
    max_distances.push_back(d[0]);
    CHECK(max_distances.back() > 0.5 * f.object.diameter());   // the stray points are there
  }
  const AutoEpsOcResult expected = EstimateEpsOc(f.object, clouds, AutoEpsOcOptions{}, &budget_distances);
  const AutoEpsOcResult from_max = EstimateEpsOc(f.object, clouds, AutoEpsOcOptions{}, &max_distances);
  CHECK(result.auto_eps_oc->eps_oc == expected.eps_oc);
  CHECK(result.auto_eps_oc->eps_oc < 0.5 * f.object.diameter());
  CHECK(from_max.eps_oc >= result.auto_eps_oc->eps_oc);
  // Each decision (oc_m, nd_m with the local test, certified) equals a run
  // with eps_oc fixed to the chosen value.
  CertifyBatchOptions fixed = options;
  fixed.pipeline.certificate.eps_oc = expected.eps_oc;
  const CertifyBatchResult again = CertifyBatch(f.object, InMemorySources(clouds, f.detected), nullptr, fixed);
  int certified = 0;
  for (int i = 0; i < kClouds; ++i) {
    CAPTURE(i);
    const Certificate& a = result.outcomes[i].estimate.certificate;
    const Certificate& b = again.outcomes[i].estimate.certificate;
    CHECK(a.oc.passed == b.oc.passed);
    CHECK(a.oc.outlier_count == b.oc.outlier_count);
    CHECK(a.nd.passed == b.nd.passed);
    CHECK(a.nd.keypoint_support == b.nd.keypoint_support);
    CHECK(a.nd.local.min_eigenvalue == b.nd.local.min_eigenvalue);
    certified += a.oc.passed && a.nd.passed;
  }
  CHECK(result.certified == again.certified);
  CHECK(result.nd == again.nd);
  CHECK(certified == result.certified);
  CHECK(result.oc > 0);   // the budget absorbs the stray points (nd_m may still refuse: > m supports)
}

TEST_CASE("CertifyBatch stops when an interrupt is requested") {
  const Fixture f;
  RequestInterrupt();
  CHECK_THROWS_AS(CertifyBatch(f.object, InMemorySources(f.clouds, f.detected), nullptr, f.Options()), Interrupted);
  ClearInterrupt();
  CHECK_NOTHROW(CertifyBatch(f.object, InMemorySources(f.clouds, f.detected), nullptr, f.Options()));
}

TEST_CASE("certify JSON lines: every field of the schema, in order, read back") {
  const Fixture f;
  const PoseEstimate e = EstimateAndCertify(f.object, f.clouds[0], f.detected[0], f.Options().pipeline);
  REQUIRE(e.ok());
  const std::string line = CertifyJsonLine("a.ply", e);
  CHECK(line.find('\n') == std::string::npos);
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(line);
  std::vector<std::string> keys;
  for (auto it = j.begin(); it != j.end(); ++it) keys.push_back(it.key());
  CHECK(keys == std::vector<std::string>{"cloud", "R", "t", "keypoints", "oc", "nd", "certified", "refused_by",
                                         "oc_distance",
                                         "keypoint_distance", "nd_set", "nd_set_distances", "eps_oc", "delta_nd",
                                         "iterations", "cost_before", "cost_after", "status", "restarts_tried",
                                         "restart_axis", "restart_angle_deg", "centred", "centred_fits", "max_outliers",
                                         "robust_loss", "robust_scale", "outliers", "unexplained_fraction", "outlier_indices", "outlier_indices_truncated",
                                         "distance_quantiles", "max_inlier_distance", "keypoint_support",
                                         "nd_set_support", "nd_sets", "nd_sets_used", "nd_local", "nd_local_eigenvalue",
                                         "nd_local_motion", "nd_local_rank", "nd_local_weak_motions",
                                         "nd_weak_motion", "weak_motion_starts", "weak_motion_rivals",
                                         "weak_motion_rival_step", "weak_motion_rival_hausdorff", "nd_global",
                                         "rivals_tried",
                                         "rivals_found", "rival_distance", "certified_bound", "rival_margin", "rival_hausdorff", "rival_outliers",
                                         "rival_axis", "rival_angle_deg", "rival_passes_oc",
                                         "rival_free_space_violations", "rival_counts", "rival_R", "rival_t", "free_space",
                                         "free_space_violations", "free_space_measured",
                                         "free_space_silhouette", "free_space_tolerance", "free_space_limit",
                                         "free_space_shift_px", "through_support", "seen_surface",
                                         "seen_outside_mask", "outside_mask_limit", "mask_at_depth", "mask_uncovered",
                                         "uncovered_mask_limit", "identity", "identity_objects", "identity_rival",
                                         "identity_rival_oc_distance", "identity_rival_R", "identity_rival_t", "ms",
                                         "ms_stages"});
  CHECK(j["cloud"] == "a.ply");
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) CHECK(j["R"][r][c].get<double>() == e.scene_from_model.R(r, c));
    CHECK(j["t"][r].get<double>() == e.scene_from_model.t(r));
  }
  REQUIRE(j["keypoints"].size() == static_cast<std::size_t>(f.object.num_keypoints()));
  CHECK(j["keypoints"][3][1].get<double>() == e.keypoints(1, 3));
  CHECK(j["certified"].get<bool>() == e.certified());
  std::vector<std::string> refused_by;
  for (const CertificatePart part : RefusedBy(e.certificate)) refused_by.push_back(ToString(part));
  CHECK(j["refused_by"].get<std::vector<std::string>>() == refused_by);
  CHECK(j["refused_by"].empty() == e.certified());
  PoseEstimate no_pose = e;   // no pose to certify: the refusal names the registration
  no_pose.correction.registration = RegistrationStatus::kCollinear;
  CHECK(nlohmann::json::parse(CertifyJsonLine("a.ply", no_pose))["refused_by"] ==
        nlohmann::json::array({"registration"}));
  CHECK(j["oc_distance"].get<double>() == e.certificate.oc.max_point_distance);
  CHECK(j["eps_oc"].get<double>() == e.certificate.oc.eps_oc);
  CHECK(j["iterations"].get<int>() == e.correction.iterations);
  // Outlier-robust evidence, read back against the certificate.
  const ObservableCorrectness& oc = e.certificate.oc;
  const NonDegeneracy& nd = e.certificate.nd;
  CHECK(j["max_outliers"].get<int>() == oc.max_outliers);
  CHECK(j["robust_loss"] == "none");
  CHECK(j["robust_scale"].get<double>() == 0.0);
  CHECK(j["outliers"].get<int>() == oc.outlier_count);
  CHECK(j["outlier_indices"].get<std::vector<int>>() == oc.outlier_indices);
  CHECK(j["outlier_indices_truncated"].get<bool>() == false);
  REQUIRE(j["distance_quantiles"].size() == 4);
  CHECK(j["distance_quantiles"][0].get<double>() == oc.quantile50);
  CHECK(j["distance_quantiles"][3].get<double>() == oc.max_point_distance);
  CHECK(j["max_inlier_distance"].get<double>() == oc.max_inlier_distance);
  CHECK(j["keypoint_support"].get<std::vector<int>>() == nd.keypoint_support);
  CHECK(j["nd_set_support"].get<std::vector<int>>() == nd.set_min_support);
  CHECK(j["nd_sets"].get<bool>() == nd.sets_passed);
  CHECK(j["nd_sets_used"].get<bool>() == nd.sets_used);
  REQUIRE(nd.local_checked);
  CHECK(j["nd_local"].get<bool>() == nd.local.passed);
  CHECK(j["nd_local_eigenvalue"].get<double>() == nd.local.min_eigenvalue);
  REQUIRE(j["nd_local_motion"].size() == 6);
  for (int k = 0; k < 6; ++k) CHECK(j["nd_local_motion"][k].get<double>() == nd.local.motion(k));
  CHECK(j["nd_local_rank"].get<int>() == nd.local.model_rank);
  // The global rival search ran (everything else passed) and is reported.
  if (e.certificate.oc.passed && nd.sets_passed && nd.local.passed) {
    REQUIRE(nd.global_checked);
    CHECK(j["nd_global"].get<bool>() == nd.global.passed);
    CHECK(j["rivals_tried"].get<int>() == nd.global.rivals_tried);
    CHECK(j["rivals_found"].get<int>() == nd.global.rivals_found);
  } else {
    CHECK(j["nd_global"].is_null());
  }
  if (nd.global.rival_axis >= 0) {
    CHECK(j["rival_R"][2][1].get<double>() == nd.global.rival_scene_from_model.R(2, 1));
    CHECK(j["rival_t"][0].get<double>() == nd.global.rival_scene_from_model.t(0));
  } else {
    CHECK(j["rival_R"].is_null());
    CHECK(j["rival_t"].is_null());
  }
  CHECK(j["free_space"].is_null());   // a ready-made cloud: no depth frame
  CHECK(j["identity"].is_null());   // no other objects named
  CHECK(j["identity_objects"] == 0);
  CHECK(j["identity_rival"].is_null());
  CHECK(j["identity_rival_R"].is_null());
  // Outlier indices are capped at kMaxListedOutliers; the count stays exact.
  PoseEstimate many = e;
  many.certificate.oc.outlier_indices.resize(kMaxListedOutliers + 5);
  for (std::size_t k = 0; k < many.certificate.oc.outlier_indices.size(); ++k) many.certificate.oc.outlier_indices[k] = static_cast<int>(k);
  many.certificate.oc.outlier_count = static_cast<int>(kMaxListedOutliers + 5);
  const nlohmann::json capped = nlohmann::json::parse(CertifyJsonLine("m.ply", many));
  CHECK(capped["outlier_indices"].size() == kMaxListedOutliers);
  CHECK(capped["outlier_indices_truncated"].get<bool>());
  CHECK(capped["outliers"].get<int>() == static_cast<int>(kMaxListedOutliers + 5));
  // With the local test off, nd_local is null.
  PoseEstimate off = e;
  off.certificate.nd.local_checked = false;
  CHECK(nlohmann::json::parse(CertifyJsonLine("o.ply", off))["nd_local"].is_null());
  // Non-finite numbers become null; errors have their own line.
  PoseEstimate failed = e;
  failed.certificate.oc.max_point_distance = std::numeric_limits<double>::infinity();
  failed.correction.cost_after = std::nan("");
  const nlohmann::json k = nlohmann::json::parse(CertifyJsonLine("b.ply", failed));
  CHECK(k["oc_distance"].is_null());
  CHECK(k["cost_after"].is_null());
  CHECK(CertifyErrorJsonLine("c.ply", "c.ply: cannot open") == R"({"cloud":"c.ply","error":"c.ply: cannot open"})");
}

TEST_CASE("certify JSON lines: the corrector's robust kernel and its truncation (the certified eps_oc)") {
  const Fixture f;
  PipelineOptions options = f.Options().pipeline;
  options.corrector.robust_loss = RobustLoss::kTruncated;
  options.certificate.eps_oc *= 0.5;   // the truncation follows the threshold certified, not the file's
  const PoseEstimate e = EstimateAndCertify(f.object, f.clouds[0], f.detected[0], options);
  REQUIRE(e.ok());
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(CertifyJsonLine("a.ply", e));
  CHECK(j["robust_loss"] == "tls");
  CHECK(j["robust_scale"].get<double>() == options.certificate.eps_oc);
}

TEST_CASE("certify JSON lines: the reported rival's pose, read back exactly (null without one)") {
  const Fixture f;
  PoseEstimate e = EstimateAndCertify(f.object, f.clouds[0], f.detected[0], f.Options().pipeline);
  REQUIRE(e.ok());
  // A rival as CheckGlobalUniqueness reports it: the estimate turned by a half-turn.
  Rng rng(5);
  GlobalUniqueness& g = e.certificate.nd.global;
  g.rival_axis = 1;
  g.rival_scene_from_model = Pose{rng.Rotation(), Eigen::Vector3d(0.1, -0.2, 0.9)};
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(CertifyJsonLine("a.ply", e));
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) CHECK(j["rival_R"][r][c].get<double>() == g.rival_scene_from_model.R(r, c));
    CHECK(j["rival_t"][r].get<double>() == g.rival_scene_from_model.t(r));
  }
  g.rival_axis = -1;   // every rival fell back into the estimate's basin: nothing to show
  const nlohmann::ordered_json none = nlohmann::ordered_json::parse(CertifyJsonLine("a.ply", e));
  CHECK(none["rival_R"].is_null());
  CHECK(none["rival_t"].is_null());
}
