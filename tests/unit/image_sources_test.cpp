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
