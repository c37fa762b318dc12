// Self-training inputs from cameras (method/selftrain_inputs.hpp) against
// independent oracles: an augmented copy without noise is an ordered
// subsequence of its instance of the stated size (two-pointer check); with
// noise, the difference to the noise-free copy of the same seed has the
// stated sigma (sample statistics over many points); seeds reproduce bytes.
// Sources are grouped by image, failed sources skipped without moving the
// others' groups. SelfTrain's split by group: the clouds trained on are whole
// groups, and at least one group is held out (counted from the detector's
// training calls).
#include <doctest/doctest.h>

#include <algorithm>
#include <map>
#include <set>

#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/method/selftrain.hpp"
#include "c3po/method/selftrain_inputs.hpp"
#include "test_objects.hpp"

using namespace c3po;

namespace {

PointSet RandomCloud(int n, std::uint64_t seed) {
  Rng rng(seed);
  PointSet cloud(3, n);
  for (Eigen::Index j = 0; j < n; ++j) cloud.col(j) = Eigen::Vector3d(rng.Uniform(), rng.Uniform(), rng.Uniform());
  return cloud;
}

UnlabelledClouds Instances(const std::vector<int>& sizes) {
  UnlabelledClouds data;
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    data.clouds.push_back(RandomCloud(sizes[i], 10 + i));
    data.groups.push_back(static_cast<int>(i / 2));
    Pose truth;
    truth.t = Eigen::Vector3d(static_cast<double>(i), 0, 1);
    data.truth.push_back(truth);
    data.names.push_back("c" + std::to_string(i));
    data.labels.push_back(i % 2 ? "a" : "");
  }
  return data;
}

// True when `part` is `whole` with some columns removed, order kept.
bool IsOrderedSubsequence(const PointSet& part, const PointSet& whole) {
  Eigen::Index j = 0;
  for (Eigen::Index i = 0; i < part.cols(); ++i) {
    while (j < whole.cols() && whole.col(j) != part.col(i)) ++j;
    if (j == whole.cols()) return false;
    ++j;
  }
  return true;
}

}  // namespace

TEST_CASE("augmentation: copies drop the stated fraction, keep order, carry group, truth, name and frame") {
  UnlabelledClouds data = Instances({1000, 37, 1, 2});
  // Each instance's depth frame (distinct images): every copy keeps its own.
  for (std::size_t i = 0; i < data.clouds.size(); ++i) {
    data.frames.push_back(
        DepthView{std::make_shared<DepthImage>(), PinholeCamera{}, std::nullopt, 0.0, nullptr, nullptr});
  }
  AugmentOptions options;
  options.copies = 3;
  options.noise_sigma = 0.0;
  options.seed = 5;
  const UnlabelledClouds copies = Augment(data, options);
  REQUIRE(copies.clouds.size() == 12);
  for (std::size_t k = 0; k < copies.clouds.size(); ++k) {
    const std::size_t i = k / 3;
    const Eigen::Index n = data.clouds[i].cols();
    // n - round(0.1 n), never below one point.
    const Eigen::Index expected = std::max<Eigen::Index>(1, n - static_cast<Eigen::Index>(std::lround(0.1 * n)));
    CHECK(copies.clouds[k].cols() == expected);
    CHECK(IsOrderedSubsequence(copies.clouds[k], data.clouds[i]));
    CHECK(copies.groups[k] == data.groups[i]);
    CHECK(copies.truth[k]->t == data.truth[i]->t);
    CHECK(copies.names[k] == data.names[i] + "#" + std::to_string(k % 3));
    CHECK(copies.labels[k] == data.labels[i]);
    CHECK(copies.frames[k].depth == data.frames[i].depth);
  }
  // The copies of one instance drop different points.
  CHECK(copies.clouds[0] != copies.clouds[1]);
  // copies = 0: the instances unchanged.
  options.copies = 0;
  const UnlabelledClouds same = Augment(data, options);
  REQUIRE(same.clouds.size() == data.clouds.size());
  CHECK(same.clouds[0] == data.clouds[0]);
  // Nothing in, nothing out.
  options.copies = 4;
  CHECK(Augment(UnlabelledClouds{}, options).clouds.empty());
  // Frames are optional (none at all), but one per cloud when given.
  data.frames.clear();
  CHECK(Augment(data, options).frames.empty());
  data.frames.resize(1);
  CHECK_THROWS_AS(Augment(data, options), std::invalid_argument);
}

TEST_CASE("augmentation: the noise has the stated sigma, the same seed gives the same clouds") {
  const UnlabelledClouds data = Instances({20000});
  AugmentOptions clean;
  clean.copies = 2;
  clean.noise_sigma = 0.0;
  clean.seed = 3;
  AugmentOptions noisy = clean;
  noisy.noise_sigma = 0.001;
  const UnlabelledClouds a = Augment(data, clean);
  const UnlabelledClouds b = Augment(data, noisy);
  for (int k = 0; k < 2; ++k) {
    REQUIRE(a.clouds[k].cols() == b.clouds[k].cols());
    const PointSet difference = b.clouds[k] - a.clouds[k];
    const Eigen::ArrayXd d = Eigen::Map<const Eigen::ArrayXd>(difference.data(), difference.size());
    const double mean = d.mean();
    const double sigma = std::sqrt((d - mean).square().mean());
    CHECK(std::abs(mean) < 0.00005);              // 54000 samples: standard error 4.3e-6
    CHECK(sigma == doctest::Approx(0.001).epsilon(0.02));
  }
  CHECK(Augment(data, noisy).clouds[1] == b.clouds[1]);   // reproducible
  noisy.seed = 4;
  CHECK(Augment(data, noisy).clouds[1] != b.clouds[1]);
}

TEST_CASE("augmentation options are checked") {
  AugmentOptions options;
  options.copies = -1;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
  options = AugmentOptions{};
  options.drop_fraction = 1.0;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
  options = AugmentOptions{};
  options.noise_sigma = std::nan("");
  CHECK_THROWS_AS(Augment(Instances({10}), options), std::invalid_argument);
  UnlabelledClouds short_labels = Instances({10, 10});
  short_labels.labels.pop_back();
  CHECK_THROWS_AS(Augment(short_labels, AugmentOptions{}), std::invalid_argument);
}

TEST_CASE("loading sources: one group per image, unreadable sources skipped with their reason") {
  std::vector<PointSet> clouds;
  for (int i = 0; i < 6; ++i) clouds.push_back(RandomCloud(20, 100 + i));
  std::vector<CloudSource> sources;
  // Images: (1,1) (1,1) (1,2) (2,1) (2,1); the second (1,2) instance is too small; one plain source.
  const int scene[] = {1, 1, 1, 1, 2, 2};
  const int image[] = {1, 1, 2, 2, 1, 1};
  for (int i = 0; i < 6; ++i) {
    CloudSource source;
    source.name = "s" + std::to_string(i);
    const PointSet cloud = i == 3 ? PointSet(3, 2) : clouds[i];
    source.load_segment = [cloud, i]() {
      SegmentCloud s;
      s.cloud = cloud;
      s.depth = std::make_shared<DepthImage>();   // the image the segment came from
      s.camera.fx = 500.0 + i;
      s.pixels.assign(static_cast<std::size_t>(cloud.cols()), 0);
      s.mask_pixels = s.pixels.size();
      return s;
    };
    CloudProvenance p;
    p.scene_id = scene[i];
    p.im_id = image[i];
    p.gt_id = i;
    source.provenance = p;
    if (i != 5) source.scene_from_model_truth = Pose{};
    sources.push_back(std::move(source));
  }
  const PointSet plain = RandomCloud(9, 7);
  CloudSource file;
  file.name = "plain";
  file.load = [plain]() { return plain; };
  sources.push_back(file);

  const UnlabelledClouds data = LoadUnlabelledClouds(sources);
  REQUIRE(data.clouds.size() == 6);
  REQUIRE(data.skipped.size() == 1);
  CHECK(data.skipped[0].find("s3") != std::string::npos);
  CHECK(data.names == std::vector<std::string>{"s0", "s1", "s2", "s4", "s5", "plain"});
  CHECK(data.clouds[3] == clouds[4]);
  CHECK(data.clouds[5] == plain);
  // Same image, same group; different images and the plain source, different groups.
  CHECK(data.groups[0] == data.groups[1]);
  CHECK(data.groups[3] == data.groups[4]);
  CHECK(std::set<int>{data.groups[0], data.groups[2], data.groups[3], data.groups[5]}.size() == 4);
  CHECK_FALSE(data.AllHaveTruth());   // s5 and the plain source have none
  // Each segment keeps its frame (the free-space test of its certificates);
  // the plain source has none.
  REQUIRE(data.frames.size() == 6);
  CHECK(data.frames[3].depth != nullptr);
  CHECK(data.frames[3].camera.fx == 504.0);
  CHECK(data.frames[5].depth == nullptr);
}

namespace {

// Keypoints = cloud centroid + learned offsets; records the clouds trained on.
class RecordingOffsetDetector : public TrainableDetector {
 public:
  explicit RecordingOffsetDetector(PointSet offsets) : offsets_(std::move(offsets)) {}
  std::string name() const override { return "offset"; }
  int num_keypoints() const override { return static_cast<int>(offsets_.cols()); }
  PointSet Detect(const PointSet& cloud) const override {
    return offsets_.colwise() + Eigen::Vector3d(cloud.rowwise().mean());
  }
  double TrainStep(const std::vector<PointSet>& clouds, const std::vector<PointSet>&) override {
    trained.insert(trained.end(), clouds.begin(), clouds.end());
    return 0.0;
  }
  std::vector<float> GetWeights() const override { return std::vector<float>(offsets_.size(), 0.0f); }
  void SetWeights(const std::vector<float>&) override {}
  void Save(const std::string&, const std::string&) const override {}
  void SaveCheckpoint(const std::string&, const std::string&) const override {}
  std::string LoadCheckpoint(const std::string&) override { return "{}"; }
  std::vector<PointSet> trained;

 private:
  PointSet offsets_;
};

}  // namespace

TEST_CASE("self-training splits by group: whole groups are trained on and at least one is held out"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  const ObjectModel object = test::AsymmetricObject(8000);
  // 10 images of 1-4 instances; every cloud a full, exactly detectable view.
  std::vector<PointSet> clouds;
  std::vector<int> groups;
  Rng rng(2);
  for (int g = 0; g < 10; ++g) {
    for (int k = 0; k <= g % 4; ++k) {
      const Eigen::Vector3d t(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(1, 2));
      clouds.push_back(SampleSurface(object.mesh(), 300, 70 + clouds.size()).colwise() + t);
      groups.push_back(100 + 7 * g);   // any int labels
    }
  }
  SelfTrainOptions options;
  options.epochs = 1;
  options.batch = 4;
  options.validation_fraction = 0.3;
  options.stop_at_percent_oc = 101;
  options.pipeline.certificate = CertificateOptions::FromObject(object.spec());
  options.pipeline.certificate.eps_oc = 0.01;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    options.seed = seed;
    RecordingOffsetDetector detector(object.keypoints().colwise() - Eigen::Vector3d(object.sample().rowwise().mean()));
    SelfTrain(object, clouds, detector, options, {}, {}, false, nullptr, &groups);
    std::map<int, int> trained_per_group, size_of_group;
    for (int g : groups) ++size_of_group[g];
    for (const PointSet& cloud : detector.trained) {
      for (std::size_t i = 0; i < clouds.size(); ++i) {
        if (clouds[i].cols() == cloud.cols() && clouds[i] == cloud) ++trained_per_group[groups[i]];
      }
    }
    int held_out_clouds = 0, held_out_groups = 0;
    for (const auto& [g, size] : size_of_group) {
      const int trained = trained_per_group.count(g) ? trained_per_group[g] : 0;
      CHECK((trained == 0 || trained == size));   // never part of a group
      if (trained == 0) {
        ++held_out_groups;
        held_out_clouds += size;
      }
    }
    CHECK(held_out_groups >= 1);
    CHECK(held_out_groups < static_cast<int>(size_of_group.size()));
    // About the validation fraction of 25 clouds (whole groups of <= 4 may overshoot).
    CHECK(held_out_clouds >= 7);
    CHECK(held_out_clouds <= 7 + 3);
  }
  // One image only: nothing to split.
  const std::vector<int> one(clouds.size(), 5);
  RecordingOffsetDetector detector(object.keypoints());
  CHECK_THROWS_WITH_AS(SelfTrain(object, clouds, detector, options, {}, {}, false, nullptr, &one),
                       doctest::Contains("one image"), InputError);
  const std::vector<int> short_groups(3, 0);
  CHECK_THROWS_AS(SelfTrain(object, clouds, detector, options, {}, {}, false, nullptr, &short_groups),
                  std::invalid_argument);
}

TEST_CASE("SplitValidation: a partition of the clouds, whole groups, the stated fraction") {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    // Without groups: round(f n) held out, every index exactly once.
    const ValidationSplit plain = SplitValidation(40, nullptr, 0.2, seed, "test");
    CHECK(plain.validation.size() == 8u);
    std::vector<int> all = plain.validation;
    all.insert(all.end(), plain.train.begin(), plain.train.end());
    std::sort(all.begin(), all.end());
    for (int i = 0; i < 40; ++i) CHECK(all[static_cast<std::size_t>(i)] == i);
    // With groups of 3 (an image's augmented copies): never cut.
    std::vector<int> groups;
    for (int i = 0; i < 30; ++i) groups.push_back(i / 3);
    const ValidationSplit by_image = SplitValidation(30, &groups, 0.25, seed, "test");
    std::set<int> held_groups, trained_groups;
    for (int i : by_image.validation) held_groups.insert(groups[static_cast<std::size_t>(i)]);
    for (int i : by_image.train) trained_groups.insert(groups[static_cast<std::size_t>(i)]);
    for (int g : held_groups) CHECK(trained_groups.count(g) == 0);
    CHECK(by_image.validation.size() + by_image.train.size() == 30u);
    CHECK(by_image.validation.size() % 3 == 0);
    CHECK(by_image.validation.size() >= 9u);   // round(0.25 * 30) = 8, whole groups of 3
    CHECK(by_image.validation.size() <= 8u + 2u + 1u);
    // Same seed, same split.
    const ValidationSplit again = SplitValidation(30, &groups, 0.25, seed, "test");
    CHECK(again.validation == by_image.validation);
  }
  const std::vector<int> one(5, 0);
  CHECK_THROWS_WITH_AS(SplitValidation(5, &one, 0.2, 1, "c3po train"), doctest::Contains("c3po train"), InputError);
  CHECK_THROWS_AS(SplitValidation(1, nullptr, 0.2, 1, "test"), std::invalid_argument);
}

TEST_CASE("LabelWithTruth: each cloud's label is the object's keypoints posed at its truth") {
  const ObjectModel object = test::AsymmetricObject(2000);
  UnlabelledClouds clouds;
  Rng rng(9);
  std::vector<Pose> poses;
  for (int i = 0; i < 4; ++i) {
    Pose pose;
    pose.R = Eigen::Quaterniond(rng.Normal(), rng.Normal(), rng.Normal(), rng.Normal()).normalized().toRotationMatrix();
    pose.t = Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(1, 3));
    poses.push_back(pose);
    clouds.clouds.push_back(RandomCloud(50, 100 + i));
    clouds.truth.push_back(pose);
    clouds.names.push_back("cloud" + std::to_string(i));
    clouds.groups.push_back(i);
    clouds.labels.push_back("");
  }
  const std::vector<TrainingSample> samples = LabelWithTruth(clouds, object, "c3po train");
  REQUIRE(samples.size() == 4u);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    CHECK(samples[i].cloud == clouds.clouds[i]);
    REQUIRE(samples[i].keypoints.cols() == object.num_keypoints());
    for (int k = 0; k < object.num_keypoints(); ++k) {
      // Oracle: x = R b + t written out entry by entry.
      for (int r = 0; r < 3; ++r) {
        double expected = poses[i].t(r);
        for (int c = 0; c < 3; ++c) expected += poses[i].R(r, c) * object.keypoints()(c, k);
        CHECK(samples[i].keypoints(r, k) == doctest::Approx(expected).epsilon(1e-12));
      }
    }
  }
  clouds.truth[2].reset();
  CHECK_THROWS_WITH_AS(LabelWithTruth(clouds, object, "c3po train"), doctest::Contains("cloud2"), InputError);
}

TEST_CASE("mixed camera inputs: another object's augmented instances are never pseudo-labels"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  const ObjectModel object = test::AsymmetricObject(8000);
  // Images with one instance of the object (obj_id 1) and one of a 12 cm cube
  // (obj_id 2), as segment sources; the detector claims the object in both.
  const Mesh cube = test::BoxMesh({0, 0, 0}, {0.12, 0.12, 0.12});
  std::vector<CloudSource> sources;
  Rng rng(8);
  for (int image = 0; image < 8; ++image) {
    for (int obj_id : {1, 2}) {
      const Eigen::Vector3d t(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(1, 2));
      const PointSet cloud =
          (obj_id == 1 ? SampleSurface(object.mesh(), 300, 500 + image) : SampleSurface(cube, 300, 600 + image))
              .colwise() + t;
      CloudSource source;
      source.name = std::to_string(image) + "_" + std::to_string(obj_id);
      source.load_segment = [cloud]() {
        SegmentCloud s;
        s.cloud = cloud;
        s.pixels.assign(static_cast<std::size_t>(cloud.cols()), 0);
        s.mask_pixels = s.pixels.size();
        return s;
      };
      CloudProvenance p;
      p.scene_id = 1;
      p.im_id = image;
      p.gt_id = obj_id - 1;
      p.obj_id = obj_id;
      source.provenance = p;
      sources.push_back(std::move(source));
    }
  }
  UnlabelledClouds data = LoadUnlabelledClouds(sources);
  REQUIRE(data.clouds.size() == 16);
  CHECK(data.labels[0] == "obj_000001");
  CHECK(data.labels[1] == "obj_000002");
  AugmentOptions augment;
  augment.copies = 3;
  augment.noise_sigma = 0.0005;
  augment.seed = 2;
  data = Augment(data, augment);
  REQUIRE(data.clouds.size() == 48);
  SelfTrainOptions options;
  options.epochs = 2;
  options.batch = 8;
  options.validation_fraction = 0.25;
  options.stop_at_percent_oc = 101;
  options.patience = 0;
  options.pipeline.certificate = CertificateOptions::FromObject(object.spec());
  options.pipeline.certificate.eps_oc = 0.01;
  RecordingOffsetDetector detector(object.keypoints().colwise() - Eigen::Vector3d(object.sample().rowwise().mean()));
  const SelfTrainResult result = SelfTrain(object, data.clouds, detector, options, {}, {}, false, nullptr, &data.groups);
  REQUIRE(result.pseudo_label_uses.size() == data.clouds.size());
  int own_uses = 0, total_uses = 0;
  for (std::size_t i = 0; i < data.clouds.size(); ++i) {
    CAPTURE(data.names[i]);
    if (data.labels[i] == "obj_000002") CHECK(result.pseudo_label_uses[i] == 0);
    if (data.labels[i] == "obj_000001") own_uses += result.pseudo_label_uses[i];
    total_uses += result.pseudo_label_uses[i];
  }
  CHECK(own_uses > 0);
  // The uses count exactly the clouds the detector was trained on.
  CHECK(total_uses == static_cast<int>(detector.trained.size()));
  for (const PointSet& cloud : detector.trained) {
    bool own = false;
    for (std::size_t i = 0; i < data.clouds.size(); ++i) {
      own = own || (data.labels[i] == "obj_000001" && data.clouds[i].cols() == cloud.cols() && data.clouds[i] == cloud);
    }
    CHECK(own);
  }
}
