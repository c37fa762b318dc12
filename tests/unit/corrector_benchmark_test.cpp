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
