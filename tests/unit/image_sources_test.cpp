// Image inputs as CloudSources (method/image_sources.hpp) against independent
// oracles: the sources' segments certified by CertifyBatch equal
// EstimateAndCertify on the same points; a too-small segment is a per-source
// error that keeps its counts; --shard parts concatenate to the whole list and
// never split an image (brute force over N); BOP rows: one per BOP source with
// a pose, score > 1 exactly when certified, time = the image's summed seconds.
#include <doctest/doctest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "c3po/method/image_sources.hpp"
#include "evaluation_fixture.hpp"

using namespace c3po;

namespace {

constexpr int kClouds = 8;

// A segment whose cloud is `cloud`, with made-up but consistent counts.
SegmentCloud SegmentOf(const PointSet& cloud) {
  SegmentCloud s;
  s.cloud = cloud;
  s.pixels.resize(static_cast<std::size_t>(cloud.cols()));
  for (std::size_t i = 0; i < s.pixels.size(); ++i) s.pixels[i] = static_cast<std::int32_t>(i);
  s.no_depth = 7;
  s.removed_by_erosion = 5;
  s.removed_by_discontinuity = 3;
  s.removed_by_plane = 4;
  s.removed_by_subsampling = 2;
  s.mask_pixels = s.pixels.size() + 21;
  return s;
}

// BOP-like sources: image (scene, im) = (i / 4, i / 2 % 2), two per image.
std::vector<CloudSource> Sources(const std::vector<PointSet>& clouds, const std::vector<Pose>& poses) {
  std::vector<CloudSource> sources;
  for (int i = 0; i < static_cast<int>(clouds.size()); ++i) {
    CloudSource source;
    source.name = "s" + std::to_string(i);
    const PointSet* cloud = &clouds[static_cast<std::size_t>(i)];
    source.load_segment = [cloud]() { return SegmentOf(*cloud); };
    CloudProvenance p;
    p.scene_id = i / 4;
    p.im_id = i / 2 % 2;
    p.gt_id = i % 2;
    p.obj_id = 5;
    source.provenance = p;
    source.scene_from_model_truth = poses[static_cast<std::size_t>(i)];
    sources.push_back(std::move(source));
  }
  return sources;
}

}  // namespace

TEST_CASE("segment sources: CertifyBatch equals EstimateAndCertify, counts and ids in the JSON line") {
  const ObjectModel object = test::EvaluationObject();
  const std::vector<Pose> poses = test::EvaluationPoses(kClouds);
  std::vector<PointSet> clouds, detected;
  for (int i = 0; i < kClouds; ++i) {
    clouds.push_back(test::EvaluationCloud(object, poses[i], i));
    detected.push_back(test::DetectedKeypoints(object, poses[i], i));
  }
  clouds[3] = clouds[3].leftCols(2).eval();   // too few points (eval: no aliasing): an error
  std::vector<CloudSource> sources = Sources(clouds, poses);
  for (int i = 0; i < kClouds; ++i) sources[i].given_keypoints = detected[i];
  CertifyBatchOptions options;
  options.pipeline.certificate = CertificateOptions::FromObject(object.spec());
  const CertifyBatchResult result = CertifyBatch(object, sources, nullptr, options);
  REQUIRE(result.outcomes.size() == static_cast<std::size_t>(kClouds));
  CHECK(result.errors == 1);
  for (int i = 0; i < kClouds; ++i) {
    const CloudOutcome& outcome = result.outcomes[i];
    REQUIRE(outcome.segment.has_value());
    CHECK(outcome.segment->cloud.cols() == 0);   // dropped, counts kept
    CHECK(outcome.segment->pixels.size() == static_cast<std::size_t>(clouds[i].cols()));
    const nlohmann::json line = nlohmann::json::parse(CertifyJsonLine(sources[i], outcome));
    CHECK(line.at("cloud") == sources[i].name);
    CHECK(line.at("scene_id") == i / 4);
    CHECK(line.at("im_id") == i / 2 % 2);
    CHECK(line.at("gt_id") == i % 2);
    CHECK(line.at("obj_id") == 5);
    CHECK(line.at("pixels").get<std::size_t>() ==
          line.at("no_depth").get<std::size_t>() + line.at("removed_erosion").get<std::size_t>() +
              line.at("removed_discontinuity").get<std::size_t>() + line.at("removed_plane").get<std::size_t>() +
              line.at("removed_subsampling").get<std::size_t>() + line.at("points").get<std::size_t>());
    CHECK(line.at("gt_t")[2].get<double>() == poses[i].t(2));
    if (i == 3) {
      CHECK(!outcome.processed());
      CHECK(line.at("error").get<std::string>().find("s3: only 2 points left") == 0);
      CHECK(!line.contains("R"));
      continue;
    }
    REQUIRE(outcome.processed());
    const PoseEstimate direct = EstimateAndCertify(object, clouds[i], detected[i], options.pipeline);
    CHECK(outcome.estimate.certified() == direct.certified());
    CHECK((outcome.estimate.scene_from_model.R - direct.scene_from_model.R).norm() == 0.0);
    CHECK(line.at("certified") == direct.certified());
    CHECK(line.at("R")[0][0].get<double>() == direct.scene_from_model.R(0, 0));
    CHECK(outcome.seconds > 0.0);
  }
  // Key order: ids, then counts, then ground truth, then the estimate.
  const std::string text = CertifyJsonLine(sources[0], result.outcomes[0]);
  CHECK(text.find("\"scene_id\"") < text.find("\"pixels\""));
  CHECK(text.find("\"points\"") < text.find("\"gt_R\""));
  CHECK(text.find("\"gt_t\"") < text.find("\"R\""));

  // BOP rows: one per source with a pose (registration succeeded); time
  // summed over the image, failed sources included.
  const std::vector<BopResultRow> rows = BopResultRows(sources, result);
  std::vector<int> with_pose;
  for (int i = 0; i < kClouds; ++i) {
    if (result.outcomes[i].processed() && result.outcomes[i].estimate.ok()) with_pose.push_back(i);
  }
  CHECK(with_pose.size() < static_cast<std::size_t>(kClouds));   // source 3 at least
  REQUIRE(rows.size() == with_pose.size());
  std::map<std::pair<int, int>, double> seconds;
  for (int i = 0; i < kClouds; ++i) seconds[{i / 4, i / 2 % 2}] += result.outcomes[i].seconds;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const int i = with_pose[r];
    const BopResultRow& row = rows[r];
    CHECK(row.scene_id == i / 4);
    CHECK(row.im_id == i / 2 % 2);
    CHECK(row.obj_id == 5);
    CHECK((row.score > 1.0) == result.outcomes[i].estimate.certified());
    CHECK(row.time == seconds[{row.scene_id, row.im_id}]);
    CHECK((row.camera_from_model.t - result.outcomes[i].estimate.scene_from_model.t).norm() == 0.0);
  }
}

TEST_CASE("ShardSources: parts 1..N concatenate to the list, an image's instances stay in one part") {
  std::vector<CloudSource> sources;
  // Images of 1-3 instances, with plain sources (groups of their own) between.
  for (int image = 0; image < 7; ++image) {
    for (int k = 0; k <= image % 3; ++k) {
      CloudSource source;
      source.name = "b" + std::to_string(image) + "_" + std::to_string(k);
      CloudProvenance p;
      p.scene_id = image / 3;
      p.im_id = image;
      p.gt_id = k;
      source.provenance = p;
      sources.push_back(source);
    }
    CloudSource plain;
    plain.name = "c" + std::to_string(image);
    sources.push_back(plain);
  }
  for (int n = 1; n <= 16; ++n) {
    std::vector<std::string> joined;
    std::map<std::string, int> part_of_image;
    for (int k = 1; k <= n; ++k) {
      for (const CloudSource& source : ShardSources(sources, Shard{k, n})) {
        joined.push_back(source.name);
        if (source.provenance) {
          const std::string image = std::to_string(source.provenance->im_id);
          const auto [it, inserted] = part_of_image.emplace(image, k);
          CHECK(it->second == k);
        }
      }
    }
    REQUIRE(joined.size() == sources.size());
    for (std::size_t i = 0; i < sources.size(); ++i) CHECK(joined[i] == sources[i].name);
  }
}

TEST_CASE("segment evidence: the pose is fitted to the cloud, the certificate judges the evidence") {
  const ObjectModel object = test::EvaluationObject();
  const std::vector<Pose> poses = test::EvaluationPoses(1);
  const PointSet cloud = test::EvaluationCloud(object, poses[0], 0);
  const PointSet detected = test::DetectedKeypoints(object, poses[0], 0);
  // The evidence: the cloud and 30 points 0.5 m beyond its centroid (stray
  // pixels the estimate's erosion removed).
  const int strays = 30;
  PointSet evidence(3, cloud.cols() + strays);
  evidence.leftCols(cloud.cols()) = cloud;
  const Eigen::Vector3d far = cloud.rowwise().mean() + Eigen::Vector3d(0.0, 0.0, 0.5);
  for (int k = 0; k < strays; ++k) evidence.col(cloud.cols() + k) = far + Eigen::Vector3d(0.001 * k, 0.0, 0.0);
  CloudSource source;
  source.name = "s0";
  source.given_keypoints = detected;
  source.load_segment = [&]() {
    SegmentCloud s = SegmentOf(cloud);
    s.evidence = evidence;
    s.evidence_points = static_cast<std::size_t>(evidence.cols());
    return s;
  };
  CertifyBatchOptions options;
  options.pipeline.certificate = CertificateOptions::FromObject(object.spec());
  for (const int budget : {strays - 1, strays}) {
    CAPTURE(budget);
    options.pipeline.certificate.max_outliers.count = budget;
    const PoseEstimate on_cloud = EstimateAndCertify(object, cloud, detected, options.pipeline);
    REQUIRE(on_cloud.certificate.oc.passed);   // the strays are what fails below
    REQUIRE(on_cloud.certificate.oc.outlier_count == 0);
    Eigen::Index visited_points = -1;
    const CertifyBatchResult result =
        CertifyBatch(object, {source}, nullptr, options, {},
                     [&](std::size_t, const PointSet& judged, const FreeSpaceTest*, CloudOutcome*) {
                       visited_points = judged.cols();
                     });
    REQUIRE(result.outcomes[0].processed());
    const PoseEstimate& e = result.outcomes[0].estimate;
    // Oracles: the corrector on the cloud alone; Certify on the evidence.
    CHECK((e.scene_from_model.R - on_cloud.scene_from_model.R).norm() == 0.0);
    CHECK((e.scene_from_model.t - on_cloud.scene_from_model.t).norm() == 0.0);
    const Certificate judged =
        Certify(object, evidence, e.scene_from_model, e.keypoints, options.pipeline.certificate);
    CHECK(e.certificate.oc.outlier_count == judged.oc.outlier_count);
    CHECK(e.certificate.oc.outlier_count == strays);
    CHECK(e.certificate.oc.passed == (budget >= strays));
    CHECK(visited_points == evidence.cols());
    const nlohmann::json line = nlohmann::json::parse(CertifyJsonLine(source, result.outcomes[0]));
    CHECK(line.at("points").get<Eigen::Index>() == cloud.cols());
    CHECK(line.at("evidence_points").get<Eigen::Index>() == evidence.cols());
  }
}
