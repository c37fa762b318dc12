// Self-training: a trainable test detector (keypoints = cloud centroid +
// learned per-keypoint offsets) improves its certified fraction from its own
// certified outputs; nothing certified => clear error; resume == uninterrupted.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/method/model_symmetries.hpp"
#include "c3po/method/pseudo_label.hpp"
#include "c3po/method/selftrain.hpp"
#include "test_helpers.hpp"
#include "test_objects.hpp"

using namespace c3po;

namespace {

class OffsetDetector : public TrainableDetector {
 public:
  OffsetDetector(PointSet offsets, double lr) : offsets_(std::move(offsets)), lr_(lr) {}
  std::string name() const override { return "offset"; }
  int num_keypoints() const override { return static_cast<int>(offsets_.cols()); }
  PointSet Detect(const PointSet& cloud) const override {
    return offsets_.colwise() + Eigen::Vector3d(cloud.rowwise().mean());
  }
  double TrainStep(const std::vector<PointSet>& clouds, const std::vector<PointSet>& targets) override {
    PointSet gradient = PointSet::Zero(3, offsets_.cols());
    double loss = 0;
    for (std::size_t i = 0; i < clouds.size(); ++i) {
      const PointSet residual = Detect(clouds[i]) - targets[i];
      loss += residual.squaredNorm() / residual.cols();
      gradient += 2.0 * residual / residual.cols();
    }
    offsets_ -= lr_ * gradient / static_cast<double>(clouds.size());
    return loss / clouds.size();
  }
  std::vector<float> GetWeights() const override {
    return std::vector<float>(offsets_.data(), offsets_.data() + offsets_.size());
  }
  void SetWeights(const std::vector<float>& w) override {
    for (Eigen::Index i = 0; i < offsets_.size(); ++i) offsets_.data()[i] = w[i];
  }
  void Save(const std::string& path, const std::string&) const override { SaveCheckpoint(path, "{}"); }
  void SaveCheckpoint(const std::string& path, const std::string& state) const override {
    // Exact doubles, so that a resumed run continues bit for bit.
    nlohmann::json j = {{"w", std::vector<double>(offsets_.data(), offsets_.data() + offsets_.size())},
                        {"state", state}};
    WriteFileAtomically(path, j.dump());
  }
  std::string LoadCheckpoint(const std::string& path) override {
    const auto j = nlohmann::json::parse(ReadFileToString(path));
    const auto w = j.at("w").get<std::vector<double>>();
    for (Eigen::Index i = 0; i < offsets_.size(); ++i) offsets_.data()[i] = w[i];
    return j.at("state").get<std::string>();
  }

 private:
  PointSet offsets_;
  double lr_;
};

// Full clouds of the object, identity rotation, random translations.
std::vector<PointSet> Clouds(const ObjectModel& object, int count) {
  std::vector<PointSet> clouds;
  Rng rng(4);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d t(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(1, 2));
    clouds.push_back(SampleSurface(object.mesh(), 300, 50 + i).colwise() + t);
  }
  return clouds;
}

SelfTrainOptions Options(const ObjectModel& object) {
  SelfTrainOptions options;
  options.epochs = 6;
  options.batch = 8;
  options.validation_fraction = 0.25;
  options.stop_at_percent_oc = 101;   // never stop early in tests
  options.patience = 0;
  options.pipeline.certificate = CertificateOptions::FromObject(object.spec());
  options.pipeline.certificate.eps_oc = 0.01;
  return options;
}

PointSet CentredKeypoints(const ObjectModel& object) {
  return object.keypoints().colwise() - Eigen::Vector3d(object.sample().rowwise().mean());
}

}  // namespace

TEST_CASE("self-training raises the certified fraction of a biased detector"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  const ObjectModel object = test::AsymmetricObject(20000);
  const auto clouds = Clouds(object, 40);
  // Biased start: every keypoint shifted by 3 cm; the corrector can still fix
  // most clouds, and their corrected keypoints teach the detector the offsets.
  OffsetDetector detector(CentredKeypoints(object).colwise() + Eigen::Vector3d(0.03, -0.02, 0.0), 0.5);
  SelfTrainOptions options = Options(object);
  options.epochs = 10;
  const PipelineOptions no_correction = [&] { PipelineOptions p = options.pipeline; p.correct = false; return p; }();
  const double before = MeasureCertified(object, clouds, detector, no_correction).percent_oc;
  const SelfTrainResult result = SelfTrain(object, clouds, detector, options);
  const double after = MeasureCertified(object, clouds, detector, no_correction).percent_oc;
  CHECK(result.epochs.size() == 10);
  CHECK(result.epochs.front().certified_samples > 0);
  CHECK(before < 50.0);          // plain registration of the biased detector is off
  CHECK(after > 90.0);           // after self-training it is right without correction
}

TEST_CASE("camera frames: free space reaches the certificates of self-training, unknown depth changes nothing") {
  const ObjectModel object = test::AsymmetricObject(6000);
  // Clouds 1.5 m in front of the default camera, near its axis (in view).
  std::vector<PointSet> clouds;
  Rng rng(12);
  for (int i = 0; i < 12; ++i) {
    const Eigen::Vector3d t(rng.Uniform(-0.1, 0.1), rng.Uniform(-0.1, 0.1), 1.5);
    clouds.push_back(SampleSurface(object.mesh(), 300, 70 + i).colwise() + t);
  }
  const auto frames_filled = [&](float depth) {
    const CameraIntrinsics camera;
    auto image = std::make_shared<DepthImage>();
    image->width = camera.width;
    image->height = camera.height;
    image->z.assign(static_cast<std::size_t>(camera.width) * camera.height, depth);
    return std::vector<DepthView>(clouds.size(), DepthView{image, camera, std::nullopt, 0.0, nullptr, nullptr});
  };
  // Oracle: a frame that measured 5 m everywhere saw through every place the
  // object could be in front of it; a frame without depth knows nothing.
  const std::vector<DepthView> seen_through = frames_filled(5.0f);
  const std::vector<DepthView> blind = frames_filled(0.0f);
  const PointSet offsets = CentredKeypoints(object).colwise() + Eigen::Vector3d(0.03, -0.02, 0.0);
  SelfTrainOptions options = Options(object);
  options.epochs = 2;
  options.pipeline.certificate.global.enabled = false;   // not what is tested here (and the slowest part)

  OffsetDetector probe(offsets, 0.5);
  const CertifiedFraction plain = MeasureCertified(object, clouds, probe, options.pipeline);
  const CertifiedFraction refuted = MeasureCertified(object, clouds, probe, options.pipeline, false, &seen_through);
  int observably_correct = 0;
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    CHECK_FALSE(plain.estimates[i].certificate.free_space.checked);
    CHECK(refuted.estimates[i].certificate.free_space.checked);
    CHECK_FALSE(refuted.estimates[i].certificate.free_space.passed);
    CHECK_FALSE(FitsObservation(refuted.estimates[i]));
    observably_correct += FitsObservation(plain.estimates[i]);
  }
  REQUIRE(observably_correct > 0);   // without the frames these would be pseudo-labels

  OffsetDetector through(offsets, 0.5);
  CHECK_THROWS_WITH_AS(SelfTrain(object, clouds, through, options, {}, {}, false, nullptr, nullptr, &seen_through),
                       doctest::Contains("nothing to learn from"), InputError);

  OffsetDetector without(offsets, 0.5), unknown(offsets, 0.5);
  const SelfTrainResult a = SelfTrain(object, clouds, without, options);
  const SelfTrainResult b = SelfTrain(object, clouds, unknown, options, {}, {}, false, nullptr, nullptr, &blind);
  CHECK(a.epochs.front().certified_samples > 0);
  CHECK(without.GetWeights() == unknown.GetWeights());
  CHECK(a.pseudo_label_uses == b.pseudo_label_uses);
  std::vector<DepthView> wrong_size(clouds.size() - 1);
  CHECK_THROWS_AS(SelfTrain(object, clouds, unknown, options, {}, {}, false, nullptr, nullptr, &wrong_size),
                  std::invalid_argument);
}

TEST_CASE("self-training with nothing certified stops with a clear message") {
  const ObjectModel object = test::AsymmetricObject(4000);
  // Clouds spread uniformly through a 2 m cube, over five times the object's size:
  // no pose of the object lies within eps_oc of every point, so nothing can
  // be observably correct whatever the detector and the corrector do.
  std::vector<PointSet> clouds;
  Rng rng(9);
  for (int i = 0; i < 12; ++i) {
    PointSet cloud(3, 300);
    for (Eigen::Index j = 0; j < cloud.cols(); ++j) {
      cloud.col(j) = Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(1, 3));
    }
    clouds.push_back(cloud);
  }
  REQUIRE(object.diameter() < 2.0 / 5);
  OffsetDetector detector(CentredKeypoints(object), 0.1);
  SelfTrainOptions options = Options(object);
  CHECK_THROWS_WITH_AS(SelfTrain(object, clouds, detector, options),
                       doctest::Contains("nothing to learn from"), InputError);
}

TEST_CASE("resuming from a checkpoint gives the uninterrupted result"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  const ObjectModel object = test::AsymmetricObject(8000);
  const auto clouds = Clouds(object, 24);
  const PointSet start = CentredKeypoints(object).colwise() + Eigen::Vector3d(0.02, 0.0, 0.01);
  test::TempDir dir("selftrain_resume");
  SelfTrainOptions options = Options(object);
  options.epochs = 4;

  OffsetDetector straight(start, 0.5);
  options.checkpoint_path = dir / "straight.ckpt";
  SelfTrain(object, clouds, straight, options);

  // "Interrupted" run: stop after 2 epochs, then resume to 4 from the checkpoint.
  OffsetDetector first_half(start, 0.5);
  options.checkpoint_path = dir / "resumed.ckpt";
  options.epochs = 2;
  SelfTrain(object, clouds, first_half, options);
  OffsetDetector resumed(start, 0.5);
  options.epochs = 4;
  const SelfTrainResult result = SelfTrain(object, clouds, resumed, options, {}, {}, /*resume=*/true);
  CHECK(result.epochs.size() == 4);
  CHECK(resumed.GetWeights() == straight.GetWeights());

  // A corrupt resume state is an InputError naming the checkpoint: a float
  // where an integer belongs (converting 1e300 to int would be undefined), a
  // wrong type, missing fields.
  for (const std::string state : {R"({"epoch": 1e300})", R"({"epoch": "two"})", R"({"epoch": 1})"}) {
    options.checkpoint_path = dir / "corrupt.ckpt";
    OffsetDetector corrupt(start, 0.5);
    corrupt.SaveCheckpoint(options.checkpoint_path, state);
    CAPTURE(state);
    try {
      SelfTrain(object, clouds, corrupt, options, {}, {}, /*resume=*/true);
      FAIL_CHECK("a corrupt resume state was accepted");
    } catch (const c3po::InputError& e) {
      const std::string message = e.what();
      CHECK(message.find(options.checkpoint_path) != std::string::npos);
      CHECK(message.find('\n') == std::string::npos);
    }
  }
}

namespace {

// A flat slab 0.20 x 0.10 x 0.012 with a small bump (bump_height high) near
// one end of its top face: exactly two-fold symmetric without the bump, so
// the half-turns about its principal axes are near-equal fits. Keypoints on
// the slab's corners and on the bump.
ObjectModel FlatNearSymmetricObject(double bump_height, int sample_size = 6000) {
  Mesh mesh = test::MergeMeshes({test::BoxMesh({0, 0, 0}, {0.20, 0.10, 0.012}),
                                 test::BoxMesh({0.07, 0.02, 0.006 + bump_height / 2},
                                               {0.012, 0.012, bump_height})});
  ObjectSpec spec;
  spec.name = "flat";
  spec.keypoints.resize(3, 9);
  spec.keypoints << -0.10, 0.10, 0.10, -0.10, -0.10, 0.10, 0.10, -0.10, 0.07,  //
      -0.05, -0.05, 0.05, 0.05, -0.05, -0.05, 0.05, 0.05, 0.02,                  //
      -0.006, -0.006, -0.006, -0.006, 0.006, 0.006, 0.006, 0.006, 0.006 + bump_height;
  spec.eps_oc = 0.01;
  spec.delta_nd = 0.004;
  ObjectModelOptions options;
  options.sample_size = sample_size;
  return ObjectModel(spec, mesh, options);
}

// The slab alone, with the same keypoints (the ninth lies on the top face):
// exactly symmetric under the half-turns about its axes.
ObjectModel SymmetricSlab() {
  const ObjectModel bumped = FlatNearSymmetricObject(0.0);
  ObjectModelOptions options;
  options.sample_size = 6000;
  return ObjectModel(bumped.spec(), test::BoxMesh({0, 0, 0}, {0.20, 0.10, 0.012}), options);
}

// Clouds of `object` at identity rotation, random translations, noise_sigma
// Gaussian noise per coordinate; the true poses in *truth.
std::vector<PointSet> NoisyClouds(const ObjectModel& object, int count, double noise_sigma, std::uint64_t seed,
                                  std::vector<Pose>* truth = nullptr) {
  std::vector<PointSet> clouds;
  Rng rng(seed);
  for (int i = 0; i < count; ++i) {
    Pose pose;
    pose.t = Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(1, 2));
    PointSet cloud = pose * SampleSurface(object.mesh(), 300, seed * 1000 + i);
    for (Eigen::Index j = 0; j < cloud.size(); ++j) cloud.data()[j] += noise_sigma * rng.Normal();
    clouds.push_back(cloud);
    if (truth) truth->push_back(pose);
  }
  return clouds;
}

Eigen::Matrix3d RotationZ(double degrees) {
  return Eigen::AngleAxisd(degrees * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// The keypoint offsets of a detector that is `degrees` off about z (model frame).
PointSet TurnedKeypoints(const ObjectModel& object, double degrees) {
  return RotationZ(degrees) * CentredKeypoints(object);
}

// Records every cloud it is trained on.
class RecordingDetector : public OffsetDetector {
 public:
  using OffsetDetector::OffsetDetector;
  double TrainStep(const std::vector<PointSet>& clouds, const std::vector<PointSet>& targets) override {
    trained.insert(trained.end(), clouds.begin(), clouds.end());
    step_sizes.push_back(clouds.size());
    return OffsetDetector::TrainStep(clouds, targets);
  }
  std::vector<PointSet> trained;
  std::vector<std::size_t> step_sizes;
};

// Adds `damage` to every offset after its sabotage_step-th training step.
class SabotagedDetector : public OffsetDetector {
 public:
  SabotagedDetector(PointSet offsets, double lr, int sabotage_step, Eigen::Vector3d damage)
      : OffsetDetector(std::move(offsets), lr), sabotage_step_(sabotage_step), damage_(std::move(damage)) {}
  double TrainStep(const std::vector<PointSet>& clouds, const std::vector<PointSet>& targets) override {
    const double loss = OffsetDetector::TrainStep(clouds, targets);
    if (++steps_ == sabotage_step_) {
      std::vector<float> w = GetWeights();
      for (std::size_t i = 0; i < w.size(); ++i) w[i] += static_cast<float>(damage_[static_cast<int>(i % 3)]);
      SetWeights(w);
    }
    return loss;
  }

 private:
  int sabotage_step_;
  Eigen::Vector3d damage_;
  int steps_ = 0;
};

}  // namespace

TEST_CASE("pseudo-label check: a flat near-symmetric object's flip is ambiguous, an asymmetric object's is not") {
  // Oracle: the true pose, corrected from the true keypoints; the half-turn
  // about the slab's normal moves the keypoints by ~0.2 m, and the flipped
  // slab explains the cloud within eps_oc = 1 cm (the bump is 4 mm).
  const ObjectModel flat = FlatNearSymmetricObject(0.004);
  const ObjectModel asym = test::AsymmetricObject(6000);
  for (const ObjectModel* object : {&flat, &asym}) {
    std::vector<Pose> truth;
    const auto clouds = NoisyClouds(*object, 3, 0.0005, 21, &truth);
    PipelineOptions pipeline;
    pipeline.certificate = CertificateOptions::FromObject(object->spec());
    pipeline.certificate.eps_oc = 0.01;
    const PrincipalFrame frame = ModelPrincipalFrame(*object);
    for (std::size_t i = 0; i < clouds.size(); ++i) {
      const PoseEstimate estimate = EstimateAndCertify(*object, clouds[i], truth[i] * object->keypoints(), pipeline);
      REQUIRE(estimate.certificate.oc.passed);
      const PseudoLabelCheck check = CheckPseudoLabel(*object, clouds[i], estimate, pipeline, {}, frame);
      CAPTURE(object->name());
      CHECK(check.ambiguous == (object == &flat));
      if (object == &flat) {
        CHECK(check.rival_passes_oc);
        CHECK(check.rival_keypoint_distance > 0.1);
      }
      // Switched off: never ambiguous, the residual still measured.
      PseudoLabelOptions off;
      off.check_ambiguity = false;
      const PseudoLabelCheck unchecked = CheckPseudoLabel(*object, clouds[i], estimate, pipeline, off, frame);
      CHECK_FALSE(unchecked.ambiguous);
      CHECK(unchecked.residual == doctest::Approx(check.residual));
    }
  }
  // The half-turn about axis 2 (the slab's normal) maps the exactly symmetric
  // part onto itself: an independent check of the principal frame.
  const PrincipalFrame frame = ModelPrincipalFrame(flat);
  CHECK(std::abs(frame.axes.col(2).z()) > 0.99);
  CHECK(std::abs(frame.axes.col(0).x()) > 0.99);
  const Pose flip = HalfTurn(frame, 2);
  CHECK((flip * flip).R.isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  CHECK((flip * frame.centroid - frame.centroid).norm() < 1e-12);
}

TEST_CASE("pseudo-label check: a second basin the frame refutes is no second explanation") {
  // Oracle: stand-ins for the frame's free-space test. One refutes every pose
  // whose keypoints lie farther than eps_oc from the estimate's (the camera
  // saw through every other placement): the flat object's flip, ambiguous
  // otherwise (test above), is then no second explanation. One refutes
  // nothing: the check is unchanged.
  struct OnlyNear : RivalFilter {
    const ObjectModel* object = nullptr;
    PointSet keypoints;
    double radius = 0.0;
    bool Passes(const Pose& pose, int* violations) const override {
      const bool near = ((pose * object->keypoints()) - keypoints).colwise().norm().maxCoeff() <= radius;
      *violations = near ? 0 : 1000;
      return near;
    }
  };
  struct Everything : RivalFilter {
    bool Passes(const Pose&, int* violations) const override {
      *violations = 0;
      return true;
    }
  };
  const ObjectModel flat = FlatNearSymmetricObject(0.004);
  std::vector<Pose> truth;
  const auto clouds = NoisyClouds(flat, 3, 0.0005, 21, &truth);
  PipelineOptions pipeline;
  pipeline.certificate = CertificateOptions::FromObject(flat.spec());
  pipeline.certificate.eps_oc = 0.01;
  const PrincipalFrame frame = ModelPrincipalFrame(flat);
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    const PoseEstimate estimate = EstimateAndCertify(flat, clouds[i], truth[i] * flat.keypoints(), pipeline);
    REQUIRE(estimate.certificate.oc.passed);
    const Everything everything;
    const PseudoLabelCheck unrefuted = CheckPseudoLabel(flat, clouds[i], estimate, pipeline, {}, frame, &everything);
    CHECK(unrefuted.ambiguous);
    CHECK(unrefuted.rivals_refuted == 0);
    OnlyNear only_near;
    only_near.object = &flat;
    only_near.keypoints = estimate.scene_from_model * flat.keypoints();
    only_near.radius = pipeline.certificate.eps_oc;
    const PseudoLabelCheck check = CheckPseudoLabel(flat, clouds[i], estimate, pipeline, {}, frame, &only_near);
    CHECK_FALSE(check.ambiguous);
    CHECK(check.rivals_refuted >= 1);
    CHECK(check.rival_residual < 0);   // no second basin left to compare
  }
}

TEST_CASE("self-training on a flat near-symmetric object: the flip is learnt without the ambiguity rule and refused with it"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  const ObjectModel object = FlatNearSymmetricObject(0.004);
  std::vector<Pose> truth;
  const auto clouds = NoisyClouds(object, 32, 0.0005, 5, &truth);
  const SelfTrainReference reference{truth, {}};
  SelfTrainOptions options = Options(object);
  options.epochs = 6;
  // The detector starts 150 degrees off about the normal: nearer the flipped
  // basin, where the corrector lands and the 1 cm certificate passes.
  const PointSet start = TurnedKeypoints(object, 150.0);
  const PointSet flipped = TurnedKeypoints(object, 180.0);
  const PointSet correct = CentredKeypoints(object);

  // Mechanism: without the rule every certified sample teaches the flip;
  // validation % oc stays at 100 and the old oc-only criterion sees nothing.
  OffsetDetector naive(start, 0.5);
  SelfTrainOptions naive_options = options;
  naive_options.pseudo_labels.check_ambiguity = false;
  const SelfTrainResult naive_result = SelfTrain(object, clouds, naive, naive_options, {}, {}, false, &reference);
  const PointSet naive_offsets = naive.Detect(PointSet::Zero(3, 1));
  CHECK((naive_offsets - flipped).norm() < 0.2 * (naive_offsets - correct).norm());
  CHECK(naive_result.initial.percent_oc == 100.0);
  CHECK(naive_result.best.percent_oc == 100.0);
  CHECK(naive_result.best.rotation_error_median > 170.0);   // reporting: the flip

  // With the rule: the samples are refused as ambiguous and the detector is
  // not moved toward the flip.
  OffsetDetector careful(start, 0.5);
  const SelfTrainResult careful_result = SelfTrain(object, clouds, careful, options, {}, {}, false, &reference);
  // The evidence of how far from a symmetry the second basins are: the flip
  // moves the bump to the other end, so the posed surfaces differ by the
  // bump's height (4 mm; the refit basin, from noisy points, within 0.5 mm of it).
  for (const auto& log : careful_result.epochs) {
    CHECK(log.certified_samples > 0);
    CHECK(log.ambiguous_skipped == log.certified_samples);
    CHECK(log.validation_percent_identified == 0.0);
    CHECK(std::abs(log.ambiguous_surface_q50 - 0.004) < 0.0005);
  }
  CHECK(careful.Detect(PointSet::Zero(3, 1)).isApprox(start, 1e-6));

  // From near the correct mode the rule also refuses (the certificate cannot
  // tell the modes apart at 1 cm), so the detector stays there.
  OffsetDetector near_correct(TurnedKeypoints(object, 20.0), 0.5);
  SelfTrain(object, clouds, near_correct, options);
  const PointSet after = near_correct.Detect(PointSet::Zero(3, 1));
  CHECK((after - correct).norm() < (after - flipped).norm());
}

TEST_CASE("symmetric labellings: an exactly symmetric slab's flips are labellings and are trained with the min loss"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  // The slab without its bump is mapped onto itself by the half-turns about
  // its three axes: each flip places the same shape with other keypoints.
  // Oracle: the exact half-turn about the slab's normal through its centre.
  const ObjectModel object = SymmetricSlab();
  std::vector<Pose> truth;
  const auto clouds = NoisyClouds(object, 32, 0.0005, 5, &truth);
  SelfTrainOptions options = Options(object);
  const PrincipalFrame frame = ModelPrincipalFrame(object);
  Pose normal_flip;
  normal_flip.R = Eigen::Vector3d(-1, -1, 1).asDiagonal();
  // The surface distance of the flip: zero for the exact slab up to the
  // bound's slack near corners, where a point's nearest triangle may have no
  // sample among its 16 nearest (far below the sample spacing that the
  // sample distance carries), the bump's height with a 4 mm bump.
  const PointSet queries = StridedColumns(object.sample(), 1000);
  CHECK(PosedSurfaceHausdorff(object, queries, Pose::Identity(), normal_flip) < 0.0005);
  CHECK(PosedModelHausdorff(object, queries, Pose::Identity(), normal_flip) > 0.5 * object.SampleSpacing());
  const ObjectModel bumped = FlatNearSymmetricObject(0.004);
  const double bump_distance =
      PosedSurfaceHausdorff(bumped, StridedColumns(bumped.sample(), 1000), Pose::Identity(), normal_flip);
  CHECK(bump_distance > 0.0039);
  CHECK(bump_distance < 0.0041);
  for (int i = 0; i < 3; ++i) {
    const PoseEstimate estimate =
        EstimateAndCertify(object, clouds[i], truth[i] * object.keypoints(), options.pipeline);
    REQUIRE(estimate.certificate.oc.passed);
    const PseudoLabelCheck check = CheckPseudoLabel(object, clouds[i], estimate, options.pipeline,
                                                    options.pseudo_labels, frame);
    CHECK_FALSE(check.ambiguous);
    REQUIRE(check.symmetric_labellings.size() >= 1);
    const PointSet flipped_truth = (truth[i] * normal_flip) * object.keypoints();
    double nearest = 1e9;
    for (const PointSet& labelling : check.symmetric_labellings) {
      nearest = std::min(nearest, (labelling - flipped_truth).colwise().norm().maxCoeff());
    }
    CHECK(nearest < 0.003);
    // Without the symmetry-aware loss the same flips make the sample ambiguous.
    PseudoLabelOptions refuse = options.pseudo_labels;
    refuse.symmetry_aware = false;
    const PseudoLabelCheck refused = CheckPseudoLabel(object, clouds[i], estimate, options.pipeline, refuse, frame);
    CHECK(refused.ambiguous);
    CHECK(refused.symmetric_labellings.empty());
    // The object's known symmetries add T̂·S·b to the labellings whether or
    // not a rival fit lands there (exact, from the estimate's pose); not
    // without the symmetry-aware loss.
    PseudoLabelOptions known = options.pseudo_labels;
    known.check_ambiguity = false;   // no rival fits: only the known symmetries
    known.model_symmetries = {normal_flip, HalfTurn(frame, 0)};
    const PseudoLabelCheck with_known = CheckPseudoLabel(object, clouds[i], estimate, options.pipeline, known, frame);
    REQUIRE(with_known.symmetric_labellings.size() == 2);
    CHECK((with_known.symmetric_labellings[0] - (estimate.scene_from_model * normal_flip) * object.keypoints())
              .cwiseAbs().maxCoeff() < 1e-12);
    known.symmetry_aware = false;
    CHECK(CheckPseudoLabel(object, clouds[i], estimate, options.pipeline, known, frame).symmetric_labellings.empty());
  }
  // The step's target is the labelling nearest the detection.
  const PointSet a = PointSet::Zero(3, 2), b = PointSet::Constant(3, 2, 1.0), c = PointSet::Constant(3, 2, 2.0);
  CHECK(&NearestLabelling(PointSet::Constant(3, 2, 0.4), a, {b, c}) == &a);
  const std::vector<PointSet> others = {b, c};
  CHECK(&NearestLabelling(PointSet::Constant(3, 2, 1.9), a, others) == &others[1]);

  // Self-training: every certified sample is trained on (none refused) and
  // the detector moves toward the labelling nearest it: from 150 degrees to
  // the flip, from 20 degrees to the modelled keypoints. Either is the same
  // shape: the held-out Hausdorff distance to the truth (reporting) stays
  // within the noise, and so does the rotation error to the nearest
  // symmetric truth (the slab's half-turns given to the reference; to the
  // truth alone it would say 180 degrees for the flip).
  SymmetrySearchOptions search;
  search.tolerance = 0.002;
  std::vector<Pose> half_turns;
  for (const ModelSymmetry& s : FindModelSymmetries(object, search)) half_turns.push_back(s.model_from_model);
  REQUIRE(half_turns.size() == 3);
  const SelfTrainReference reference{truth, half_turns};
  const PointSet flipped = TurnedKeypoints(object, 180.0), correct = CentredKeypoints(object);
  for (const double start_degrees : {150.0, 20.0}) {
    CAPTURE(start_degrees);
    const PointSet start = TurnedKeypoints(object, start_degrees);
    const PointSet& mode = start_degrees > 90 ? flipped : correct;
    OffsetDetector detector(start, 0.5);
    const SelfTrainResult result = SelfTrain(object, clouds, detector, options, {}, {}, false, &reference);
    // (a sample whose rival fit stops in a non-symmetric basin that fits
    // nearly as well is still refused: a few per epoch.)
    for (const auto& log : result.epochs) {
      CHECK(log.symmetric_trained + log.ambiguous_skipped == log.certified_samples);
      CHECK(log.symmetric_trained >= 0.8 * log.certified_samples);
    }
    CHECK(result.epochs.front().certified_samples > 0);
    const PointSet after = detector.Detect(PointSet::Zero(3, 1));
    CHECK((after - mode).norm() < 0.8 * (start - mode).norm());
    CHECK(result.best.hausdorff_median < 0.002);
    CHECK(result.best.rotation_error_median < 3.0);
    // Refusing them instead leaves the detector where it started.
    SelfTrainOptions refuse = options;
    refuse.epochs = 2;
    refuse.pseudo_labels.symmetry_aware = false;
    OffsetDetector unchanged(start, 0.5);
    const SelfTrainResult refused = SelfTrain(object, clouds, unchanged, refuse);
    CHECK(refused.epochs.front().ambiguous_skipped == refused.epochs.front().certified_samples);
    CHECK(unchanged.Detect(PointSet::Zero(3, 1)).isApprox(start, 1e-6));
  }
}

TEST_CASE("self-training keeps the correct mode when the certificate separates the flip"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  // A 2.5 cm bump: the flipped slab leaves points 2.5 cm from the model, so
  // the flip fails the 1 cm certificate and the samples are not ambiguous.
  const ObjectModel object = FlatNearSymmetricObject(0.025);
  std::vector<Pose> truth;
  const auto clouds = NoisyClouds(object, 32, 0.0005, 6, &truth);
  const SelfTrainReference reference{truth, {}};
  SelfTrainOptions options = Options(object);
  options.epochs = 6;
  OffsetDetector detector(TurnedKeypoints(object, 20.0), 0.5);
  const SelfTrainResult result = SelfTrain(object, clouds, detector, options, {}, {}, false, &reference);
  CHECK(result.epochs.front().ambiguous_skipped == 0);
  CHECK(result.best.rotation_error_median < 1.0);
  const PointSet after = detector.Detect(PointSet::Zero(3, 1));
  CHECK((after - CentredKeypoints(object)).norm() < (TurnedKeypoints(object, 20.0) - CentredKeypoints(object)).norm());
}

TEST_CASE("epoch selection rolls back a deliberately bad epoch"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  const ObjectModel object = test::AsymmetricObject(8000);
  const auto clouds = Clouds(object, 40);
  SelfTrainOptions options = Options(object);
  options.epochs = 5;
  const int steps_per_epoch = (40 - 10 + options.batch - 1) / options.batch;   // 30 training clouds
  // After the last step of epoch 3 every keypoint is thrown 5 cm off: the
  // corrector still rescues the held-out clouds, but the detected keypoints
  // now disagree with their corrections by ~7 cm (the label-free agreement
  // criterion).
  SabotagedDetector detector(CentredKeypoints(object).colwise() + Eigen::Vector3d(0.02, 0.0, 0.01), 0.5,
                             3 * steps_per_epoch, Eigen::Vector3d(0.05, 0.05, 0.0));
  const SelfTrainResult result = SelfTrain(object, clouds, detector, options);
  REQUIRE(result.epochs.size() == 5);
  CHECK(result.epochs[2].rolled_back);
  CHECK(result.epochs[2].validation_detection_error > 0.05);
  CHECK(result.best.detection_error < 0.01);
  CHECK(result.best_epoch != 3);
  CHECK_FALSE(result.epochs[0].rolled_back);
  // Training continued from the best weights: epoch 4 agrees again.
  CHECK_FALSE(result.epochs[3].rolled_back);
  CHECK(result.epochs[3].validation_detection_error < 0.01);
  // The returned detector holds the best weights, not the sabotaged ones.
  const CertifiedFraction final_fit = MeasureCertified(object, clouds, detector, options.pipeline);
  CHECK(final_fit.percent_oc == 100.0);
  CHECK(final_fit.detection_error < 0.01);
}

TEST_CASE("patience stops self-training after epochs without a new best"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  const ObjectModel object = test::AsymmetricObject(8000);
  const auto clouds = Clouds(object, 24);
  SelfTrainOptions options = Options(object);
  options.epochs = 20;
  options.patience = 2;
  // A detector that cannot learn (zero step): every epoch equals the initial
  // model, so none is a new best and the run stops after `patience` epochs.
  OffsetDetector detector(CentredKeypoints(object).colwise() + Eigen::Vector3d(0.01, 0.0, 0.0), 0.0);
  const SelfTrainResult result = SelfTrain(object, clouds, detector, options);
  CHECK(result.stopped_early);
  CHECK(result.epochs.size() == 2);
  CHECK(result.best_epoch == 0);
}

TEST_CASE("mixed unlabelled data: another object's clouds are never pseudo-labels"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  const ObjectModel object = test::AsymmetricObject(8000);
  // A 12 cm cube: no pose of the asymmetric object explains its clouds
  // within eps_oc, so the certificate must reject every one of them.
  ObjectSpec cube_spec;
  cube_spec.name = "cube12";
  cube_spec.keypoints = test::BoxMesh({0, 0, 0}, {0.12, 0.12, 0.12}).vertices;
  cube_spec.eps_oc = 0.01;
  cube_spec.delta_nd = 0.004;
  const ObjectModel other(cube_spec, test::BoxMesh({0, 0, 0}, {0.12, 0.12, 0.12}));
  std::vector<PointSet> own = Clouds(object, 24);
  std::vector<PointSet> mixed = own;
  for (const auto& cloud : NoisyClouds(other, 24, 0.0005, 8)) mixed.push_back(cloud);
  RecordingDetector detector(CentredKeypoints(object).colwise() + Eigen::Vector3d(0.02, 0.0, 0.01), 0.5);
  SelfTrainOptions options = Options(object);
  options.epochs = 3;
  const SelfTrainResult result = SelfTrain(object, mixed, detector, options);
  REQUIRE_FALSE(detector.trained.empty());
  // Steps count pseudo-labels, not clouds: every step but the last of an
  // epoch is a full batch, although half the clouds are refused (with one
  // step per batch of clouds the steps would hold ~4 of 8).
  std::size_t short_steps = 0;
  for (const std::size_t size : detector.step_sizes) {
    CHECK(size <= static_cast<std::size_t>(options.batch));
    short_steps += size < static_cast<std::size_t>(options.batch);
  }
  CHECK(short_steps <= result.epochs.size());
  CHECK(detector.step_sizes.size() > result.epochs.size());
  // And the final detector + corrector certifies none of the cube's clouds.
  const CertifiedFraction on_other = MeasureCertified(object, std::vector<PointSet>(mixed.begin() + 24, mixed.end()),
                                                      detector, options.pipeline);
  CHECK(on_other.percent_oc == 0.0);
  for (const auto& cloud : detector.trained) {
    const bool is_own = std::any_of(own.begin(), own.end(), [&](const PointSet& c) {
      return c.cols() == cloud.cols() && c == cloud;
    });
    CHECK(is_own);
  }
  // The label-free epoch criterion measures the fit residual of the clouds
  // the certificate accepts: the cube's refused clouds do not move it.
  // Oracle: the same detector measured on the object's clouds alone.
  const ValidationFit on_mixed =
      MeasureValidationFit(object, mixed, detector, options.pipeline, options.pseudo_labels, nullptr, {}, nullptr);
  const ValidationFit on_own =
      MeasureValidationFit(object, own, detector, options.pipeline, options.pseudo_labels, nullptr, {}, nullptr);
  REQUIRE(on_own.percent_oc > 0.0);
  CHECK(on_mixed.percent_oc == doctest::Approx(on_own.percent_oc / 2.0));
  CHECK(on_mixed.residual_q50 == on_own.residual_q50);
  CHECK(on_mixed.residual_q90 == on_own.residual_q90);
}

TEST_CASE("epoch criterion: the validation measures the detector and not re-estimation's rescue"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  // A 2.5 cm bump: a detector in the flipped basin is refuted by the bump's
  // points, and re-estimation's half-turn restart would certify the truth
  // whatever the detector said. Selection must see the detector as it is.
  const ObjectModel object = FlatNearSymmetricObject(0.025);
  const auto clouds = NoisyClouds(object, 8, 0.0005, 9);
  SelfTrainOptions options = Options(object);
  OffsetDetector flipped(TurnedKeypoints(object, 180.0), 0.0);
  PipelineOptions rescued = options.pipeline;
  rescued.certificate.global.reestimate = true;
  // Oracles: the detector + corrector alone, and the same with re-estimation.
  const CertifiedFraction alone = MeasureCertified(object, clouds, flipped, options.pipeline);
  const CertifiedFraction with_restarts = MeasureCertified(object, clouds, flipped, rescued);
  REQUIRE(alone.percent_oc == 0.0);
  REQUIRE(with_restarts.percent_oc == 100.0);
  const ValidationFit fit =
      MeasureValidationFit(object, clouds, flipped, rescued, options.pseudo_labels, nullptr, {}, nullptr);
  CHECK(fit.percent_oc == alone.percent_oc);
  CHECK(fit.percent_identified == 0.0);
  // No cloud is accepted, so no residual is measured (and none is compared).
  CHECK(fit.residual_q50 == 0.0);
}

TEST_CASE("epoch selection: a detector that starts with no oc validation cloud can improve"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  // The detector starts in the flipped basin (no validation cloud passes oc,
  // so the start has no residual and no agreement to compare); re-estimation
  // makes its training pseudo-labels. An epoch that identifies validation
  // clouds is better, never "worse" than a start that measured nothing.
  const ObjectModel object = FlatNearSymmetricObject(0.025);
  const auto clouds = NoisyClouds(object, 16, 0.0005, 10);
  SelfTrainOptions options = Options(object);
  options.epochs = 6;
  options.batch = 4;
  options.pipeline.certificate.global.reestimate = true;
  OffsetDetector detector(TurnedKeypoints(object, 180.0), 0.5);
  const SelfTrainResult result = SelfTrain(object, clouds, detector, options);
  REQUIRE(result.initial.percent_oc == 0.0);
  CHECK(result.best_epoch > 0);
  CHECK(result.best.percent_identified == 100.0);
  // Oracle: the kept detector + corrector, without re-estimation, on every cloud.
  PipelineOptions as_used = options.pipeline;
  as_used.certificate.global.reestimate = false;
  CHECK(MeasureCertified(object, clouds, detector, as_used).percent_oc == 100.0);
}
