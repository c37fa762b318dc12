// The pointnet detector: forward pass against a plain-Eigen oracle, gradients
// against finite differences, training (overfitting, determinism, resumable
// checkpoints) and the model file (round trip, wrong object, corrupt files).
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/base/random.hpp"
#include "c3po/object/object_io.hpp"
#include "test_helpers.hpp"

#if __has_include(<c3po/plugins/pointnet.hpp>)
#include <c3po/plugins/pointnet.hpp>
#define C3PO_TEST_HAVE_POINTNET 1
#endif

#ifdef C3PO_TEST_HAVE_POINTNET
namespace {

using c3po::PointNetArchitecture;
using c3po::PointNetDetector;
using c3po::PointNetIdentity;
using c3po::PointSet;
using c3po::Rng;
using c3po::TrainingSample;

PointNetIdentity Identity(const std::string& name, int keypoints, double scale = 1.0) {
  PointNetIdentity identity;
  identity.object_name = name;
  identity.keypoint_hash = "hash-of-" + name;
  identity.num_keypoints = keypoints;
  identity.scale = scale;
  return identity;
}

PointNetArchitecture SmallArchitecture(int num_points) {
  PointNetArchitecture architecture;
  architecture.num_points = num_points;
  architecture.point_mlp = {6, 8, 12};
  architecture.head = {10};
  return architecture;
}

PointSet RandomPoints(int count, Rng* rng, double extent = 1.0) {
  PointSet points(3, count);
  for (Eigen::Index i = 0; i < points.size(); ++i) points.data()[i] = rng->Uniform(-extent, extent);
  return points;
}

// A toy dataset whose keypoints are a function of the cloud: an anisotropic
// blob, keypoints = centroid +- its principal-axis-aligned extents.
std::vector<TrainingSample> ToyDataset(int count, int points, std::uint64_t seed) {
  std::vector<TrainingSample> samples;
  Rng rng(seed);
  for (int s = 0; s < count; ++s) {
    const Eigen::Vector3d extent(rng.Uniform(0.2, 1.0), rng.Uniform(0.2, 1.0), rng.Uniform(0.2, 1.0));
    const Eigen::Vector3d center(rng.Uniform(-2, 2), rng.Uniform(-2, 2), rng.Uniform(-2, 2));
    TrainingSample sample;
    sample.cloud = RandomPoints(points, &rng);
    sample.cloud = (extent.asDiagonal() * sample.cloud).colwise() + center;
    sample.keypoints.resize(3, 2);
    sample.keypoints.col(0) = center + extent;
    sample.keypoints.col(1) = center - extent;
    samples.push_back(sample);
  }
  return samples;
}

// Oracle: the network written out with plain Eigen (double) from the flat
// weights and their documented layout, on all points of a cloud with <= n points.
PointSet OracleForward(const PointNetDetector& detector, const PointSet& cloud) {
  const std::vector<float> weights = detector.GetWeights();
  const auto blocks = detector.WeightBlocks();
  auto matrix = [&](std::size_t b, Eigen::Index rows) {
    const auto& block = blocks[b];
    const Eigen::Index cols = static_cast<Eigen::Index>(block.size) / rows;
    Eigen::MatrixXd m(rows, cols);
    for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = weights[block.offset + static_cast<std::size_t>(i)];
    return m;
  };
  const double scale = detector.identity().scale;
  const Eigen::Vector3d centroid = cloud.rowwise().mean();
  Eigen::MatrixXd a = (cloud.colwise() - centroid) / scale;
  std::size_t b = 0;
  const auto& arch = detector.architecture();
  for (std::size_t l = 0; l < arch.point_mlp.size(); ++l, b += 2) {
    const Eigen::Index out = arch.point_mlp[l];
    a = ((matrix(b, out) * a).colwise() + matrix(b + 1, out).col(0)).cwiseMax(0.0);
  }
  Eigen::VectorXd g = a.rowwise().maxCoeff();
  for (std::size_t h = 0; h < arch.head.size(); ++h, b += 2) {
    const Eigen::Index out = arch.head[h];
    g = (matrix(b, out) * g + matrix(b + 1, out).col(0)).cwiseMax(0.0);
  }
  const Eigen::Index outputs = 3 * detector.num_keypoints();
  const Eigen::VectorXd y = matrix(b, outputs) * g + matrix(b + 1, outputs).col(0);
  PointSet keypoints(3, detector.num_keypoints());
  for (Eigen::Index i = 0; i < keypoints.cols(); ++i) keypoints.col(i) = centroid + scale * y.segment<3>(3 * i);
  return keypoints;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
}

// Restores C3PO_THREADS when it goes out of scope.
class ThreadCount {
 public:
  explicit ThreadCount(int threads) {
    if (const char* old = std::getenv("C3PO_THREADS")) old_ = old;
    setenv("C3PO_THREADS", std::to_string(threads).c_str(), 1);
  }
  ~ThreadCount() {
    if (old_.empty()) unsetenv("C3PO_THREADS"); else setenv("C3PO_THREADS", old_.c_str(), 1);
  }

 private:
  std::string old_;
};

c3po::PointNetTrainOptions ToyOptions(int num_points) {
  c3po::PointNetTrainOptions options;
  options.num_points = num_points;
  options.epochs = 4;
  options.batch = 8;
  options.lr = 3e-3;
  options.seed = 11;
  options.rotate_about_camera_deg = 10.0;
  options.point_dropout = 0.2;
  options.noise_sigma = 0.01;
  return options;
}

}  // namespace

TEST_CASE("pointnet forward pass equals a plain Eigen oracle, with repeated and subsampled points") {
  Rng rng(1);
  PointNetDetector detector(Identity("toy", 3, 2.5), SmallArchitecture(32), 5);
  // Fewer points than n: repeated cyclically, which max pooling ignores.
  for (int count : {1, 7, 32}) {
    const PointSet cloud = RandomPoints(count, &rng, 3.0).colwise() + Eigen::Vector3d(10, -4, 2);
    const PointSet detected = detector.Detect(cloud);
    const PointSet expected = OracleForward(detector, cloud);
    CHECK((detected - expected).cwiseAbs().maxCoeff() < 1e-4 * (1.0 + expected.cwiseAbs().maxCoeff()));
  }
  // More points than n: a deterministic subsample of n points.
  const PointSet big = RandomPoints(500, &rng);
  CHECK(detector.Detect(big) == detector.Detect(big));
  const std::vector<PointSet> batch = {big, RandomPoints(40, &rng), RandomPoints(3, &rng)};
  const std::vector<PointSet> batched = detector.DetectBatch(batch);
  for (std::size_t i = 0; i < batch.size(); ++i) CHECK(batched[i] == detector.Detect(batch[i]));
}

TEST_CASE("pointnet ignores non-finite points and rejects clouds without finite points") {
  Rng rng(2);
  PointNetDetector detector(Identity("toy", 2), SmallArchitecture(16), 1);
  const PointSet clean = RandomPoints(10, &rng);
  PointSet dirty(3, 12);
  dirty << clean.leftCols(5), Eigen::Vector3d(NAN, 0, 0), clean.rightCols(5),
      Eigen::Vector3d(0, INFINITY, 0);
  CHECK(detector.Detect(dirty) == detector.Detect(clean));
  CHECK_THROWS_AS(detector.Detect(PointSet(3, 0)), c3po::InputError);
  CHECK_THROWS_AS(detector.Detect(PointSet::Constant(3, 4, NAN)), c3po::InputError);
}

TEST_CASE("pointnet gradients match central finite differences in every layer") {
  Rng rng(3);
  PointNetDetector detector(Identity("toy", 2, 1.5), SmallArchitecture(24), 9);
  std::vector<PointSet> clouds, targets;
  for (int s = 0; s < 3; ++s) {
    clouds.push_back(RandomPoints(24, &rng, 1.5));   // exactly n: no subsampling
    targets.push_back(RandomPoints(2, &rng));
  }
  std::vector<double> gradient;
  detector.LossAndGradient(clouds, targets, &gradient);
  const std::vector<float> weights = detector.GetWeights();
  REQUIRE(gradient.size() == weights.size());
  // The loss is piecewise smooth (ReLU, max): an entry whose one-sided
  // differences disagree straddles a kink and is skipped (at most a few).
  auto loss_at = [&](std::size_t k, float value) {
    std::vector<float> w = weights;
    w[k] = value;
    detector.SetWeights(w);
    return detector.LossAndGradient(clouds, targets, nullptr);
  };
  int checked = 0, kinks = 0;
  for (const auto& block : detector.WeightBlocks()) {
    CAPTURE(block.name);
    for (int trial = 0; trial < 8; ++trial) {
      const std::size_t k = block.offset + static_cast<std::size_t>(rng.UniformInt(static_cast<int>(block.size)));
      CAPTURE(k);
      const float w = weights[k], h = 1e-3f;
      const double at = loss_at(k, w), plus = loss_at(k, w + h), minus = loss_at(k, w - h);
      const double right = (plus - at) / h, left = (at - minus) / h;
      if (std::abs(right - left) > 5e-3 * std::max(std::abs(right), std::abs(left)) + 5e-4) {
        ++kinks;
        continue;
      }
      ++checked;
      const double central = (plus - minus) / (2.0 * h);
      CHECK(std::abs(central - gradient[k]) <= 1e-2 * std::abs(central) + 5e-4);
    }
  }
  detector.SetWeights(weights);
  MESSAGE(checked << " weights checked, " << kinks << " at kinks skipped");
  CHECK(kinks * 3 <= checked);
}

TEST_CASE("a tiny pointnet overfits a tiny dataset") {
  const auto samples = ToyDataset(8, 48, 4);
  PointNetArchitecture architecture;
  architecture.num_points = 48;
  architecture.point_mlp = {32, 64};
  architecture.head = {64};
  PointNetDetector detector(Identity("toy", 2), architecture, 2);
  const double initial = detector.Evaluate(samples).loss;
  c3po::PointNetTrainOptions options;
  options.num_points = 48;
  options.epochs = 300;
  options.batch = 8;
  options.lr = 3e-3;
  const auto result = detector.Fit(samples, samples, options);
  const double final_loss = detector.Evaluate(samples).loss;
  MESSAGE("toy loss " << initial << " -> " << final_loss << " (best epoch " << result.best_epoch << ")");
  CHECK(final_loss < 0.02 * initial);
  CHECK(final_loss == doctest::Approx(result.best_val_loss));
  REQUIRE(result.epochs.size() == 300u);
}

TEST_CASE("symmetric labellings: plain MSE learns their average, the symmetry-aware loss one of them") {
  // Every toy cloud twice, labelled (c + e, c - e) and (c - e, c + e): a
  // two-fold symmetry that swaps the keypoints. The plain loss's optimum is
  // the average (c, c), a keypoint error |e| from either labelling
  // (analytic); with each labelling as the other's symmetric labelling the
  // network can fit one per cloud.
  const auto base = ToyDataset(8, 48, 4);
  std::vector<TrainingSample> plain, symmetric;
  double mean_half_spread = 0.0;
  for (const auto& sample : base) {
    TrainingSample swapped = sample;
    swapped.keypoints.col(0) = sample.keypoints.col(1);
    swapped.keypoints.col(1) = sample.keypoints.col(0);
    plain.push_back(sample);
    plain.push_back(swapped);
    TrainingSample a = sample, b = swapped;
    a.symmetric_keypoints = {swapped.keypoints};
    b.symmetric_keypoints = {sample.keypoints};
    symmetric.push_back(a);
    symmetric.push_back(b);
    mean_half_spread += 0.5 * (sample.keypoints.col(0) - sample.keypoints.col(1)).norm() / base.size();
  }
  PointNetArchitecture architecture;
  architecture.num_points = 48;
  architecture.point_mlp = {32, 64};
  architecture.head = {64};
  c3po::PointNetTrainOptions options;
  options.num_points = 48;
  options.epochs = 150;
  options.batch = 16;
  options.lr = 3e-3;
  PointNetDetector plain_detector(Identity("toy", 2), architecture, 2);
  const auto plain_fit = plain_detector.Fit(plain, {}, options);
  PointNetDetector symmetric_detector(Identity("toy", 2), architecture, 2);
  const auto symmetric_fit = symmetric_detector.Fit(symmetric, {}, options);
  // Both judged by the error to the nearest labelling (Evaluate's measure).
  const double plain_error = plain_detector.Evaluate(symmetric).keypoint_error;
  const double symmetric_error = symmetric_detector.Evaluate(symmetric).keypoint_error;
  MESSAGE("half spread " << mean_half_spread << ", plain " << plain_error << ", symmetric " << symmetric_error);
  CHECK(plain_error > 0.7 * mean_half_spread);
  CHECK(symmetric_error < 0.25 * plain_error);
  int switched = 0;
  for (const auto& epoch : symmetric_fit.epochs) switched += epoch.labellings_switched;
  CHECK(switched > 0);
  for (const auto& epoch : plain_fit.epochs) CHECK(epoch.labellings_switched == 0);
  // Evaluate measures to the nearest labelling: the detector's own output
  // as a symmetric labelling of a far-off label costs nothing.
  TrainingSample own = base[0];
  own.symmetric_keypoints = {symmetric_detector.Detect(own.cloud)};
  own.keypoints.array() += 5.0;
  CHECK(symmetric_detector.Evaluate({own}).keypoint_error < 1e-9);
}

TEST_CASE("TrainStep lowers the loss of the batch it trains on, with sgd and adam") {
  const auto samples = ToyDataset(6, 20, 5);
  std::vector<PointSet> clouds, keypoints;
  for (const auto& s : samples) {
    clouds.push_back(s.cloud);
    keypoints.push_back(s.keypoints);
  }
  for (const std::string optimizer : {"sgd", "adam"}) {
    CAPTURE(optimizer);
    PointNetDetector detector(Identity("toy", 2), SmallArchitecture(20), 3);
    c3po::PointNetTrainOptions options;
    options.num_points = 20;
    options.optimizer = optimizer;
    options.lr = optimizer == "sgd" ? 1e-2 : 1e-3;
    const double first = detector.TrainStep(clouds, keypoints, options);
    double last = first;
    for (int i = 0; i < 30; ++i) last = detector.TrainStep(clouds, keypoints, options);
    CHECK(last < 0.7 * first);
    const double evaluated = detector.Evaluate(samples).loss;
    const double before_step = detector.TrainStep(clouds, keypoints, options);
    CHECK(evaluated == doctest::Approx(before_step).epsilon(1e-4));
  }
}

TEST_CASE("pointnet training is deterministic and independent of the thread count") {
  const auto samples = ToyDataset(20, 40, 6);
  const auto options = ToyOptions(32);
  auto train = [&](int threads, std::uint64_t seed) {
    ThreadCount scope(threads);
    PointNetDetector detector(Identity("toy", 2), SmallArchitecture(32), 4);
    auto o = options;
    o.seed = seed;
    detector.Fit(samples, {}, o);
    return detector.GetWeights();
  };
  const auto two = train(2, 11);
  CHECK(train(2, 11) == two);
  CHECK(train(1, 11) == two);
  CHECK(train(2, 12) != two);
}

TEST_CASE("a resumed checkpoint gives the weights of an uninterrupted run") {
  c3po::test::TempDir dir("pointnet_resume");
  const auto samples = ToyDataset(20, 40, 7);
  auto options = ToyOptions(32);
  PointNetDetector uninterrupted(Identity("toy", 2), SmallArchitecture(32), 4);
  const auto full = uninterrupted.Fit(samples, {}, options);

  options.checkpoint_path = dir / "run.ckpt";
  PointNetDetector interrupted(Identity("toy", 2), SmallArchitecture(32), 4);
  CHECK_THROWS_AS(interrupted.Fit(samples, {}, options, [](const c3po::EpochLog& log) {
    if (log.epoch == 2) throw c3po::Interrupted();
  }), c3po::Interrupted);
  PointNetDetector resumed(Identity("toy", 2), SmallArchitecture(32), 99);
  CHECK(resumed.LoadCheckpoint(options.checkpoint_path).empty());
  options.resume = true;
  std::vector<int> epochs_run;
  const auto rest = resumed.Fit(samples, {}, options, [&](const c3po::EpochLog& log) {
    epochs_run.push_back(log.epoch);
  });
  CHECK(epochs_run == std::vector<int>{3, 4});
  CHECK(resumed.GetWeights() == uninterrupted.GetWeights());
  REQUIRE(rest.epochs.size() == full.epochs.size());
  CHECK(rest.epochs.back().val_loss == full.epochs.back().val_loss);
  CHECK(rest.best_epoch == full.best_epoch);
  CHECK_THROWS_AS(resumed.LoadCheckpoint(dir / "missing.ckpt"), c3po::InputError);
  // The caller's state travels with the checkpoint; another architecture is refused.
  resumed.SaveCheckpoint(dir / "state.ckpt", R"({"epoch": 7})");
  CHECK(resumed.LoadCheckpoint(dir / "state.ckpt") == R"({"epoch": 7})");
  PointNetDetector other_shape(Identity("toy", 2), SmallArchitecture(16), 4);
  CHECK_THROWS_AS(other_shape.LoadCheckpoint(dir / "state.ckpt"), c3po::InputError);
}

TEST_CASE("fine-tuning: epoch 0 is the starting weights, kept unless an epoch beats them") {
  const auto train = ToyDataset(16, 40, 21);
  const auto validation = ToyDataset(6, 40, 22);
  // A model trained a little (the "init model"), then fine-tuned from its weights.
  PointNetDetector init(Identity("toy", 2), SmallArchitecture(32), 5);
  auto options = ToyOptions(32);
  init.Fit(train, validation, options);
  const std::vector<float> init_weights = init.GetWeights();
  const PointNetDetector::Evaluation init_on_validation = init.Evaluate(validation);
  const PointNetDetector::Evaluation init_on_train = init.Evaluate(train);

  // A step size that throws the network out of its basin: every epoch is worse.
  PointNetDetector thrown(Identity("toy", 2), SmallArchitecture(32), 77);
  thrown.SetWeights(init_weights);
  auto bad = options;
  bad.optimizer = "sgd";
  bad.lr = 5.0;
  bad.epochs = 2;
  bad.validate_initial = true;
  std::vector<int> logged;
  const auto result = thrown.Fit(train, validation, bad, [&](const c3po::EpochLog& log) { logged.push_back(log.epoch); });
  CHECK(logged == std::vector<int>{0, 1, 2});
  REQUIRE(result.epochs.size() == 3u);
  const c3po::EpochLog& zero = result.epochs.front();
  CHECK(zero.epoch == 0);
  CHECK(zero.val_keypoint_error == init_on_validation.keypoint_error);
  CHECK(zero.val_loss == init_on_validation.loss);
  CHECK(zero.train_loss == init_on_train.loss);   // no augmentation at epoch 0
  REQUIRE(result.epochs[1].val_loss > zero.val_loss);
  REQUIRE(result.epochs[2].val_loss > zero.val_loss);
  CHECK(result.best_epoch == 0);
  CHECK(thrown.GetWeights() == init_weights);

  // A sensible step size on the same data: a later epoch beats epoch 0 and is kept.
  PointNetDetector tuned(Identity("toy", 2), SmallArchitecture(32), 78);
  tuned.SetWeights(init_weights);
  auto good = options;
  good.epochs = 30;
  good.validate_initial = true;
  const auto better = tuned.Fit(train, validation, good);
  CHECK(better.epochs.front().val_loss == init_on_validation.loss);
  CHECK(better.best_epoch > 0);
  CHECK(tuned.Evaluate(validation).loss < init_on_validation.loss);
  // Without validate_initial there is no epoch 0 (fresh training is unchanged).
  PointNetDetector plain(Identity("toy", 2), SmallArchitecture(32), 78);
  plain.SetWeights(init_weights);
  CHECK(plain.Fit(train, validation, options).epochs.front().epoch == 1);
}

TEST_CASE("pointnet model files: round trip, wrong object, truncated and corrupt files") {
  c3po::test::TempDir dir("pointnet_model");
  Rng rng(8);
  PointNetDetector detector(Identity("box", 3, 0.3), SmallArchitecture(32), 6);
  detector.set_training_info_json(R"({"note": "unit test"})");
  const std::string path = dir / "model.c3po";
  detector.Save(path, R"({"selftrained": true})");
  CHECK_THROWS_AS(detector.Save(dir / "x.c3po", R"({"object": "mug"})"), std::invalid_argument);
  CHECK(ReadBytes(path).find("\"selftrained\":true") != std::string::npos);

  const auto loaded = PointNetDetector::Load(path, Identity("box", 3, 0.3));
  CHECK(loaded->GetWeights() == detector.GetWeights());
  std::vector<PointSet> clouds = {RandomPoints(100, &rng), RandomPoints(20, &rng)};
  CHECK(loaded->DetectBatch(clouds) == detector.DetectBatch(clouds));
  CHECK(loaded->training_info_json().find("unit test") != std::string::npos);
  CHECK(loaded->identity().scale == 0.3);

  // Another object: a clear message that names the file and both objects.
  try {
    PointNetDetector::Load(path, Identity("mug", 3));
    FAIL("loaded a model for another object");
  } catch (const c3po::InputError& e) {
    const std::string message = e.what();
    CHECK(message.find(path) == 0);
    CHECK(message.find("trained for object 'box'") != std::string::npos);
    CHECK(message.find("not 'mug'") != std::string::npos);
  }
  PointNetIdentity same_name_other_keypoints = Identity("box", 3);
  same_name_other_keypoints.keypoint_hash = "different";
  CHECK_THROWS_AS(PointNetDetector::Load(path, same_name_other_keypoints), c3po::InputError);
  CHECK_THROWS_AS(detector.LoadCheckpoint(path), c3po::InputError);   // a model, not a checkpoint

  // Truncated at every interesting length, corrupted bytes, garbage, missing.
  const std::string bytes = ReadBytes(path);
  const std::size_t header_end = bytes.find('\n');
  const std::string broken = dir / "broken.c3po";
  for (std::size_t length : {std::size_t{0}, std::size_t{1}, header_end / 2, header_end, header_end + 1,
                             header_end + 100, bytes.size() - 1}) {
    CAPTURE(length);
    WriteBytes(broken, bytes.substr(0, length));
    CHECK_THROWS_AS(PointNetDetector::Load(broken, Identity("box", 3)), c3po::InputError);
  }
  std::string flipped = bytes;
  flipped[header_end + 50] = static_cast<char>(flipped[header_end + 50] ^ 0x40);
  WriteBytes(broken, flipped);
  CHECK_THROWS_AS(PointNetDetector::Load(broken, Identity("box", 3)), c3po::InputError);
  std::string bad_header = bytes;
  bad_header[header_end / 3] = '}';
  WriteBytes(broken, bad_header);
  CHECK_THROWS_AS(PointNetDetector::Load(broken, Identity("box", 3)), c3po::InputError);
  // A header edited to claim a huge network (the weights' checksum still
  // holds) is refused before anything is allocated.
  nlohmann::json header = nlohmann::json::parse(bytes.substr(0, header_end));
  header["point_mlp"] = {8192, 8192, 8192};
  WriteBytes(broken, header.dump() + bytes.substr(header_end));
  CHECK_THROWS_AS(PointNetDetector::Load(broken, Identity("box", 3)), c3po::InputError);
  header = nlohmann::json::parse(bytes.substr(0, header_end));
  header["num_points"] = -5;
  WriteBytes(broken, header.dump() + bytes.substr(header_end));
  CHECK_THROWS_AS(PointNetDetector::Load(broken, Identity("box", 3)), c3po::InputError);
  header = nlohmann::json::parse(bytes.substr(0, header_end));
  header["scale"] = "big";
  WriteBytes(broken, header.dump() + bytes.substr(header_end));
  CHECK_THROWS_AS(PointNetDetector::Load(broken, Identity("box", 3)), c3po::InputError);
  WriteBytes(broken, std::string(5000, '\xff'));
  CHECK_THROWS_AS(PointNetDetector::Load(broken, Identity("box", 3)), c3po::InputError);
  CHECK_THROWS_AS(PointNetDetector::Load(dir / "absent.c3po", Identity("box", 3)), c3po::InputError);
}

TEST_CASE("pointnet models of bundled objects load only for their object") {
  c3po::test::TempDir dir("pointnet_objects");
  c3po::ObjectModelOptions sample;
  sample.sample_size = 500;
  const c3po::ObjectModel mug = c3po::LoadObject(c3po::test::SourceDir() + "/annotations/mug.json", sample);
  const c3po::ObjectModel box = c3po::LoadObject(c3po::test::SourceDir() + "/annotations/box.json", sample);
  PointNetArchitecture architecture = SmallArchitecture(32);
  PointNetDetector detector(mug, architecture, 3);
  CHECK(detector.identity().scale == mug.diameter());
  CHECK(detector.num_keypoints() == mug.num_keypoints());
  const std::string path = dir / "mug.c3po";
  detector.Save(path);
  CHECK(PointNetDetector::Load(path, mug)->GetWeights() == detector.GetWeights());
  try {
    PointNetDetector::Load(path, box);
    FAIL("a mug model loaded for the box");
  } catch (const c3po::InputError& e) {
    const std::string message = e.what();
    CHECK(message.find(path + ": trained for object '" + mug.name() + "' (keypoint hash " +
                       mug.KeypointHash() + "), not '" + box.name() + "'") == 0);
  }
}

TEST_CASE("pointnet options reject nonsense") {
  c3po::PointNetTrainOptions options;
  CHECK_NOTHROW(options.Check());
  options.optimizer = "rmsprop";
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
  options = {};
  options.batch = 0;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
  options = {};
  options.point_dropout = 1.0;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
  PointNetArchitecture architecture;
  architecture.point_mlp.clear();
  CHECK_THROWS_AS(architecture.Check(), std::invalid_argument);
  CHECK_THROWS_AS(PointNetDetector(Identity("toy", 0), PointNetArchitecture{}), std::invalid_argument);
  PointNetDetector detector(Identity("toy", 2), SmallArchitecture(16));
  const auto samples = ToyDataset(4, 16, 1);
  c3po::PointNetTrainOptions mismatched;
  mismatched.num_points = 17;
  CHECK_THROWS_AS(detector.Fit(samples, {}, mismatched), std::invalid_argument);
}

#else
TEST_CASE("pointnet plugin not built") {
  MESSAGE("skipped: c3po was configured with C3PO_WITH_POINTNET=OFF");
}
#endif
