// Self-training: a trainable test detector (keypoints = cloud centroid +
// learned per-keypoint offsets) improves its certified fraction from its own
// certified outputs; nothing certified => clear error; resume == uninterrupted.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
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
  options.pipeline.certificate = CertificateOptions::FromObject(object.spec());
  options.pipeline.certificate.eps_oc = 0.01;
  return options;
}

PointSet CentredKeypoints(const ObjectModel& object) {
  return object.keypoints().colwise() - Eigen::Vector3d(object.sample().rowwise().mean());
}

}  // namespace

TEST_CASE("self-training raises the certified fraction of a biased detector") {
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

TEST_CASE("resuming from a checkpoint gives the uninterrupted result") {
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
}
