// Poses from other estimators: the BOP CSV / JSON-lines reader (round trip
// of known poses, bad inputs) and certifying given poses through the batch
// path (the ground truth and the Hausdorff distance are the oracle).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "asymmetric_object.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/eval/metrics.hpp"
#include "c3po/geometry/distances.hpp"
#include "c3po/io/pose_list.hpp"
#include "c3po/method/given_poses.hpp"

using namespace c3po;

namespace {

std::string Row(const Pose& pose, int scene, int im, int obj, double score) {
  char text[1024];
  const Eigen::Matrix3d& R = pose.R;
  const Eigen::Vector3d t = pose.t * 1000.0;
  std::snprintf(text, sizeof text, "%d,%d,%d,%.17g,%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g,%.17g %.17g %.17g,-1\n",
                scene, im, obj, score, R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2),
                t(0), t(1), t(2));
  return text;
}

}  // namespace

TEST_CASE("BOP CSV and JSON lines give back the poses written") {
  Rng rng(4);
  const Pose a{rng.Rotation(), Eigen::Vector3d(0.01, -0.2, 0.7)};
  const Pose b{rng.Rotation(), Eigen::Vector3d(-0.1, 0.05, 1.2)};
  const std::string csv = "scene_id,im_id,obj_id,score,R,t,time\n" + Row(a, 3, 7, 5, 0.9) + "\n" + Row(b, 3, 8, 5, 0.1);
  const auto poses = ParsePoseList(csv, "test.csv");
  REQUIRE(poses.size() == 2);
  CHECK(poses[0].line == 2);
  CHECK(poses[1].line == 4);
  CHECK(*poses[0].scene_id == 3);
  CHECK(*poses[1].im_id == 8);
  CHECK(*poses[0].obj_id == 5);
  CHECK(poses[0].score == 0.9);
  CHECK((poses[0].scene_from_model.R - a.R).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((poses[1].scene_from_model.t - b.t).cwiseAbs().maxCoeff() < 1e-12);   // mm -> m
  CHECK(PoseMatchKey(poses[1]) == "3/8");

  const std::string jsonl = "{\"cloud\": \"x.ply\", \"R\": [[1,0,0],[0,1,0],[0,0,1]], \"t\": [1, 2, 3], \"score\": 2}\n";
  const auto json_poses = ParsePoseList(jsonl, "test.jsonl");
  REQUIRE(json_poses.size() == 1);
  CHECK(json_poses[0].cloud == "x.ply");
  CHECK(json_poses[0].scene_from_model.t == Eigen::Vector3d(1, 2, 3));   // object units, no conversion
  CHECK(json_poses[0].score == 2);
  CHECK(PoseMatchKey(json_poses[0]) == "x.ply");
}

TEST_CASE("Pose files with bad content are refused with the line and field") {
  const std::string header = "scene_id,im_id,obj_id,score,R,t,time\n";
  auto message = [](const std::string& text) {
    try {
      ParsePoseList(text, "p");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK(message("") == "p: empty pose file");
  CHECK(message(header).find("no pose line") != std::string::npos);
  CHECK(message("a,b,c\n").find("line 1: header") != std::string::npos);
  CHECK(message(header + "1,2,3,0.5,1 0 0 0 1 0 0 0 1,0 0 0\n").find("line 2: row") != std::string::npos);
  CHECK(message(header + "1,2,3,0.5,1 0 0 0 1 0 0 0,0 0 0,1\n").find("line 2: R") != std::string::npos);
  CHECK(message(header + "1,2,3,0.5,2 0 0 0 1 0 0 0 1,0 0 0,1\n").find("not a rotation") != std::string::npos);
  CHECK(message(header + "1,2,3,0.5,-1 0 0 0 1 0 0 0 1,0 0 0,1\n").find("reflection") != std::string::npos);
  CHECK(message(header + "1,2,3,0.5,1 0 0 0 1 0 0 0 1,0 nan 0,1\n").find("line 2: t") != std::string::npos);
  CHECK(message(header + "-1,2,3,0.5,1 0 0 0 1 0 0 0 1,0 0 0,1\n").find("scene_id") != std::string::npos);
  CHECK(message(header + "1,2,3,x,1 0 0 0 1 0 0 0 1,0 0 0,1\n").find("score") != std::string::npos);
  CHECK(message("{\"R\": [[1,0,0],[0,1,0],[0,0,1]], \"t\": [0,0,0]}\n").find("line 1: cloud") != std::string::npos);
  CHECK(message("{\"cloud\": \"a\", \"t\": [0,0,0]}\n").find("line 1: R") != std::string::npos);
  CHECK(message("{\"cloud\": \"a\", \"R\": [[1,0,0],[0,1,0],[0,0,1]]}\n").find("line 1: t") != std::string::npos);
  CHECK(message("{\"cloud\": \"a\"\n").find("not valid JSON") != std::string::npos);
  CHECK(message("{\"cloud\": \"a\", \"R\": [[1,0,0],[0,1,0],[0,0,1]], \"t\": [0,0,1e999]}\n") != "accepted");
  CHECK_THROWS_AS(ReadPoseList("/nonexistent/poses.csv"), InputError);
}

TEST_CASE("Given poses are certified as they are: only the right one passes, and it is chosen") {
  ObjectModel object = test::AsymmetricObject();
  // One indicator set of every keypoint (all are seen in a full-surface cloud).
  object.mutable_spec().indicator_sets = {{0, 1, 2, 3, 4}};
  // Thresholds above the sampling density of B̂ and of the cloud (eps_s, Theorem 12).
  object.mutable_spec().eps_oc = 0.012;
  object.mutable_spec().delta_nd = 0.015;
  Rng rng(8);
  const Pose truth{rng.Rotation(), Eigen::Vector3d(0.05, -0.02, 0.8)};
  const PointSet cloud = truth * SampleSurface(object.mesh(), 6000, 3);
  const std::vector<PointSet> clouds = {cloud};
  std::vector<CloudSource> sources = InMemorySources(clouds);
  REQUIRE(sources.size() == 1);
  const std::string name = sources[0].name;

  Pose wrong = truth;
  wrong.R = truth.R * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Pose shifted = truth;
  shifted.t += Eigen::Vector3d(0.0005, 0, 0);
  std::vector<PoseHypothesis> poses(4);
  poses[0].cloud = name; poses[0].line = 1; poses[0].scene_from_model = wrong; poses[0].score = 0.99;
  poses[1].cloud = name; poses[1].line = 2; poses[1].scene_from_model = shifted; poses[1].score = 0.5;
  poses[2].cloud = name; poses[2].line = 3; poses[2].scene_from_model = truth; poses[2].score = 0.1;
  poses[3].cloud = "elsewhere.ply"; poses[3].line = 4;
  const GivenPoseSources matched = MatchGivenPoses(object, sources, poses);
  REQUIRE(matched.sources.size() == 3);
  CHECK(matched.unmatched == std::vector<std::size_t>{3});

  CertifyBatchOptions options;
  options.pipeline.correct = false;
  options.pipeline.certificate = CertificateOptions::FromObject(object.spec());
  const CertifyBatchResult result = CertifyBatch(object, matched.sources, nullptr, options);
  // Without correction the certified pose is the given one.
  for (std::size_t s = 0; s < 3; ++s) {
    const PoseChange change = ChangeBetween(poses[matched.hypothesis[s]].scene_from_model,
                                            result.outcomes[s].estimate.scene_from_model);
    CHECK(change.rotation_degrees < 1e-5);
    CHECK(change.translation < 1e-9);
  }
  // Oracle: the symmetric Hausdorff distance between the model posed at the
  // truth and at each pose; a certificate must not pass a far pose.
  for (std::size_t s = 0; s < 3; ++s) {
    const Pose& pose = poses[matched.hypothesis[s]].scene_from_model;
    const double hausdorff = HausdorffDistance(truth * object.sample(), pose * object.sample());
    if (result.outcomes[s].certified()) CHECK(hausdorff < 0.05 * object.diameter());
  }
  CHECK_FALSE(result.outcomes[0].certified());
  CHECK(result.outcomes[2].certified());
  const auto verdicts = ChooseCertified(matched, poses, result);
  REQUIRE(verdicts.size() == 1);
  REQUIRE(verdicts[0].chosen);
  // Best fit = the smallest oc distance among the certified hypotheses (never the wrong pose).
  const std::size_t chosen = *verdicts[0].chosen;
  CHECK(matched.hypothesis[chosen] != 0);
  for (std::size_t s = 0; s < 3; ++s) {
    if (result.outcomes[s].certified()) {
      CHECK(result.outcomes[chosen].estimate.certificate.oc.max_point_distance <=
            result.outcomes[s].estimate.certificate.oc.max_point_distance);
    }
  }

  CHECK(verdicts[0].best_fit == verdicts[0].chosen);   // the CSV row of a certified instance is its chosen one

  SUBCASE("without a certified hypothesis the CSV row is the best fit (brute force over the outcomes)") {
    CertifyBatchResult refused = result;
    for (CloudOutcome& outcome : refused.outcomes) outcome.estimate.certificate.oc.passed = false;
    const auto none = ChooseCertified(matched, poses, refused);
    REQUIRE(none.size() == 1);
    CHECK_FALSE(none[0].chosen);
    REQUIRE(none[0].best_fit);
    std::size_t smallest = 0;
    for (std::size_t s = 1; s < 3; ++s) {
      if (refused.outcomes[s].estimate.certificate.oc.max_point_distance <
          refused.outcomes[smallest].estimate.certificate.oc.max_point_distance) {
        smallest = s;
      }
    }
    CHECK(*none[0].best_fit == smallest);
    CHECK(matched.hypothesis[smallest] != 0);   // never the 90°-turned pose
  }

  SUBCASE("with correction the wrong start is reported with its change") {
    options.pipeline.correct = true;
    const CertifyBatchResult corrected = CertifyBatch(object, matched.sources, nullptr, options);
    const PoseChange change = ChangeBetween(wrong, corrected.outcomes[0].estimate.scene_from_model);
    CHECK(std::isfinite(change.rotation_degrees));
    if (corrected.outcomes[0].certified()) {
      CHECK(HausdorffDistance(truth * object.sample(), corrected.outcomes[0].estimate.scene_from_model * object.sample()) <
            0.05 * object.diameter());
    }
  }
}

TEST_CASE("BOP rows (no gt_id) are hypotheses for every instance of their object in their image") {
  ObjectModel object = test::AsymmetricObject();
  object.mutable_spec().indicator_sets = {{0, 1, 2, 3, 4}};
  object.mutable_spec().eps_oc = 0.012;
  object.mutable_spec().delta_nd = 0.015;
  Rng rng(11);
  // Two instances of obj 5 in scene 0 image 1 (apart), one in image 2.
  const std::vector<Pose> truth = {{rng.Rotation(), Eigen::Vector3d(-0.3, 0.0, 1.0)},
                                   {rng.Rotation(), Eigen::Vector3d(0.3, 0.05, 1.2)},
                                   {rng.Rotation(), Eigen::Vector3d(0.0, 0.0, 0.9)}};
  std::vector<PointSet> clouds;
  for (const Pose& pose : truth) clouds.push_back(pose * SampleSurface(object.mesh(), 6000, 3));
  std::vector<CloudSource> sources = InMemorySources(clouds);
  const int image[] = {1, 1, 2}, gt[] = {0, 1, 0};
  for (int k = 0; k < 3; ++k) {
    CloudProvenance provenance;
    provenance.scene_id = 0;
    provenance.im_id = image[k];
    provenance.gt_id = gt[k];
    provenance.obj_id = 5;
    sources[k].provenance = provenance;
  }
  const std::string csv = "scene_id,im_id,obj_id,score,R,t,time\n" + Row(truth[0], 0, 1, 5, 0.4) +
                          Row(truth[1], 0, 1, 5, 0.9) + Row(truth[2], 0, 2, 5, 0.5) +
                          Row(truth[0], 0, 1, 9, 1.0) +   // another object: skipped, listed
                          Row(truth[2], 0, 3, 5, 1.0);    // no such image: unmatched
  const std::vector<PoseHypothesis> poses = ParsePoseList(csv, "rows.csv");
  REQUIRE(poses.size() == 5);
  const GivenPoseSources matched = MatchGivenPoses(object, sources, poses);
  // Rows 0 and 1 on both instances of image 1, row 2 on image 2's instance.
  REQUIRE(matched.sources.size() == 5);
  CHECK(matched.hypothesis == std::vector<std::size_t>{0, 0, 1, 1, 2});
  CHECK(matched.instance == std::vector<std::size_t>{0, 1, 0, 1, 2});
  CHECK(matched.other_object == std::vector<std::size_t>{3});
  CHECK(matched.unmatched == std::vector<std::size_t>{4});

  CertifyBatchOptions options;
  options.pipeline.correct = false;
  options.pipeline.certificate = CertificateOptions::FromObject(object.spec());
  const CertifyBatchResult result = CertifyBatch(object, matched.sources, nullptr, options);
  for (std::size_t s = 0; s < matched.sources.size(); ++s) {
    CAPTURE(s);
    const bool own = matched.hypothesis[s] == matched.instance[s];   // row k is instance k's pose here
    const double hausdorff = HausdorffDistance(truth[matched.instance[s]] * object.sample(),
                                               poses[matched.hypothesis[s]].scene_from_model * object.sample());
    CHECK(result.outcomes[s].certified() == own);
    if (result.outcomes[s].certified()) CHECK(hausdorff < 0.05 * object.diameter());
  }
  const auto verdicts = ChooseCertified(matched, poses, result);
  REQUIRE(verdicts.size() == 3);
  for (const auto& verdict : verdicts) {
    CAPTURE(verdict.instance);
    REQUIRE(verdict.chosen);
    CHECK(matched.hypothesis[*verdict.chosen] == verdict.instance);   // its own row, whatever the scores
  }

  SUBCASE("without BOP sources a row with ids is unmatched, not another object's") {
    const std::vector<CloudSource> plain = InMemorySources(clouds);
    const GivenPoseSources none = MatchGivenPoses(object, plain, poses);
    CHECK(none.sources.empty());
    CHECK(none.other_object.empty());
    CHECK(none.unmatched.size() == poses.size());
  }
}
