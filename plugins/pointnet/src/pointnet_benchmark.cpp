// Throughput of the pointnet network on random clouds (no object needed).
#include <chrono>
#include <ctime>
#include <stdexcept>

#include "c3po/base/parallel.hpp"
#include "c3po/base/random.hpp"
#include "c3po/plugins/pointnet.hpp"

namespace c3po {
namespace {

double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Random clouds of 1000 points in a unit box and random keypoints: the
// figures include input preparation (centring, subsampling to n).
std::vector<PointSet> RandomClouds(int count, int points, Rng* rng) {
  std::vector<PointSet> clouds(static_cast<std::size_t>(count));
  for (auto& c : clouds) {
    c.resize(3, points);
    for (Eigen::Index i = 0; i < c.size(); ++i) c.data()[i] = rng->Uniform(-0.5, 0.5);
  }
  return clouds;
}

struct Rate {
  double per_second = 0.0;
  double per_cpu_second = 0.0;
};

// Repeats `step` (which handles `items` items) for at least `seconds`.
template <typename Step>
Rate Measure(double seconds, int items, const Step& step) {
  step();   // warm-up (allocations, inference pool)
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = ProcessCpuSeconds();
  long done = 0;
  double elapsed = 0.0;
  do {
    step();
    done += items;
    elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  } while (elapsed < seconds);
  Rate rate;
  rate.per_second = static_cast<double>(done) / elapsed;
  rate.per_cpu_second = static_cast<double>(done) / (ProcessCpuSeconds() - cpu_start);
  return rate;
}

}  // namespace

void PointNetBenchmarkOptions::Check() const {
  if (num_points < 1 || batch < 1 || num_keypoints < 1 || inference_batch < 1) {
    throw std::invalid_argument("benchmark sizes must be >= 1");
  }
  if (!(seconds > 0.0)) throw std::invalid_argument("seconds must be > 0");
}

PointNetBenchmarkResult RunPointNetBenchmark(const PointNetBenchmarkOptions& options) {
  options.Check();
  PointNetIdentity identity;
  identity.object_name = "benchmark";
  identity.keypoint_hash = "none";
  identity.num_keypoints = options.num_keypoints;
  identity.scale = 1.0;
  PointNetArchitecture architecture;
  architecture.num_points = options.num_points;
  PointNetDetector detector(identity, architecture, 1);
  Rng rng(7);
  const int cloud_points = 1000;
  const std::vector<PointSet> train_clouds = RandomClouds(options.batch, cloud_points, &rng);
  const std::vector<PointSet> targets = RandomClouds(options.batch, options.num_keypoints, &rng);
  const std::vector<PointSet> test_clouds = RandomClouds(options.inference_batch, cloud_points, &rng);
  PointNetTrainOptions train_options;
  train_options.num_points = options.num_points;

  PointNetBenchmarkResult result;
  result.threads = options.threads > 0 ? options.threads : DefaultThreadCount();
  result.parameters = detector.GetWeights().size();
  const Rate train = Measure(options.seconds, options.batch, [&] {
    detector.TrainStep(train_clouds, targets, train_options);
  });
  const Rate inference = Measure(options.seconds, options.inference_batch, [&] {
    detector.DetectBatch(test_clouds);
  });
  result.train_samples_per_second = train.per_second;
  result.train_samples_per_cpu_second = train.per_cpu_second;
  result.inference_clouds_per_second = inference.per_second;
  result.inference_clouds_per_cpu_second = inference.per_cpu_second;
  return result;
}

}  // namespace c3po
