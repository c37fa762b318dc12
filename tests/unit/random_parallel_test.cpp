// Rng determinism and distributions (checked against their analytic moments
// and CDFs with binomial / CLT tolerances), ParallelFor coverage and errors.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <set>
#include <stdexcept>
#include <string>
#include <future>
#include <thread>
#include <vector>

#include "c3po/base/parallel.hpp"
#include "c3po/base/random.hpp"

namespace {

std::vector<std::uint64_t> Draw(c3po::Rng rng, int n) {
  std::vector<std::uint64_t> out;
  for (int i = 0; i < n; ++i) out.push_back(rng.Next());
  return out;
}

// Rotation angle from the trace: cos(theta) = (tr R - 1) / 2.
double Angle(const Eigen::Matrix3d& R) { return std::acos(std::clamp((R.trace() - 1) / 2, -1.0, 1.0)); }

}  // namespace

TEST_CASE("Rng is deterministic per seed and per item") {
  CHECK(Draw(c3po::Rng(42), 1000) == Draw(c3po::Rng(42), 1000));
  CHECK(Draw(c3po::Rng(42), 1000) != Draw(c3po::Rng(43), 1000));
  CHECK(Draw(c3po::Rng::ForItem(7, 3), 100) == Draw(c3po::Rng::ForItem(7, 3), 100));
  // Streams of different items, or of the same item under different seeds, differ;
  // no item stream equals the plain stream of its seed.
  std::set<std::vector<std::uint64_t>> streams;
  for (std::uint64_t seed : {0ULL, 1ULL, 7ULL}) {
    streams.insert(Draw(c3po::Rng(seed), 8));
    for (std::uint64_t item = 0; item < 50; ++item) streams.insert(Draw(c3po::Rng::ForItem(seed, item), 8));
  }
  CHECK(streams.size() == 3 * 51);
  // Copies continue identically.
  c3po::Rng a(5);
  a.Next();
  c3po::Rng b = a;
  CHECK(Draw(a, 10) == Draw(b, 10));
}

TEST_CASE("Uniform, UniformInt and Normal have the right moments") {
  c3po::Rng rng(1);
  constexpr int kN = 200000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < kN; ++i) {
    const double u = rng.Uniform();
    REQUIRE(u >= 0.0);
    REQUIRE(u < 1.0);
    sum += u;
    sum2 += u * u;
  }
  // Mean 1/2 (sd 1/sqrt(12 n)), second moment 1/3 (sd sqrt(4/45 / n)); 5 sigma.
  CHECK(std::abs(sum / kN - 0.5) < 5 / std::sqrt(12.0 * kN));
  CHECK(std::abs(sum2 / kN - 1.0 / 3) < 5 * std::sqrt(4.0 / 45 / kN));

  for (int i = 0; i < 1000; ++i) {
    const double v = rng.Uniform(-3.0, 2.0);
    CHECK(v >= -3.0);
    CHECK(v < 2.0);
  }

  constexpr int kBins = 7;
  std::vector<int> counts(kBins, 0);
  for (int i = 0; i < kN; ++i) {
    const int k = rng.UniformInt(kBins);
    REQUIRE(k >= 0);
    REQUIRE(k < kBins);
    ++counts[k];
  }
  const double p = 1.0 / kBins, sigma = std::sqrt(kN * p * (1 - p));
  for (int c : counts) CHECK(std::abs(c - kN * p) < 5 * sigma);
  CHECK(rng.UniformInt(1) == 0);
  CHECK(rng.UniformInt(0) == 0);

  double m1 = 0, m2 = 0, m4 = 0;
  int within_one = 0;
  for (int i = 0; i < kN; ++i) {
    const double z = rng.Normal();
    REQUIRE(std::isfinite(z));
    m1 += z;
    m2 += z * z;
    m4 += z * z * z * z;
    within_one += std::abs(z) < 1 ? 1 : 0;
  }
  CHECK(std::abs(m1 / kN) < 5 / std::sqrt(double(kN)));
  CHECK(std::abs(m2 / kN - 1) < 5 * std::sqrt(2.0 / kN));   // var(z^2) = 2
  CHECK(std::abs(m4 / kN - 3) < 5 * std::sqrt(96.0 / kN));  // var(z^4) = 105 - 9
  const double p1 = std::erf(1 / std::sqrt(2.0));           // P(|z| < 1)
  CHECK(std::abs(within_one / double(kN) - p1) < 5 * std::sqrt(p1 * (1 - p1) / kN));
}

TEST_CASE("UnitVector is uniform on the sphere") {
  c3po::Rng rng(2);
  constexpr int kN = 100000;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (int i = 0; i < kN; ++i) {
    const Eigen::Vector3d v = rng.UnitVector();
    REQUIRE(std::abs(v.norm() - 1) < 1e-12);
    mean += v / kN;
    second += v * v.transpose() / kN;
  }
  // E[v] = 0 (sd per coordinate 1/sqrt(3n)); E[v v^T] = I / 3.
  CHECK(mean.cwiseAbs().maxCoeff() < 5 / std::sqrt(3.0 * kN));
  CHECK((second - Eigen::Matrix3d::Identity() / 3).cwiseAbs().maxCoeff() < 0.01);
}

TEST_CASE("Rotation is a proper rotation, uniform on SO(3)") {
  c3po::Rng rng(3);
  constexpr int kN = 40000;
  Eigen::Matrix3d mean = Eigen::Matrix3d::Zero();
  int below_half_pi = 0;
  for (int i = 0; i < kN; ++i) {
    const Eigen::Matrix3d R = rng.Rotation();
    REQUIRE((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-12);
    REQUIRE(R.determinant() == doctest::Approx(1.0).epsilon(1e-12));
    mean += R / kN;
    below_half_pi += Angle(R) < M_PI / 2 ? 1 : 0;
  }
  // Haar measure: every entry has mean 0 and variance 1/3.
  CHECK(mean.cwiseAbs().maxCoeff() < 5 / std::sqrt(3.0 * kN));
  // Angle CDF under the Haar measure: P(theta <= x) = (x - sin x) / pi.
  const double p = (M_PI / 2 - 1) / M_PI;
  CHECK(std::abs(below_half_pi / double(kN) - p) < 5 * std::sqrt(p * (1 - p) / kN));
}

TEST_CASE("RotationUpTo draws angles uniformly in [0, max]") {
  c3po::Rng rng(4);
  constexpr int kN = 20000;
  const double max_angle = 0.8;
  double sum = 0;
  for (int i = 0; i < kN; ++i) {
    const Eigen::Matrix3d R = rng.RotationUpTo(max_angle);
    REQUIRE(R.determinant() == doctest::Approx(1.0).epsilon(1e-12));
    const double angle = Angle(R);
    CHECK(angle <= max_angle + 1e-7);
    sum += angle;
  }
  CHECK(std::abs(sum / kN - max_angle / 2) < 5 * max_angle / std::sqrt(12.0 * kN));
  CHECK(Angle(rng.RotationUpTo(0.0)) < 1e-7);
}

TEST_CASE("ParallelFor runs every index exactly once") {
  for (int threads : {0, 1, 2, 3, 8, 1000}) {
    for (const auto& range : std::vector<std::pair<int, int>>{{0, 0}, {5, 3}, {0, 1}, {-7, 10}, {3, 5003}}) {
      const int begin = range.first;  // named, not bound: lambdas may not capture structured bindings in C++17
      const int end = range.second;
      CAPTURE(threads);
      CAPTURE(begin);
      const int count = std::max(0, end - begin);
      std::vector<std::atomic<int>> hits(count);
      std::atomic<int> outside{0};
      c3po::ParallelFor(begin, end, [&](int i) {
        if (i < begin || i >= end) {
          outside.fetch_add(1);
        } else {
          hits[i - begin].fetch_add(1);
        }
      }, threads);
      int wrong = 0;
      for (int i = 0; i < count; ++i) wrong += hits[i].load() == 1 ? 0 : 1;
      CHECK(wrong == 0);
      CHECK(outside.load() == 0);
    }
  }
}

TEST_CASE("ParallelFor nested in a ParallelFor body runs inline on that thread, every pair once") {
  for (int threads : {1, 2, 3}) {
    CAPTURE(threads);
    const int outer = 6, inner = 50;
    std::vector<std::atomic<int>> hits(outer * inner);
    std::atomic<int> foreign{0};   // inner items run on another thread than their outer item
    c3po::ParallelFor(0, outer, [&](int i) {
      const std::thread::id mine = std::this_thread::get_id();
      c3po::ParallelFor(0, inner, [&](int j) {
        if (std::this_thread::get_id() != mine) foreign.fetch_add(1);
        hits[i * inner + j].fetch_add(1);
      }, threads);
    }, threads);
    int wrong = 0;
    for (const auto& hit : hits) wrong += hit.load() == 1 ? 0 : 1;
    CHECK(wrong == 0);
    if (threads > 1) CHECK(foreign.load() == 0);
    // An inner item's exception reaches the outermost caller.
    CHECK_THROWS_AS(c3po::ParallelFor(0, outer, [&](int i) {
      c3po::ParallelFor(0, inner, [&](int j) {
        if (i == 3 && j == 7) throw std::runtime_error("inner");
      }, threads);
    }, threads), std::runtime_error);
  }
}

TEST_CASE("ParallelFor propagates the first exception, each index runs at most once") {
  for (int threads : {1, 2, 4}) {
    CAPTURE(threads);
    std::vector<std::atomic<int>> hits(100000);
    try {
      c3po::ParallelFor(0, 100000, [&](int i) {
        hits[i].fetch_add(1);
        if (i == 37) throw std::runtime_error("item 37 failed");
      }, threads);
      FAIL_CHECK("no exception");
    } catch (const std::runtime_error& e) {
      CHECK(std::string(e.what()) == "item 37 failed");
    }
    int twice = 0, ran = 0;
    for (auto& h : hits) {
      twice += h.load() > 1 ? 1 : 0;
      ran += h.load();
    }
    CHECK(twice == 0);
    CHECK(hits[37].load() == 1);
    // One thread claims in order and stops at the failing item: exactly 0..37 ran.
    if (threads == 1) CHECK(ran == 38);
  }
  CHECK_THROWS_AS(c3po::ParallelFor(0, 10, [](int) { throw std::logic_error("x"); }, 2), std::logic_error);
}

TEST_CASE("IndexQueue hands out every index once across threads") {
  c3po::IndexQueue queue(-5, 20000);
  std::vector<std::atomic<int>> hits(20005);
  std::vector<std::thread> pool;
  for (int t = 0; t < 4; ++t) {
    pool.emplace_back([&] {
      int i = 0;
      while (queue.Claim(&i)) hits[i + 5].fetch_add(1);
    });
  }
  for (auto& thread : pool) thread.join();
  int wrong = 0;
  for (auto& h : hits) wrong += h.load() == 1 ? 0 : 1;
  CHECK(wrong == 0);
  int i = 0;
  CHECK_FALSE(queue.Claim(&i));
  CHECK(queue.Stop() == 20005);
}

TEST_CASE("IndexQueue: no index is claimed after Stop() returns, on any thread") {
  // Deterministic: the claimers start only after Stop() has returned (a
  // promise released by the stopping thread), so every one of their claims
  // is ordered after the stop; none may succeed however threads interleave.
  for (int round = 0; round < 50; ++round) {
    c3po::IndexQueue queue(0, 1000);
    int first = -1;
    REQUIRE(queue.Claim(&first));
    CHECK(first == 0);
    std::promise<void> stopped;
    std::shared_future<void> after_stop = stopped.get_future().share();
    std::atomic<int> claimed_after_stop{0};
    std::vector<std::thread> pool;
    for (int t = 0; t < 3; ++t) {
      pool.emplace_back([&] {
        after_stop.wait();
        int i = 0;
        for (int k = 0; k < 100; ++k) claimed_after_stop.fetch_add(queue.Claim(&i) ? 1 : 0);
      });
    }
    const int claimed_before = queue.Stop();
    stopped.set_value();
    for (auto& thread : pool) thread.join();
    CHECK(claimed_before == 1);
    CHECK(queue.stopped());
    CHECK(claimed_after_stop.load() == 0);
  }
}

TEST_CASE("IndexQueue: Stop() counts the claims that preceded it") {
  c3po::IndexQueue queue(10, 20);
  int i = 0;
  for (int k = 0; k < 4; ++k) REQUIRE(queue.Claim(&i));
  CHECK(i == 13);
  CHECK(queue.Stop() == 4);
  CHECK_FALSE(queue.Claim(&i));
  c3po::IndexQueue empty(5, 3);
  CHECK_FALSE(empty.Claim(&i));
  CHECK(empty.Stop() == 0);
}

TEST_CASE("per-item streams make parallel results independent of threading") {
  auto run = [](int threads) {
    std::vector<double> values(3000);
    c3po::ParallelFor(0, 3000, [&](int i) {
      c3po::Rng rng = c3po::Rng::ForItem(99, static_cast<std::uint64_t>(i));
      values[i] = rng.Uniform() + rng.Normal();
    }, threads);
    return values;
  };
  const auto serial = run(1);
  CHECK(run(2) == serial);
  CHECK(run(5) == serial);
}

TEST_CASE("DefaultThreadCount honours C3PO_THREADS") {
  const char* old = std::getenv("C3PO_THREADS");
  const std::string saved = old ? old : "";
  setenv("C3PO_THREADS", "3", 1);
  CHECK(c3po::DefaultThreadCount() == 3);
  setenv("C3PO_THREADS", "garbage", 1);
  CHECK(c3po::DefaultThreadCount() >= 1);
  setenv("C3PO_THREADS", "-2", 1);
  CHECK(c3po::DefaultThreadCount() >= 1);
  unsetenv("C3PO_THREADS");
  CHECK(c3po::DefaultThreadCount() >= 1);
  if (old) setenv("C3PO_THREADS", saved.c_str(), 1);
}
