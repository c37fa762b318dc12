// The corrector benchmark: rows per (sigma, method), and the per-cloud cases it
// records are a faithful record (rerunning the corrector on a case's input
// reproduces its result), as libc3po/eval/bench/pytorch_corrector_gd.py relies on.
#include <doctest/doctest.h>

#include "c3po/eval/corrector_benchmark.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/method/certificate.hpp"
#include "c3po/synth/synth.hpp"
#include "test_helpers.hpp"
#include "test_objects.hpp"

using namespace c3po;

TEST_CASE("corrector benchmark: rows, times split, and reproducible cases") {
  const ObjectModel object = test::AsymmetricObject();
  const test::TempDir dir("corrector_benchmark");
  SynthOptions synth;
  synth.kind = CloudKind::kDepth;
  synth.count = 4;
  synth.points = 300;
  synth.seed = 3;
  WriteSynthDataset(object.mesh(), object.spec(), synth, dir / "depth");
  const Dataset dataset = ReadDataset(dir / "depth");

  CorrectorBenchmarkOptions options;
  options.sigmas = {0.1, 0.4};
  options.solvers = {CorrectorSolver::kFast, CorrectorSolver::kGradientDescent};
  options.certificate = CertificateOptions::FromObject(object.spec());
  std::vector<CorrectorBenchmarkCase> cases;
  const auto rows = RunCorrectorBenchmark(object, dataset, options, {}, &cases);

  REQUIRE(rows.size() == 6);  // 2 sigmas x (registration, fast, gd)
  REQUIRE(cases.size() == 6 * 4);
  CHECK(rows[0].method == "registration");
  CHECK(rows[1].method == "corrector (fast)");
  CHECK(rows[2].method == "corrector (gd)");
  for (const auto& row : rows) {
    CAPTURE(row.method);
    CHECK(row.clouds == 4);
    CHECK(row.median_corrector_ms >= 0.0);
    CHECK(row.median_certify_ms > 0.0);
    CHECK(row.median_ms >= row.median_certify_ms);
  }
  // The corrector recovers what registration alone cannot at sigma 0.4.
  CHECK(rows[4].median_rotation_deg < rows[3].median_rotation_deg);

  for (const auto& one : cases) {
    CAPTURE(one.method);
    CAPTURE(one.cloud);
    // Every method of a sigma saw the same perturbed keypoints.
    const auto& first_of_sigma = cases[(one.sigma == 0.1 ? 0 : 12) + one.cloud];
    CHECK(one.detected_keypoints.isApprox(first_of_sigma.detected_keypoints));
    if (one.method == "registration") continue;
    CorrectorOptions corrector = options.corrector;
    corrector.solver = one.method == "corrector (gd)" ? CorrectorSolver::kGradientDescent : CorrectorSolver::kFast;
    const CorrectorResult again =
        CorrectKeypoints(object, dataset.LoadCloud(one.cloud), one.detected_keypoints, corrector);
    CHECK(again.iterations == one.iterations);
    CHECK(again.cost_after == doctest::Approx(one.cost_after).epsilon(1e-12));
    CHECK(again.cost_before == doctest::Approx(one.cost_before).epsilon(1e-12));
  }
}

TEST_CASE("corrector benchmark: clouds of another object are refused, naming the manifest line") {
  const ObjectModel object = test::AsymmetricObject();
  const test::TempDir dir("corrector_benchmark_other");
  SynthOptions synth;
  synth.kind = CloudKind::kDepth;
  synth.count = 2;
  synth.points = 200;
  synth.seed = 3;
  WriteSynthDataset(object.mesh(), object.spec(), synth, dir / "depth");
  Dataset dataset = ReadDataset(dir / "depth");
  CorrectorBenchmarkOptions options;
  options.sigmas = {0.1};
  options.certificate = CertificateOptions::FromObject(object.spec());
  const std::string line = dir / "depth/manifest.jsonl: line 2 (" + dataset.entries[1].cloud + ")";

  // Another object's label on the second cloud.
  dataset.entries[1].object = "drill";
  const std::string other = test::InputErrorOf([&] { RunCorrectorBenchmark(object, dataset, options, {}); });
  CHECK(other == line + ": a cloud of object 'drill', not '" + object.name() + "'");

  // Unlabelled, but with one keypoint fewer than the object (before, the registration threw a bare
  // "RegisterPoints: model and scene sizes differ").
  dataset.entries[1].object.reset();
  const PointSet all = *dataset.entries[1].keypoints;
  dataset.entries[1].keypoints = PointSet(all.leftCols(all.cols() - 1));
  const std::string fewer = test::InputErrorOf([&] { RunCorrectorBenchmark(object, dataset, options, {}); });
  CHECK(fewer == line + ": " + std::to_string(all.cols() - 1) + " keypoints, the object '" + object.name() +
                     "' has " + std::to_string(all.cols()));

  // The same dataset, as written, runs.
  const Dataset intact = ReadDataset(dir / "depth");
  CHECK(RunCorrectorBenchmark(object, intact, options, {}).size() == 1 + options.solvers.size());   // + registration
}
