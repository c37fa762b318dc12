// Automatic eps_oc: the noise estimate against known Gaussian noise, the
// sampling-density term against the sample size, and the proposal against the
// certificate it is meant to pass.
#include <doctest/doctest.h>

#include <limits>

#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/method/auto_threshold.hpp"
#include "c3po/method/certificate.hpp"
#include "test_objects.hpp"

using namespace c3po;

namespace {

// n points uniform on a 0.2 x 0.2 patch of a tilted plane, plus isotropic
// Gaussian noise sigma.
PointSet NoisyPlane(int n, double sigma, std::uint64_t seed) {
  Rng rng(seed);
  const Eigen::Matrix3d tilt = rng.Rotation();
  PointSet cloud(3, n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p(rng.Uniform(-0.1, 0.1), rng.Uniform(-0.1, 0.1), 0.0);
    const Eigen::Vector3d noise(rng.Normal(), rng.Normal(), rng.Normal());
    cloud.col(i) = tilt * p + Eigen::Vector3d(0.3, 0.1, 0.8) + sigma * noise;
  }
  return cloud;
}

// n points on a sphere of radius r (a curved surface), plus noise.
PointSet NoisySphere(int n, double radius, double sigma, std::uint64_t seed) {
  Rng rng(seed);
  PointSet cloud(3, n);
  for (int i = 0; i < n; ++i) {
    cloud.col(i) = radius * rng.UnitVector() + sigma * Eigen::Vector3d(rng.Normal(), rng.Normal(), rng.Normal());
  }
  return cloud;
}

Eigen::VectorXd NearestDistancesBruteForce(const PointSet& from, const PointSet& to) {
  Eigen::VectorXd d(from.cols());
  for (Eigen::Index i = 0; i < from.cols(); ++i) d(i) = (to.colwise() - from.col(i)).colwise().norm().minCoeff();
  return d;
}

ObjectModel Block(int sample_size) {
  ObjectSpec spec;
  spec.name = "block";
  spec.keypoints.resize(3, 4);
  spec.keypoints << -0.1, 0.1, 0.1, -0.1,  //
      -0.05, -0.05, 0.05, 0.05,            //
      0.0, 0.0, 0.06, 0.06;
  spec.eps_oc = 0.01;
  spec.delta_nd = 0.01;
  ObjectModelOptions options;
  options.sample_size = sample_size;
  options.seed = 2;
  return ObjectModel(spec, test::BoxMesh({0, 0, 0.03}, {0.2, 0.1, 0.06}), options);
}

}  // namespace

TEST_CASE("eps_w on planes with known Gaussian noise is within 1.5x of 3 sigma") {
  for (double sigma : {0.0005, 0.001, 0.003}) {
    std::vector<PointSet> clouds;
    for (int c = 0; c < 6; ++c) clouds.push_back(NoisyPlane(1500, sigma, 100 + c));
    const NoiseEstimate noise = EstimateSensorNoise(clouds, {});
    CAPTURE(sigma);
    CAPTURE(noise.eps_w);
    CHECK(noise.clouds == 6);
    CHECK(noise.eps_w > 3 * sigma / 1.5);
    CHECK(noise.eps_w < 3 * sigma * 1.5);
    CHECK(noise.q99 > noise.median);
  }
}

TEST_CASE("eps_w on a curved surface: noise dominates curvature, and a noise-free cloud gives a small bound") {
  const double sigma = 0.001;
  const NoiseEstimate noisy = EstimateSensorNoise({NoisySphere(3000, 0.1, sigma, 4)}, {});
  CHECK(noisy.eps_w > 3 * sigma / 1.5);
  CHECK(noisy.eps_w < 3 * sigma * 1.5);
  const NoiseEstimate clean = EstimateSensorNoise({NoisySphere(3000, 0.1, 0.0, 4)}, {});
  CHECK(clean.eps_w < 0.2 * noisy.eps_w);
}

TEST_CASE("eps_s shrinks as the model sample grows and bounds the surface-to-sample distance") {
  double previous = 1e9;
  for (int size : {1000, 4000, 16000}) {
    const ObjectModel block = Block(size);
    const SamplingDensityEstimate s = EstimateSamplingDensity(block, {});
    CAPTURE(size);
    CHECK(s.eps_s < previous);
    CHECK(s.eps_s >= s.probe_q99);
    CHECK(s.max_gap >= s.spacing);
    previous = s.eps_s;
    // Independent check: fresh surface points (another seed) lie within about
    // eps_s of the sample (brute force distances).
    const PointSet others = SampleSurface(block.mesh(), 2000, 777);
    const Eigen::VectorXd d = NearestDistancesBruteForce(others, block.sample());
    CHECK(d.maxCoeff() < 1.3 * s.eps_s);
  }
}

TEST_CASE("the automatic eps_oc certifies noise-free sampled clouds at their true pose") {
  const ObjectModel block = Block(5000);
  Rng rng(9);
  std::vector<PointSet> clouds;
  std::vector<Pose> poses;
  for (int c = 0; c < 20; ++c) {
    Pose pose{rng.Rotation(), Eigen::Vector3d(rng.Uniform(), rng.Uniform(), rng.Uniform())};
    poses.push_back(pose);
    clouds.push_back(pose * SampleSurface(block.mesh(), 1000, 1000 + c));
  }
  const AutoEpsOcResult result = EstimateEpsOc(block, clouds, {});
  CHECK(result.eps_oc == doctest::Approx(1.25 * (result.noise.eps_w + result.sampling.eps_s)));
  CHECK(result.eps_oc < 0.1 * block.diameter());
  CertificateOptions options;
  options.eps_oc = result.eps_oc;
  options.delta_nd = 0.01;
  for (std::size_t c = 0; c < clouds.size(); ++c) {
    const ObservableCorrectness oc = CheckObservableCorrectness(block, clouds[c], poses[c],
                                                                poses[c] * block.keypoints(), options);
    CAPTURE(c);
    CHECK(oc.passed);
  }
}

TEST_CASE("oc distances: a cluster above the geometric value raises eps_oc, capped, outliers do not") {
  const ObjectModel block = Block(5000);
  const std::vector<PointSet> clouds = {NoisyPlane(1500, 0.001, 3)};
  const AutoEpsOcResult base = EstimateEpsOc(block, clouds, {});
  const double g = base.geometric;
  // Cluster just above g, wrong estimates far above.
  Rng rng(5);
  std::vector<double> distances;
  for (int i = 0; i < 80; ++i) distances.push_back(g * rng.Uniform(1.10, 1.20));
  for (int i = 0; i < 20; ++i) distances.push_back(g * rng.Uniform(5.0, 20.0));
  const AutoEpsOcResult raised = EstimateEpsOc(block, clouds, {}, &distances);
  CHECK(raised.eps_oc > g * 1.20);           // accepts the whole cluster
  CHECK(raised.eps_oc <= 2.0 * g + 1e-15);    // never beyond the cap
  CHECK(raised.oc_fraction_below == doctest::Approx(0.8));
  CHECK(raised.oc_count == 100);
  // Cluster below g: the geometric value stands.
  std::vector<double> low;
  for (int i = 0; i < 50; ++i) low.push_back(g * rng.Uniform(0.5, 0.7));
  const AutoEpsOcResult kept = EstimateEpsOc(block, clouds, {}, &low);
  CHECK(kept.eps_oc == doctest::Approx(g));
  // Too few distances: unused.
  const std::vector<double> few = {3 * g, 3 * g};
  CHECK(EstimateEpsOc(block, clouds, {}, &few).eps_oc == doctest::Approx(g));
}

TEST_CASE("RethresholdObservableCorrectness matches a fresh certificate") {
  const ObjectModel block = Block(3000);
  const Pose pose{Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 0.5)};
  const PointSet cloud = pose * SampleSurface(block.mesh(), 500, 4);
  CertificateOptions options;
  options.delta_nd = 0.01;
  for (double eps : {0.001, 0.004, 0.02}) {
    options.eps_oc = 0.05;
    ObservableCorrectness oc = CheckObservableCorrectness(block, cloud, pose, pose * block.keypoints(), options);
    RethresholdObservableCorrectness(&oc, eps);
    options.eps_oc = eps;
    const ObservableCorrectness fresh = CheckObservableCorrectness(block, cloud, pose, pose * block.keypoints(), options);
    CHECK(oc.passed == fresh.passed);
    CHECK(oc.eps_oc == eps);
  }
}

TEST_CASE("degenerate inputs: no usable cloud is an InputError, bad options throw") {
  const ObjectModel block = Block(1000);
  CHECK_THROWS_AS(EstimateEpsOc(block, {}, {}), InputError);
  CHECK_THROWS_AS(EstimateEpsOc(block, {PointSet(3, 5)}, {}), InputError);
  PointSet nan_cloud = PointSet::Constant(3, 100, std::numeric_limits<double>::quiet_NaN());
  CHECK_THROWS_AS(EstimateEpsOc(block, {nan_cloud}, {}), InputError);
  AutoEpsOcOptions bad;
  bad.margin = 0.5;
  CHECK_THROWS_AS(EstimateEpsOc(block, {NoisyPlane(100, 0.001, 1)}, bad), InputError);
  CHECK(SampleQuantile({}, 0.5) == 0.0);
  CHECK(SampleQuantile({3.0, 1.0, 2.0}, 0.5) == 2.0);
  CHECK(SampleQuantile({0.0, 10.0}, 0.25) == doctest::Approx(2.5));
}
