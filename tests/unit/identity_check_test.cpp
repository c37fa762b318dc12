// Identity among known objects (identity_check.hpp; docs/method.md "Identity
// among known objects"). Oracle: construction. A box's corner view is
// explained within eps_oc by a twin box a few millimetres smaller or larger
// per side (its certifier certifies the cloud), and not at all by a thin bar
// (its oc fails); the detectors are oracles that return each object's
// keypoints at the cloud's true pose, so the test judges the check, not the
// detection.
#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "c3po/geometry/mesh.hpp"
#include "c3po/method/certify_batch.hpp"
#include "c3po/method/identity_check.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/method/refusal.hpp"
#include "test_objects.hpp"

using namespace c3po;

namespace {

ObjectModel Box(const std::string& name, const Eigen::Vector3d& size) { return test::BoxObject(size, name); }

// Returns the object's keypoints at a fixed pose, whatever the cloud.
class PosedKeypoints : public Detector {
 public:
  PosedKeypoints(const ObjectModel& object, const Pose& pose) : keypoints_(pose * object.keypoints()) {}
  std::string name() const override { return "posed_keypoints"; }
  int num_keypoints() const override { return static_cast<int>(keypoints_.cols()); }
  PointSet Detect(const PointSet&) const override { return keypoints_; }

 private:
  PointSet keypoints_;
};

Pose Truth() {
  Pose pose;
  pose.R = Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, -2, 1).normalized()).toRotationMatrix();
  pose.t = {0.03, -0.02, 0.9};
  return pose;
}

// The three faces of a box of `size` seen from (+1, +1, +1): a view that
// constrains every motion.
PointSet CornerView(const Eigen::Vector3d& size) {
  const PointSet surface = SampleSurface(test::BoxMesh({0, 0, 0}, size), 6000, 3);
  PointSet kept(3, surface.cols());
  Eigen::Index n = 0;
  for (Eigen::Index j = 0; j < surface.cols(); ++j) {
    const Eigen::Vector3d p = surface.col(j);
    bool seen = false;
    for (int axis = 0; axis < 3; ++axis) seen = seen || std::abs(p(axis) - 0.5 * size(axis)) < 1e-9;
    if (seen) kept.col(n++) = p;
  }
  return kept.leftCols(n);
}

KnownObject Known(const std::string& name, const ObjectModel& object, const Detector& detector) {
  KnownObject known;
  known.name = name;
  known.object = &object;
  known.detector = &detector;
  known.pipeline.certificate = CertificateOptions::FromObject(object.spec());
  return known;
}

const Eigen::Vector3d kBoxSize(0.16, 0.08, 0.22);
const Eigen::Vector3d kTwinSize(0.164, 0.072, 0.213);   // at most 8 mm apart per side, eps_oc 10 mm

}  // namespace

TEST_CASE("identity: a twin box's certifier certifies the cloud too, a bar's does not") {
  const ObjectModel box = Box("box", kBoxSize), twin = Box("twin", kTwinSize),
                    bar = Box("bar", {0.30, 0.03, 0.03});
  const Pose truth = Truth();
  const PointSet cloud = truth * CornerView(kBoxSize);
  PipelineOptions options;
  options.certificate = CertificateOptions::FromObject(box.spec());
  const PoseEstimate own = EstimateAndCertify(box, cloud, truth * box.keypoints(), options);
  REQUIRE(own.certified());   // the cloud's own object certifies it
  CHECK_FALSE(own.certificate.identity.checked);

  const PosedKeypoints twin_detector(twin, truth), bar_detector(bar, truth);
  const KnownObject twin_known = Known("twin.json", twin, twin_detector);
  const KnownObject bar_known = Known("bar.json", bar, bar_detector);
  const DepthView no_frame;

  const IdentityCheck with_bar = CheckIdentity({bar_known}, cloud, no_frame);
  CHECK(with_bar.checked);
  CHECK(with_bar.passed);
  CHECK(with_bar.objects_tried == 1);
  CHECK(with_bar.rival.empty());

  const IdentityCheck with_twin = CheckIdentity({bar_known, twin_known}, cloud, no_frame);
  CHECK(with_twin.checked);
  CHECK_FALSE(with_twin.passed);
  CHECK(with_twin.objects_tried == 2);
  CHECK(with_twin.rival == "twin.json");
  CHECK(with_twin.rival_oc_distance < twin.spec().eps_oc);
  // The twin's certified pose lies where the box is: its centre within the sizes' difference.
  CHECK((with_twin.rival_scene_from_model.t - truth.t).norm() < 0.01);

  // The twin's own certificate on the cloud, computed directly, is what the check reports.
  const PoseEstimate twin_on_cloud = EstimateAndCertify(twin, cloud, truth * twin.keypoints(), twin_known.pipeline);
  CHECK(twin_on_cloud.certified());
  CHECK(twin_on_cloud.certificate.oc.budget_distance == doctest::Approx(with_twin.rival_oc_distance));
}

TEST_CASE("identity: the batch refuses a pose another known object's certifier certifies too") {
  const ObjectModel box = Box("box", kBoxSize), twin = Box("twin", kTwinSize),
                    bar = Box("bar", {0.30, 0.03, 0.03});
  const Pose truth = Truth();
  const std::vector<PointSet> clouds = {truth * CornerView(kBoxSize)};
  const std::vector<PointSet> keypoints = {truth * box.keypoints()};
  const PosedKeypoints twin_detector(twin, truth), bar_detector(bar, truth);
  CertifyBatchOptions options;
  options.pipeline.certificate = CertificateOptions::FromObject(box.spec());

  const CertifyBatchResult alone = CertifyBatch(box, InMemorySources(clouds, keypoints), nullptr, options);
  REQUIRE(alone.outcomes[0].certified());

  options.other_objects = {Known("bar.json", bar, bar_detector)};
  const CertifyBatchResult with_bar = CertifyBatch(box, InMemorySources(clouds, keypoints), nullptr, options);
  CHECK(with_bar.outcomes[0].certified());
  CHECK(with_bar.outcomes[0].estimate.certificate.identity.checked);
  CHECK(with_bar.certified == 1);

  options.other_objects.push_back(Known("twin.json", twin, twin_detector));
  const CertifyBatchResult with_twin = CertifyBatch(box, InMemorySources(clouds, keypoints), nullptr, options);
  const PoseEstimate& refused = with_twin.outcomes[0].estimate;
  CHECK_FALSE(refused.certified());
  CHECK(with_twin.certified == 0);
  CHECK(RefusedBy(refused.certificate) == std::vector<CertificatePart>{CertificatePart::kIdentity});
  CHECK(RefusedByNames(refused) == std::vector<std::string>{"identity"});
  // The pose itself is unchanged: identity refuses, it does not re-estimate.
  CHECK((refused.scene_from_model.t - alone.outcomes[0].estimate.scene_from_model.t).norm() == 0.0);
  const std::string line = CertifyJsonLine("#0", refused);
  CHECK(line.find("\"identity\":false,\"identity_objects\":2,\"identity_rival\":\"twin.json\"") != std::string::npos);
}

TEST_CASE("identity: not with --eps-oc auto, and every known object needs its object and detector") {
  const ObjectModel box = Box("box", kBoxSize), twin = Box("twin", kTwinSize);
  const PosedKeypoints twin_detector(twin, Truth());
  CertifyBatchOptions options;
  options.pipeline.certificate = CertificateOptions::FromObject(box.spec());
  options.other_objects = {Known("twin.json", twin, twin_detector)};
  CHECK_NOTHROW(options.Check());
  options.auto_eps_oc = true;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
  options.auto_eps_oc = false;
  options.other_objects[0].detector = nullptr;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
}
