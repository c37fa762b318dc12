// Evaluation against brute-force oracles on a tiny dataset with known poses
// (evaluation_fixture.hpp): poses, ADD-S, certificates, scores, AUC, medians,
// subsets and false certificates are recomputed here independently.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>

#include "c3po/base/error.hpp"
#include "c3po/eval/evaluation.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/method/free_space.hpp"
#include "brute_force.hpp"
#include "evaluation_fixture.hpp"
#include "test_helpers.hpp"

using namespace c3po;
using namespace c3po::test;

namespace {

constexpr int kClouds = 12;

// mean_i min_j ||a_i - b_j||, by brute force.
double MeanNearest(const PointSet& a, const PointSet& b) {
  double sum = 0.0;
  for (Eigen::Index i = 0; i < a.cols(); ++i) sum += (b.colwise() - a.col(i)).colwise().norm().minCoeff();
  return sum / static_cast<double>(a.cols());
}

double BruteAddS(const ObjectModel& object, const Pose& truth, const Pose& estimate, AddSVariant variant) {
  const PointSet a = truth * object.sample(), b = estimate * object.sample();
  return MeanNearest(a, b) + (variant == AddSVariant::kSymmetric ? MeanNearest(b, a) : 0.0);
}

// oc and nd of an estimate by brute force (docs/method.md "Certificates").
std::pair<bool, bool> BruteCertificate(const ObjectModel& object, const PointSet& cloud, const Pose& estimate,
                                       const PointSet& keypoints, double eps_oc, double delta_nd) {
  const PointSet posed = estimate * object.sample();
  double worst = 0.0;
  for (Eigen::Index i = 0; i < cloud.cols(); ++i) worst = std::max(worst, DistanceToSet(cloud.col(i), posed));
  const PointSet posed_keypoints = estimate * object.keypoints();
  const double agreement = (keypoints - posed_keypoints).colwise().norm().maxCoeff();
  const bool oc = worst < eps_oc && agreement < eps_oc;
  bool nd = object.spec().indicator_sets.empty();
  for (const auto& set : object.spec().indicator_sets) {
    bool all_near = true;
    for (int k : set) all_near = all_near && DistanceToSet(posed_keypoints.col(k), cloud) < delta_nd;
    nd = nd || all_near;
  }
  return {oc, nd};
}

double BruteRotationError(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return std::acos(std::clamp(((a.transpose() * b).trace() - 1.0) / 2.0, -1.0, 1.0));
}

// (100 / m) * integral_0^m fraction{e < t} dt by the midpoint rule.
double NumericAuc(const std::vector<double>& errors, double m) {
  const int steps = 20000;
  double sum = 0.0;
  for (int s = 0; s < steps; ++s) {
    const double t = (s + 0.5) * m / steps;
    sum += std::count_if(errors.begin(), errors.end(), [t](double e) { return e < t; });
  }
  return 100.0 * sum / (steps * static_cast<double>(errors.size()));
}

double SortedMedian(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Fixture {
  ObjectModel object = EvaluationObject();
  TempDir dir{"evaluation_test"};
  Dataset dataset;
  std::vector<Pose> poses = EvaluationPoses(kClouds);
  Fixture() {
    WriteEvaluationDataset(object, dir / "data", kClouds);
    dataset = ReadDataset(dir / "data");
  }
};

// Every sample of `row` against the oracles; returns the brute-force ADD-S values.
std::vector<double> CheckSamples(const Fixture& f, const EvaluationRow& row, const EvaluationOptions& options) {
  std::vector<double> adds;
  for (const SampleResult& s : row.samples) {
    CAPTURE(row.label);
    CAPTURE(s.cloud);
    if (!s.ok()) {
      CHECK(std::isinf(s.adds));
      CHECK_FALSE(s.certified());
      adds.push_back(std::numeric_limits<double>::infinity());
      continue;
    }
    const Pose& truth = f.poses[s.index];
    const double expected = BruteAddS(f.object, truth, s.scene_from_model, options.adds_variant);
    CHECK(s.adds == doctest::Approx(expected).epsilon(1e-9));
    CHECK(s.rotation_error == doctest::Approx(BruteRotationError(s.scene_from_model.R, truth.R)).epsilon(1e-6));
    CHECK(s.translation_error == doctest::Approx((s.scene_from_model.t - truth.t).norm()).epsilon(1e-9));
    const auto [oc, nd] = BruteCertificate(f.object, f.dataset.LoadCloud(s.index), s.scene_from_model, s.keypoints,
                                           options.pipeline.certificate.eps_oc, options.pipeline.certificate.delta_nd);
    CHECK(s.oc == oc);
    CHECK(s.nd == nd);
    if (s.certified()) {
      CHECK(s.hausdorff == doctest::Approx(BrutePosedHausdorff(f.object, truth, s.scene_from_model)).epsilon(1e-9));
    } else {
      CHECK(std::isnan(s.hausdorff));
    }
    adds.push_back(expected);
  }
  return adds;
}

void CheckSummary(const EvaluationRow& row, const std::vector<double>& adds, const EvaluationOptions& options,
                  double diameter) {
  CAPTURE(row.label);
  const RowSummary& s = row.summary;
  const double n = static_cast<double>(adds.size());
  REQUIRE(s.n == static_cast<int>(adds.size()));
  const auto below = std::count_if(adds.begin(), adds.end(), [&](double a) { return a < options.adds_threshold; });
  CHECK(s.adds_score == doctest::Approx(100.0 * below / n));
  CHECK(s.adds_auc == doctest::Approx(NumericAuc(adds, options.auc_max)).epsilon(1e-3));
  std::vector<double> rotation, translation;
  int oc = 0, nd = 0, certified = 0, false_certificates = 0, false_hausdorff = 0;
  double max_hausdorff = 0.0;
  for (std::size_t k = 0; k < row.samples.size(); ++k) {
    const SampleResult& sample = row.samples[k];
    // (each rotation error was checked against the brute force in CheckSamples)
    rotation.push_back(sample.ok() ? sample.rotation_error : M_PI);
    translation.push_back(sample.translation_error);
    oc += sample.oc;
    nd += sample.nd;
    certified += sample.oc && sample.nd;
    false_certificates += sample.oc && sample.nd && !(adds[k] < options.adds_threshold);
    if (sample.oc && sample.nd) {
      // (each Hausdorff distance was checked against the brute force in CheckSamples)
      false_hausdorff += !(sample.hausdorff < options.adds_threshold);
      max_hausdorff = std::max(max_hausdorff, sample.hausdorff);
    }
  }
  CHECK(s.median_rotation_error == doctest::Approx(SortedMedian(rotation)));
  CHECK(s.median_translation_error_over_d == doctest::Approx(SortedMedian(translation) / diameter));
  CHECK(s.percent_oc == doctest::Approx(100.0 * oc / n));
  CHECK(s.percent_nd == doctest::Approx(100.0 * nd / n));
  CHECK(s.percent_certified == doctest::Approx(100.0 * certified / n));
  CHECK(s.false_certificates == false_certificates);
  CHECK(s.false_certificates_hausdorff == false_hausdorff);
  CHECK(s.max_certified_hausdorff == max_hausdorff);
}

}  // namespace

TEST_CASE("KeyPo, ICP and corrector rows match brute-force ADD-S, certificates and scores") {
  Fixture f;
  EvaluationOptions options = EvaluationOptions::Defaults(f.object);
  REQUIRE(options.adds_variant == AddSVariant::kSymmetric);
  const Evaluation e = Evaluate(f.object, f.dataset, {{"manifest", nullptr, false}}, options);
  REQUIRE(e.rows.size() == 4);
  CHECK(e.rows[0].label == "KeyPo (manifest)");
  CHECK(e.rows[1].label == "KeyPo (manifest) + ICP");
  CHECK(e.rows[2].label == "KeyPo (manifest) + RANSAC + ICP");
  CHECK(e.rows[3].label == "KeyPo (manifest) + corrector");
  CHECK(e.clouds == kClouds);
  // Every detection here is consistent (exact, or exactly turned): RANSAC keeps
  // every keypoint, so its start is eq. (8)'s and ICP ends at the same pose.
  for (int i = 0; i < kClouds; ++i) {
    const SampleResult& icp = e.rows[1].samples[i];
    const SampleResult& ransac = e.rows[2].samples[i];
    CAPTURE(i);
    CHECK(icp.ok() == ransac.ok());
    if (icp.ok() && ransac.ok()) {
      CHECK((icp.scene_from_model.R - ransac.scene_from_model.R).norm() < 1e-6);
      CHECK((icp.scene_from_model.t - ransac.scene_from_model.t).norm() < 1e-6);
    }
  }

  // The registration of exact keypoints is the pose that posed them.
  const EvaluationRow& keypo = e.rows[0];
  REQUIRE(keypo.samples.size() == kClouds);
  for (int i = 0; i < kClouds; ++i) {
    const SampleResult& s = keypo.samples[i];
    CAPTURE(i);
    CHECK(s.index == static_cast<std::size_t>(i));
    if (KindOf(i) == DetectedKind::kDegenerate) {
      CHECK_FALSE(s.ok());
      continue;
    }
    REQUIRE(s.ok());
    const Pose expected = KindOf(i) == DetectedKind::kTruth ? f.poses[i] : f.poses[i] * WrongTurn();
    CHECK((s.scene_from_model.R - expected.R).norm() < 1e-9);
    CHECK((s.scene_from_model.t - expected.t).norm() < 1e-9);
    // Exact keypoints on a cloud from the model sample: oc = 1; nd = 0 only on partial clouds.
    if (KindOf(i) == DetectedKind::kTruth) {
      CHECK(s.oc);
      CHECK(s.nd == !IsPartial(i));
    }
  }
  for (const auto& row : e.rows) CheckSummary(row, CheckSamples(f, row, options), options, f.object.diameter());
  // By construction: 6 exact detections (ADD-S 0), 3 wrong by 90 degrees, 3 failures.
  CHECK(keypo.summary.adds_score == doctest::Approx(50.0));
  CHECK(keypo.summary.failures == 3);
  CHECK(keypo.summary.percent_certified == doctest::Approx(100.0 * 4 / kClouds));
  CHECK(e.total_false_certificates() == 0);
  CHECK(EvaluationTable(e).find("Failures: KeyPo (manifest): 3 of 12 samples without a pose") != std::string::npos);
}

TEST_CASE("with the object's symmetries, rotation and translation errors are to the nearest symmetric truth") {
  // The fixture's wrong detections are posed at T·W (W: 90 degrees about z).
  // Declared a symmetry, W makes them exact (error 0 against T·W, analytic);
  // undeclared they are 90 degrees off; ADD-S does not change.
  Fixture f;
  EvaluationOptions plain = EvaluationOptions::Defaults(f.object);
  plain.run_icp = false;
  EvaluationOptions symmetric = plain;
  symmetric.symmetries = {WrongTurn()};
  const Evaluation e_plain = Evaluate(f.object, f.dataset, {{"manifest", nullptr, false}}, plain);
  const Evaluation e_symmetric = Evaluate(f.object, f.dataset, {{"manifest", nullptr, false}}, symmetric);
  const auto& a = e_plain.rows[0].samples;
  const auto& b = e_symmetric.rows[0].samples;
  for (int i = 0; i < kClouds; ++i) {
    CAPTURE(i);
    if (!a[i].ok()) continue;
    CHECK(b[i].adds == a[i].adds);
    if (KindOf(i) == DetectedKind::kWrongPose) {
      CHECK(a[i].rotation_error == doctest::Approx(M_PI / 2).epsilon(1e-9));
      CHECK(b[i].rotation_error < 1e-6);
      CHECK(b[i].translation_error < 1e-9);
    } else {
      CHECK(b[i].rotation_error == a[i].rotation_error);
      CHECK(b[i].translation_error == a[i].translation_error);
    }
  }
  CHECK(EvaluationTable(e_symmetric).find("to the nearest of the truth and its 1 symmetric pose") != std::string::npos);
  CHECK(EvaluationTable(e_plain).find("symmetric pose") == std::string::npos);
  symmetric.symmetries[0].t.x() = std::nan("");
  CHECK_THROWS_AS(symmetric.Check(), std::invalid_argument);
}

TEST_CASE("self-trained detectors give the C-3PO rows on the certified subsets") {
  Fixture f;
  EvaluationOptions options = EvaluationOptions::Defaults(f.object);
  options.adds_variant = AddSVariant::kOneSided;
  options.run_icp = false;
  const Evaluation e = Evaluate(f.object, f.dataset, {{"sim", nullptr, false}, {"self", nullptr, true}}, options);
  REQUIRE(e.rows.size() == 5);
  CHECK(e.rows[0].label == "KeyPo (sim)");
  CHECK(e.rows[1].label == "KeyPo (sim) + corrector");
  CHECK(e.rows[2].label == "C-3PO (self)");
  CHECK(e.rows[3].label == "C-3PO (self) (oc = 1)");
  CHECK(e.rows[4].label == "C-3PO (self) (oc = nd = 1)");
  CHECK(e.MainRow() == &e.rows[2]);
  // Same detections: the C-3PO row equals the corrector row sample by sample.
  const EvaluationRow& all = e.rows[2];
  REQUIRE(all.samples.size() == e.rows[1].samples.size());
  std::vector<std::size_t> oc_indices, certified_indices;
  for (std::size_t k = 0; k < all.samples.size(); ++k) {
    CHECK(all.samples[k].adds == e.rows[1].samples[k].adds);
    if (all.samples[k].oc) oc_indices.push_back(all.samples[k].index);
    if (all.samples[k].certified()) certified_indices.push_back(all.samples[k].index);
  }
  std::vector<std::size_t> got_oc, got_certified;
  for (const auto& s : e.rows[3].samples) got_oc.push_back(s.index);
  for (const auto& s : e.rows[4].samples) got_certified.push_back(s.index);
  CHECK(got_oc == oc_indices);
  CHECK(got_certified == certified_indices);
  CHECK(!certified_indices.empty());
  for (const auto& row : e.rows) CheckSummary(row, CheckSamples(f, row, options), options, f.object.diameter());
  CHECK(e.rows[4].summary.percent_certified == doctest::Approx(100.0));
}

TEST_CASE("loose certificate thresholds produce false certificates that are counted and listed worst first") {
  Fixture f;
  EvaluationOptions options = EvaluationOptions::Defaults(f.object);
  options.run_icp = false;
  options.pipeline.certificate.eps_oc = 2.0 * f.object.diameter();
  options.pipeline.certificate.delta_nd = 2.0 * f.object.diameter();
  options.worst_listed = 2;
  const Evaluation e = Evaluate(f.object, f.dataset, {{"m", nullptr, false}}, options);
  const EvaluationRow& keypo = e.rows[0];
  const std::vector<double> adds = CheckSamples(f, keypo, options);
  CheckSummary(keypo, adds, options, f.object.diameter());
  // The three 90-degree errors are now certified: three false certificates.
  std::vector<double> wrong;
  for (int i = 0; i < kClouds; ++i) {
    if (KindOf(i) == DetectedKind::kWrongPose) wrong.push_back(adds[i]);
  }
  std::sort(wrong.rbegin(), wrong.rend());
  CHECK(keypo.summary.false_certificates == 3);
  REQUIRE(keypo.summary.worst_false_certificates.size() == 2);
  CHECK(keypo.summary.worst_false_certificates[0].adds == doctest::Approx(wrong[0]));
  CHECK(keypo.summary.worst_false_certificates[1].adds == doctest::Approx(wrong[1]));
  CHECK(e.total_false_certificates() >= 3);
  CHECK(keypo.summary.false_certificates_hausdorff >= 3);   // a 90-degree turn moves the model by more than 5 % d
  CHECK(keypo.summary.max_certified_hausdorff > options.adds_threshold);
  const std::string table = EvaluationTable(e);
  CHECK(table.find("Soundness: " + std::to_string(e.total_false_certificates()) + " false certificates") !=
        std::string::npos);
  CHECK(table.find("ADD-S variant: symmetric") != std::string::npos);
  CHECK(table.find("Hausdorff check: " + std::to_string(e.total_false_certificates_hausdorff()) +
                   " certified outputs") != std::string::npos);
}

TEST_CASE("Summarize: empty subsets, failures and the false-certificate order") {
  EvaluationOptions options;
  options.adds_threshold = 1.0;
  options.auc_max = 2.0;
  const RowSummary empty = Summarize({}, options, 1.0);
  CHECK(empty.n == 0);
  CHECK(std::isnan(empty.adds_score));
  CHECK(std::isnan(empty.percent_certified));

  std::vector<SampleResult> samples(4);
  const double adds[] = {0.5, 3.0, 1.0, std::numeric_limits<double>::infinity()};
  for (int k = 0; k < 4; ++k) {
    samples[k].index = k;
    samples[k].cloud = "c" + std::to_string(k);
    samples[k].adds = adds[k];
    samples[k].oc = samples[k].nd = k < 3;
  }
  samples[0].hausdorff = 0.9;   // certified, ADD-S fine, Hausdorff fine
  samples[1].hausdorff = 4.0;
  // samples[2]: certified without a Hausdorff distance (NaN) counts as false
  samples[3].error = "registration failed";
  const RowSummary s = Summarize(samples, options, 1.0);
  CHECK(s.failures == 1);
  CHECK(s.adds_score == doctest::Approx(25.0));               // only 0.5 < 1 (strict)
  CHECK(s.adds_auc == doctest::Approx(NumericAuc({0.5, 3.0, 1.0, INFINITY}, 2.0)).epsilon(1e-3));
  CHECK(s.false_certificates == 2);                          // 3.0 and 1.0 (not below 1.0)
  CHECK(s.false_certificates_hausdorff == 2);                // 4.0 and NaN
  CHECK(s.max_certified_hausdorff == 4.0);
  REQUIRE(s.worst_false_certificates.size() == 2);
  CHECK(s.worst_false_certificates[0].cloud == "c1");
  CHECK(s.worst_false_certificates[1].cloud == "c2");
}

TEST_CASE("a dataset without ground truth or without detected keypoints is an input error") {
  const ObjectModel object = EvaluationObject();
  TempDir dir("evaluation_test_bad");
  {
    DatasetWriter writer(dir / "nogt");
    DatasetEntry entry;
    entry.cloud = "a.ply";
    entry.detected_keypoints = object.keypoints();
    writer.Add(0, entry, object.sample());
    writer.Commit();
  }
  {
    DatasetWriter writer(dir / "nodet");
    DatasetEntry entry;
    entry.cloud = "a.ply";
    entry.pose = Pose::Identity();
    entry.keypoints = object.keypoints();
    writer.Add(0, entry, object.sample());
    writer.Commit();
  }
  const EvaluationOptions options = EvaluationOptions::Defaults(object);
  CHECK_THROWS_AS(Evaluate(object, ReadDataset(dir / "nogt"), {{"m", nullptr, false}}, options), InputError);
  CHECK_THROWS_AS(Evaluate(object, ReadDataset(dir / "nodet"), {{"m", nullptr, false}}, options), InputError);
  EvaluationOptions bad = options;
  bad.adds_threshold = 0.0;
  CHECK_THROWS_AS(Evaluate(object, ReadDataset(dir / "nodet"), {{"m", nullptr, false}}, bad), std::invalid_argument);
}

TEST_CASE("mixed dataset: rows from the object's clouds only, other objects' clouds counted and rejected") {
  Fixture f;
  // The fixture's clouds (labelled with the object's name, or not) interleaved
  // with a 12 cm cube's clouds whose detections claim the object is there
  // (its keypoints posed at the cube's centre): no pose of the asymmetric
  // object explains a cube within eps_oc, so none may be accepted. A third
  // label's detections have the wrong keypoint count: failures, not accepted.
  const Mesh cube = BoxMesh({0, 0, 0}, {0.12, 0.12, 0.12});
  DatasetWriter writer(f.dir / "mixed");
  std::vector<std::size_t> own_entries;
  std::size_t order = 0;
  Rng rng(77);
  for (int i = 0; i < kClouds; ++i) {
    DatasetEntry own = f.dataset.entries[static_cast<std::size_t>(i)];
    if (i % 2 == 0) own.object = f.object.name();
    own_entries.push_back(order);
    writer.Add(order++, own, f.dataset.LoadCloud(static_cast<std::size_t>(i)));
    Pose pose;
    pose.R = rng.Rotation();
    pose.t = Eigen::Vector3d(rng.Uniform(), rng.Uniform(), 1.0 + rng.Uniform());
    DatasetEntry other;
    other.cloud = "cube_" + std::to_string(i) + ".ply";
    other.object = i % 3 == 0 ? "cube5" : "cube";
    other.pose = pose;
    other.detected_keypoints = i % 3 == 0 ? PointSet(pose * PointSet(cube.vertices.leftCols(5)))
                                          : PointSet(pose * PointSet(f.object.keypoints().colwise() -
                                                                     Eigen::Vector3d(f.object.sample().rowwise().mean())));
    writer.Add(order++, other, pose * SampleSurface(cube, 400, 100 + i));
  }
  writer.Commit();
  const Dataset mixed = ReadDataset(f.dir / "mixed");
  EvaluationOptions options = EvaluationOptions::Defaults(f.object);
  const Evaluation alone = Evaluate(f.object, f.dataset, {{"manifest", nullptr, false}}, options);
  const Evaluation e = Evaluate(f.object, mixed, {{"manifest", nullptr, false}}, options);
  CHECK(e.clouds == kClouds);
  REQUIRE(e.rows.size() == alone.rows.size());
  for (std::size_t r = 0; r < e.rows.size(); ++r) {
    REQUIRE(e.rows[r].samples.size() == alone.rows[r].samples.size());
    CHECK(e.rows[r].summary.certified == alone.rows[r].summary.certified);
    for (std::size_t k = 0; k < e.rows[r].samples.size(); ++k) {
      const SampleResult& s = e.rows[r].samples[k];
      // Indices name the mixed dataset's entries.
      CHECK(s.index == own_entries[alone.rows[r].samples[k].index]);
      CHECK(mixed.entries[s.index].cloud == s.cloud);
      CHECK(s.ok() == alone.rows[r].samples[k].ok());
      if (s.ok()) CHECK((s.scene_from_model.R - alone.rows[r].samples[k].scene_from_model.R).norm() < 1e-9);
    }
  }
  REQUIRE(e.objects.size() == 3);
  CHECK(e.objects[0].evaluated_object);
  CHECK(e.objects[0].object == f.object.name());
  CHECK(e.objects[0].clouds == kClouds);
  CHECK(e.objects[0].certified == alone.rows.back().summary.certified);   // the corrector row
  CHECK(e.objects[0].certified > 0);
  CHECK(e.objects[1].object == "cube");
  CHECK(e.objects[1].clouds == kClouds - 4);
  CHECK(e.objects[1].failures == 0);
  CHECK(e.objects[1].certified == 0);
  CHECK(e.objects[2].object == "cube5");
  CHECK(e.objects[2].clouds == 4);
  CHECK(e.objects[2].failures == 4);
  CHECK(e.objects[2].certified == 0);
  CHECK(e.other_objects_accepted() == 0);
  CHECK(EvaluationTable(e).find("cube 0 of 8 accepted") != std::string::npos);
  CHECK(EvaluationJson(e).find("\"other_objects_accepted\": 0") != std::string::npos);
  // A single-object dataset has no per-object lines.
  CHECK(alone.objects.empty());
  CHECK(EvaluationTable(alone).find("Mixed dataset") == std::string::npos);

  // No cloud of the object at all: an input error naming the manifest.
  Dataset cubes;
  cubes.dir = mixed.dir;
  for (const DatasetEntry& entry : mixed.entries) {
    if (entry.object == "cube") cubes.entries.push_back(entry);
  }
  CHECK_THROWS_WITH_AS(Evaluate(f.object, cubes, {{"manifest", nullptr, false}}, options),
                       doctest::Contains("no cloud of object"), InputError);

  // An own cloud without ground truth is named by its line of the whole
  // manifest (entries alternate own, cube: own cloud k is line 2k + 1); other
  // objects' clouds need none.
  Dataset no_truth = mixed;
  no_truth.entries[1].pose.reset();
  CHECK_NOTHROW(CheckEvaluationDataset(f.object, no_truth, {{"manifest", nullptr, false}}));
  no_truth.entries[4].pose.reset();
  const std::string line5 = "manifest.jsonl: line 5 (" + mixed.entries[4].cloud + "): no ground-truth";
  CHECK_THROWS_WITH_AS(CheckEvaluationDataset(f.object, no_truth, {{"manifest", nullptr, false}}),
                       doctest::Contains(line5.c_str()), InputError);
  CHECK_THROWS_WITH_AS(Evaluate(f.object, no_truth, {{"manifest", nullptr, false}}, options),
                       doctest::Contains("line 5 ("), InputError);
  Dataset no_keypoints = mixed;
  no_keypoints.entries[2].detected_keypoints.reset();
  const std::string line3 = "line 3 (" + mixed.entries[2].cloud + "): --detector manifest needs";
  CHECK_THROWS_WITH_AS(CheckEvaluationDataset(f.object, no_keypoints, {{"manifest", nullptr, false}}),
                       doctest::Contains(line3.c_str()), InputError);
}

TEST_CASE("frames: every row's certificate includes the frame's free space, a frame without depth changes nothing") {
  // The fixture's clouds moved 1.5 m in front of the default camera (in view).
  const ObjectModel object = EvaluationObject();
  TempDir dir("evaluation_frames_test");
  std::vector<Pose> poses = EvaluationPoses(kClouds);
  DatasetWriter writer(dir / "data");
  for (int i = 0; i < kClouds; ++i) {
    Pose& pose = poses[static_cast<std::size_t>(i)];
    pose.t = Eigen::Vector3d(0.2 * (pose.t.x() - 0.5), 0.2 * (pose.t.y() - 0.5), 1.5);
    DatasetEntry entry;
    entry.cloud = std::to_string(i) + ".ply";
    entry.pose = pose;
    entry.detected_keypoints = DetectedKeypoints(object, pose, i);
    writer.Add(static_cast<std::size_t>(i), entry, EvaluationCloud(object, pose, i));
  }
  writer.Commit();
  const Dataset dataset = ReadDataset(dir / "data");
  const auto filled = [](float depth) {
    const CameraIntrinsics camera;
    auto image = std::make_shared<DepthImage>();
    image->width = camera.width;
    image->height = camera.height;
    image->z.assign(static_cast<std::size_t>(camera.width) * camera.height, depth);
    return DepthView{image, camera, std::nullopt, 0.0, nullptr, nullptr};
  };
  // Oracle: a frame that measured 5 m everywhere saw through every place the
  // object could be in front of it (every pose is refuted); a frame without
  // depth (0 = unknown) or no frame at all refutes nothing.
  const DepthView seen_through = filled(5.0f), blind = filled(0.0f);
  std::vector<std::string> asked;
  std::mutex mutex;
  const DatasetFrames through = [&](const DatasetEntry& entry) {
    std::lock_guard<std::mutex> lock(mutex);
    asked.push_back(entry.cloud);
    return seen_through;
  };
  EvaluationOptions options = EvaluationOptions::Defaults(object);
  options.pipeline.certificate.global.enabled = false;   // not what is tested here
  const std::vector<EvaluatedDetector> detectors = {{"manifest", nullptr, false}};
  const Evaluation plain = Evaluate(object, dataset, detectors, options);
  const Evaluation refuted = Evaluate(object, dataset, detectors, options, {}, through);
  const Evaluation unknown =
      Evaluate(object, dataset, detectors, options, {}, [&](const DatasetEntry&) { return blind; });
  const Evaluation none = Evaluate(object, dataset, detectors, options, {}, [](const DatasetEntry&) { return DepthView{}; });
  REQUIRE(refuted.rows.size() == plain.rows.size());
  CHECK(asked.size() == static_cast<std::size_t>(kClouds));   // one read per cloud and detector
  int certified_without = 0;
  for (std::size_t r = 0; r < plain.rows.size(); ++r) {
    CAPTURE(plain.rows[r].label);
    certified_without += plain.rows[r].summary.certified;
    CHECK(refuted.rows[r].summary.certified == 0);   // KeyPo, + ICP, + RANSAC + ICP, + corrector
    for (std::size_t k = 0; k < plain.rows[r].samples.size(); ++k) {
      const SampleResult& s = refuted.rows[r].samples[k];
      CHECK(plain.rows[r].samples[k].free_space);
      if (s.ok()) CHECK_FALSE(s.free_space);
      CHECK(s.oc == plain.rows[r].samples[k].oc);   // the distances do not see the frame
      CHECK(unknown.rows[r].samples[k].certified() == plain.rows[r].samples[k].certified());
      CHECK(none.rows[r].samples[k].certified() == plain.rows[r].samples[k].certified());
      CHECK(unknown.rows[r].samples[k].free_space);
    }
  }
  REQUIRE(certified_without > 0);   // without the frames these would be certified
  CHECK(refuted.total_false_certificates() == 0);
  // The samples file carries the free-space decision.
  const std::string text = EvaluationJson(refuted);
  CHECK(text.find("\"free_space\": false") != std::string::npos);
}
