// The training-free fpfh detector (FPFH + TEASER-style registration), end to
// end on synthetic clouds with a known pose (the ground truth is the oracle).
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/eval/metrics.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/method/icp.hpp"
#include "c3po/plugins/fpfh_detector.hpp"
#include "test_helpers.hpp"

using namespace c3po;

TEST_CASE("fpfh detector recovers the pose of a full sample of the drill in the camera frame") {
  const ObjectModel object = LoadObject(test::SourceDir() + "/annotations/drill.json");
  const FpfhDetector detector(object);
  CHECK(detector.name() == "fpfh");
  const double d = object.diameter();
  int within = 0;
  const int count = 4;
  for (int i = 0; i < count; ++i) {
    Rng rng = Rng::ForItem(3, i);
    const Pose truth{rng.Rotation(), Eigen::Vector3d(0, 0, 0.7)};
    // A dense surface sample (every side); normals oriented to the camera
    // are then wrong on the far side, so only the near side matches well.
    const PointSet cloud = truth * SampleSurface(object.mesh(), 4000, 10 + i);
    const FpfhEstimate estimate = detector.Estimate(cloud);
    if (estimate.registration.ok() && AddS(object.tree(), truth, estimate.scene_from_model) < 0.05 * d) ++within;
  }
  MESSAGE(within << " of " << count << " full samples with ADD-S below 5 % d");
  CHECK(within >= count / 2);
}

TEST_CASE("fpfh detector on rendered depth clouds of the drill (1 mm noise)") {
  const ObjectModel object = LoadObject(test::SourceDir() + "/annotations/drill.json");
  const FpfhDetector detector(object);
  const double d = object.diameter();
  DepthRenderer renderer{CameraIntrinsics()};
  DepthSampleOptions sampling;
  sampling.points = 2000;
  sampling.noise_sigma = 0.001;
  int within = 0, within_icp = 0, failed = 0;
  const int count = 10;
  for (int i = 0; i < count; ++i) {
    Rng rng = Rng::ForItem(5, i);
    const Pose truth{rng.Rotation(), Eigen::Vector3d(rng.Uniform(-0.05, 0.05), rng.Uniform(-0.05, 0.05),
                                                     rng.Uniform(0.5, 0.8))};
    renderer.Render(object.mesh(), truth);
    const PointSet cloud = renderer.SampleCloud(sampling, rng);
    REQUIRE(cloud.cols() > 100);
    const FpfhEstimate estimate = detector.Estimate(cloud);
    if (!estimate.registration.ok()) {
      ++failed;
      continue;
    }
    CHECK(estimate.registration.clique_size >= 3);
    if (AddS(object.tree(), truth, estimate.scene_from_model) < 0.05 * d) ++within;
    IcpOptions icp;
    icp.max_correspondence_distance = 0.05 * d;
    if (AddS(object.tree(), truth, RefineIcp(object, cloud, estimate.scene_from_model, icp).scene_from_model) < 0.05 * d) {
      ++within_icp;
    }
  }
  MESSAGE(within << " (" << within_icp << " after ICP) of " << count
                 << " drill depth clouds with ADD-S below 5 % d, " << failed << " failed");
  // FPFH + TEASER is a weak baseline (the paper: <= 48 % ADD-S on YCB); the
  // bounds are below the rates measured on 30 such clouds (50 %, 77 % with ICP).
  CHECK(within >= 3);
  CHECK(within_icp >= 6);
}

TEST_CASE("fpfh detector on degenerate clouds") {
  const ObjectModel object = LoadObject(test::SourceDir() + "/annotations/drill.json");
  const FpfhDetector detector(object);
  CHECK_THROWS_AS(detector.Detect(PointSet(3, 0)), InputError);
  PointSet nan_cloud = PointSet::Constant(3, 10, std::numeric_limits<double>::quiet_NaN());
  CHECK_THROWS_AS(detector.Detect(nan_cloud), InputError);
  PointSet one_point = PointSet::Zero(3, 5);   // one voxel
  CHECK_THROWS_AS(detector.Detect(one_point), InputError);
  CHECK_FALSE(detector.Estimate(one_point).registration.ok());
  FpfhDetectorOptions bad;
  bad.voxel_fraction = 0;
  CHECK_THROWS_AS(bad.Check(), std::invalid_argument);
}
