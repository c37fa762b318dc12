// Global uniqueness (rival search) and free space (issue 16; docs/method.md
// "Global uniqueness" and "Free space"). Oracles: planted two-fold
// ambiguities whose rival is known by construction, and rendered depth frames
// where the true pose is consistent with the observed free space by
// construction and a shifted pose is not.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <utility>

#include "c3po/base/random.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/geometry/scene_render.hpp"
#include "c3po/io/segment.hpp"
#include "c3po/io/support_plane.hpp"
#include "c3po/method/free_space.hpp"
#include "c3po/method/global_uniqueness.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/method/refusal.hpp"
#include "c3po/object/object_io.hpp"
#include "brute_force.hpp"
#include "test_helpers.hpp"
#include "test_objects.hpp"

using namespace c3po;

namespace {

// A 0.20 x 0.10 x 0.06 box with a 0.04-cube bump on one end of the top face:
// two-fold symmetric (half-turn about z) except for the bump.
Mesh BumpedBoxMesh() { return test::MergeMeshes({test::BoxMesh({0, 0, 0}, {0.20, 0.10, 0.06}),
                                                 test::BoxMesh({0.07, 0.0, 0.05}, {0.04, 0.04, 0.04})}); }

ObjectModel BumpedBox() {
  ObjectSpec spec;
  spec.name = "bumped_box";
  spec.keypoints.resize(3, 9);
  spec.keypoints << -0.10, 0.10, 0.10, -0.10, -0.10, 0.10, 0.10, -0.10, 0.07,  //
      -0.05, -0.05, 0.05, 0.05, -0.05, -0.05, 0.05, 0.05, 0.0,                 //
      -0.03, -0.03, -0.03, -0.03, 0.03, 0.03, 0.03, 0.03, 0.07;
  spec.eps_oc = 0.01;   // above the sample spacing of B̂ (~2 mm) with margin
  spec.delta_nd = 0.008;
  ObjectModelOptions options;
  options.sample_size = 20000;
  return ObjectModel(spec, BumpedBoxMesh(), options);
}

Pose TestPose() {
  Pose pose;
  pose.R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  pose.t = {0.02, -0.01, 0.8};
  return pose;
}

PipelineOptions Options(const ObjectModel& object) {
  PipelineOptions options;
  options.certificate = CertificateOptions::FromObject(object.spec());
  return options;
}

// A plain box of the given size centred at the origin (keypoints: its corners).
ObjectModel PlainBox(const Eigen::Vector3d& size) { return test::BoxObject(size); }

// Points on the box part only (the bump's footprint on the top face removed):
// every one of them also lies on the model turned by pi about z.
PointSet BoxOnlyCloud(int count, std::uint64_t seed) {
  const PointSet box = SampleSurface(test::BoxMesh({0, 0, 0}, {0.20, 0.10, 0.06}), count, seed);
  PointSet kept(3, box.cols());
  Eigen::Index n = 0;
  for (Eigen::Index j = 0; j < box.cols(); ++j) {
    const Eigen::Vector3d p = box.col(j);
    const bool under_bump = p.z() > 0.029 && std::abs(p.x() - 0.07) < 0.021 && std::abs(p.y()) < 0.021;
    const bool under_mirror = p.z() > 0.029 && std::abs(p.x() + 0.07) < 0.021 && std::abs(p.y()) < 0.021;
    if (!under_bump && !under_mirror) kept.col(n++) = p;
  }
  return kept.leftCols(n);
}

}  // namespace

TEST_CASE("tolerance: rho = tolerance - eps_oc, default max(10 % of d, 3 eps_oc), an explicit rival distance wins") {
  c3po::GlobalUniquenessOptions options;
  // Default, 10 % of d dominating (eps_oc = 3 % of d): rho = 7 % of d, above 2 eps_oc.
  CHECK(options.Tolerance(0.003, 0.1) == doctest::Approx(0.01));
  CHECK(options.RivalDistance(0.003, 0.1) == doctest::Approx(0.007));
  // Default, 3 eps_oc dominating (eps_oc = 5 % of d): rho = 2 eps_oc, the truth's own valley never counts.
  CHECK(options.Tolerance(0.005, 0.1) == doctest::Approx(0.015));
  CHECK(options.RivalDistance(0.005, 0.1) == doctest::Approx(0.01));
  options.tolerance = 0.02;   // the user's: 2 cm whatever the diameter
  CHECK(options.Tolerance(0.005, 1.0) == doctest::Approx(0.02));
  CHECK(options.RivalDistance(0.005, 1.0) == doctest::Approx(0.015));
  options.tolerance = 0.004;  // below eps_oc (the CLI refuses it): rho 0, not negative
  CHECK(options.RivalDistance(0.005, 1.0) == 0.0);
  options.rival_distance = 0.03;
  CHECK(options.RivalDistance(0.005, 1.0) == doctest::Approx(0.03));
  options.tolerance = -1.0;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);
}

TEST_CASE("global uniqueness: hypotheses and axis rotations") {
  GlobalUniquenessOptions options;
  // 3 x 3 turns about the principal axes, then the 10 diagonals' half-turns,
  // then the estimate itself (no turn).
  const std::vector<std::pair<int, double>> hypotheses = RivalHypotheses(options);
  REQUIRE(hypotheses.size() == 20);
  CHECK(hypotheses[0] == std::make_pair(0, M_PI / 2));
  CHECK(hypotheses[8] == std::make_pair(2, 3 * M_PI / 2));
  for (int k = 9; k < 19; ++k) CHECK(hypotheses[k] == std::make_pair(k - 6, M_PI));
  CHECK(hypotheses[19] == std::make_pair(0, 0.0));
  options.steps = 6;
  CHECK(RivalHypotheses(options).size() == 15 + 10 + 1);
  options.steps = 3;
  CHECK_THROWS(options.Check());
  const ObjectModel object = BumpedBox();
  const PrincipalFrame frame = ModelPrincipalFrame(object);
  const Eigen::Matrix<double, 3, 13> axes = ReestimateAxes(frame);
  for (int axis = 3; axis < 13; ++axis) {
    // A diagonal's half-turn: R = 2uu^T - I about the ReestimateAxes column
    // (fixes u and the centroid, reverses what is orthogonal to u).
    const Pose flip = HalfTurn(frame, axis);
    const Eigen::Vector3d u = axes.col(axis);
    CHECK((flip.R * u - u).norm() < 1e-12);
    CHECK((flip.R * flip.R - Eigen::Matrix3d::Identity()).norm() < 1e-12);
    CHECK(flip.R.trace() == doctest::Approx(-1.0));
    CHECK((flip * frame.centroid - frame.centroid).norm() < 1e-12);
    CHECK((AxisRotation(frame, axis, M_PI).R - flip.R).norm() < 1e-12);
  }
  CHECK_THROWS(HalfTurn(frame, 13));
  for (int axis = 0; axis < 3; ++axis) {
    // AxisRotation(pi) is the exact half-turn; rotations fix the centroid.
    const Pose a = AxisRotation(frame, axis, M_PI), b = HalfTurn(frame, axis);
    CHECK((a.R - b.R).norm() < 1e-12);
    CHECK((a * frame.centroid - frame.centroid).norm() < 1e-12);
    const Pose quarter = AxisRotation(frame, axis, M_PI / 2);
    CHECK(((quarter * quarter).R - b.R).norm() < 1e-12);
  }
}

TEST_CASE("global uniqueness: a planted two-fold rival is refused, the discriminating part is certified") {
  const ObjectModel object = BumpedBox();
  const Pose truth = TestPose();
  const PipelineOptions options = Options(object);

  // Only the symmetric box: the bump may be at either end.
  const PointSet ambiguous = truth * BoxOnlyCloud(3000, 3);
  const PoseEstimate at_truth = EstimateAndCertify(object, ambiguous, truth * object.keypoints(), options);
  REQUIRE(at_truth.ok());
  CHECK(at_truth.certificate.oc.passed);
  CHECK(at_truth.certificate.nd.local.passed);    // locally well constrained: the local test cannot see it
  REQUIRE(at_truth.certificate.nd.global_checked);
  CHECK_FALSE(at_truth.certificate.nd.global.passed);
  CHECK_FALSE(at_truth.certified());
  CHECK(at_truth.certificate.nd.global.rivals_found >= 1);
  CHECK(at_truth.certificate.nd.global.rival_counts);
  CHECK(at_truth.certificate.nd.global.rival_passes_oc);
  // The rival is the half-turn: the bump (0.04 above the top face) moved to
  // the other end, so its top is ~0.04 from the rival's surface.
  CHECK(at_truth.certificate.nd.global.rival_hausdorff > 0.035);
  CHECK(at_truth.certificate.nd.global.rival_hausdorff < 0.06);
  CHECK(at_truth.certificate.nd.global.rival_outliers == 0);
  // The refusal names the rival search, with the rival's distance and axis (refusal.hpp).
  CHECK(RefusedBy(at_truth.certificate) == std::vector<CertificatePart>{CertificatePart::kNdGlobal});
  CHECK(RefusalSummary(at_truth.certificate).rfind("nd_global: a pose 0.0", 0) == 0);
  CHECK(RefusalSummary(at_truth.certificate).find("leaves 0 points at >= eps_oc") != std::string::npos);

  // Switched off, the same estimate is certified (what the test adds).
  PipelineOptions off = options;
  off.certificate.global.enabled = false;
  const PoseEstimate unchecked = EstimateAndCertify(object, ambiguous, truth * object.keypoints(), off);
  CHECK(unchecked.certified());
  CHECK_FALSE(unchecked.certificate.nd.global_checked);

  // With the bump's points the rival leaves them in the air: certified.
  const PointSet bump = truth * SampleSurface(test::BoxMesh({0.07, 0.0, 0.05}, {0.04, 0.04, 0.04}), 400, 4);
  PointSet discriminating(3, ambiguous.cols() + bump.cols());
  discriminating << ambiguous, bump;
  const PointSet& cloud = discriminating;
  const PoseEstimate good = EstimateAndCertify(object, cloud, truth * object.keypoints(), options);
  REQUIRE(good.ok());
  CHECK(good.certificate.nd.global_checked);
  CHECK(good.certificate.nd.global.passed);
  CHECK(good.certified());
  CHECK(good.certificate.nd.global.rivals_tried == 20);
}

TEST_CASE("global uniqueness: a symmetric object's turns are not rivals") {
  // A plain box: every half-turn about a principal axis maps it onto itself,
  // so the refined rivals coincide with the estimate as shapes (Hausdorff ~ 0).
  const ObjectModel box = PlainBox({0.20, 0.10, 0.06});
  const Pose truth = TestPose();
  const PointSet cloud = truth * SampleSurface(box.mesh(), 3000, 5);
  const PoseEstimate e = EstimateAndCertify(box, cloud, truth * box.keypoints(), Options(box));
  REQUIRE(e.ok());
  CHECK(e.certificate.nd.global_checked);
  CHECK(e.certificate.nd.global.passed);
  CHECK(e.certified());
}

TEST_CASE("global uniqueness: a given pose the data put elsewhere has its rival at its own refit") {
  // A 0.30 m bar seen only at one end (x < -0.05). The given pose turns the
  // truth by 0.12 rad about z through (-0.10, 0, 0), inside the seen part:
  // every seen point moves < 8 mm (< eps_oc = 10 mm: oc passes with no
  // outlier) while the far end moves ~30 mm. The local test cannot object
  // (the seen end constrains every motion); the refit from the given pose
  // settles back at the truth, a second fit beyond 2 eps_oc.
  const ObjectModel bar = PlainBox({0.30, 0.08, 0.05});
  const Pose truth = TestPose();
  const PointSet all = SampleSurface(bar.mesh(), 6000, 3);
  std::vector<Eigen::Index> seen;
  for (Eigen::Index i = 0; i < all.cols(); ++i) {
    if (all(0, i) < -0.05) seen.push_back(i);
  }
  PointSet end(3, static_cast<Eigen::Index>(seen.size()));
  for (std::size_t k = 0; k < seen.size(); ++k) end.col(static_cast<Eigen::Index>(k)) = all.col(seen[k]);
  const PointSet cloud = truth * end;
  Pose turn;
  turn.R = Eigen::AngleAxisd(0.12, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d pivot(-0.10, 0.0, 0.0);
  turn.t = pivot - turn.R * pivot;
  const Pose given = truth * turn;
  const PointSet queries = StridedColumns(bar.sample(), 1000);
  const double wrong_by = PosedModelHausdorff(bar, queries, truth, given);
  REQUIRE(wrong_by > 2.0 * bar.spec().eps_oc);   // beyond the bound: must not be certified

  PipelineOptions options = Options(bar);
  options.correct = false;   // certify the pose as given (certify --poses --no-correct)
  PipelineOptions unsearched = options;
  unsearched.certificate.global.enabled = false;
  const PoseEstimate blind = EstimateAndCertify(bar, cloud, given * bar.keypoints(), unsearched);
  REQUIRE(blind.ok());
  CHECK(blind.certificate.oc.passed);            // the case is real: only the search can refuse it
  CHECK(blind.certificate.oc.outlier_count == 0);
  CHECK(blind.certificate.nd.local.passed);

  const PoseEstimate e = EstimateAndCertify(bar, cloud, given * bar.keypoints(), options);
  REQUIRE(e.ok());
  CHECK_FALSE(e.certified());
  CHECK(RefusedBy(e.certificate) == std::vector<CertificatePart>{CertificatePart::kNdGlobal});
  const GlobalUniqueness& g = e.certificate.nd.global;
  CHECK(g.rival_hausdorff > g.rival_distance);
  // The rival is the truth (up to the corrector's settling and the bar's
  // symmetries), not another wrong pose.
  CHECK(PosedModelHausdorff(bar, queries, truth, g.rival_scene_from_model) < bar.spec().eps_oc);
  // The own refit alone finds it (the bar's symmetric half-turns find it too;
  // a shape without them has only this start near the truth).
  const auto hypotheses = RivalHypotheses(options.certificate.global);
  CHECK(std::count(hypotheses.begin(), hypotheses.end(), std::make_pair(0, 0.0)) == 1);
  const std::vector<RivalFit> own = RefineRivals(bar, cloud, blind, options, ModelPrincipalFrame(bar), {{0, 0.0}});
  REQUIRE(own.size() == 1);
  CHECK(own[0].ok);
  CHECK(own[0].passes_oc);
  CHECK(own[0].hausdorff > g.rival_distance);
  CHECK(PosedModelHausdorff(bar, queries, truth, own[0].scene_from_model) < bar.spec().eps_oc);

  // At the truth the refit stays: certified, the own refit among the 20 tried.
  const PoseEstimate at_truth = EstimateAndCertify(bar, cloud, truth * bar.keypoints(), options);
  CHECK(at_truth.certified());
  CHECK(at_truth.certificate.nd.global.rivals_tried == 20);
}

namespace {

// oc passed, `part` alone refused the estimate, and the refusal's words
// begin with `summary`.
void CheckRefusedOnlyBy(const PoseEstimate& e, CertificatePart part, const std::string& summary) {
  REQUIRE(e.ok());
  CHECK(e.certificate.oc.passed);
  CHECK(RefusedBy(e.certificate) == std::vector<CertificatePart>{part});
  CHECK(RefusalSummary(e.certificate).rfind(summary, 0) == 0);
}

// The object's own surface at the truth through the pipeline with `test`:
// `part` alone refuses, and the summary begins with `summary(free space)`.
void CheckPipelineRefusedOnlyBy(const ObjectModel& object, const Pose& truth, const FreeSpaceTest& test,
                                CertificatePart part, const std::function<std::string(const FreeSpace&)>& summary) {
  const PointSet cloud = truth * SampleSurface(object.mesh(), 2000, 9);
  const PoseEstimate e = EstimateAndCertify(object, cloud, truth * object.keypoints(), Options(object), &test);
  CheckRefusedOnlyBy(e, part, summary(e.certificate.free_space));
}

// A depth frame of the bumped box in front of a wall (the background) at the
// true pose, rendered by the same renderer the test uses.
struct Frame {
  DepthView view;
  Pose truth;
};

Frame RenderFrame(const ObjectModel& object, const Pose& truth = TestPose()) {
  Frame frame;
  frame.truth = truth;
  CameraIntrinsics camera;
  DepthRenderer renderer(camera);
  renderer.Render(object.mesh(), frame.truth);
  auto depth = std::make_shared<DepthImage>();
  depth->width = camera.width;
  depth->height = camera.height;
  depth->z.assign(static_cast<std::size_t>(camera.width) * camera.height, 1.5f);   // a wall at 1.5 m
  for (const int pixel : renderer.covered_pixels()) {
    depth->z[static_cast<std::size_t>(pixel)] = static_cast<float>(renderer.BackProject(pixel).z());
  }
  frame.view.depth = depth;
  frame.view.camera = camera;
  return frame;
}

}  // namespace

TEST_CASE("free space: the true pose passes, a pose whose silhouette covers the background fails") {
  const ObjectModel object = BumpedBox();
  const Frame frame = RenderFrame(object);
  FreeSpaceOptions options;
  const FreeSpaceTest test(object, frame.view, options, object.spec().eps_oc);
  const FreeSpace at_truth = test.Check(frame.truth);
  CHECK(at_truth.checked);
  CHECK(at_truth.passed);
  CHECK(at_truth.silhouette > 1000);
  CHECK(at_truth.measured == at_truth.silhouette);
  CHECK(at_truth.violations == 0);

  // Shifted sideways by 10 cm: most of its silhouette lies over the wall.
  Pose shifted = frame.truth;
  shifted.t.x() += 0.10;
  const FreeSpace off = test.Check(shifted);
  CHECK_FALSE(off.passed);
  CHECK(off.violations > 0.3 * off.measured);

  // Turned by 90 deg about the camera axis: the long box now covers wall.
  Pose turned = frame.truth;
  turned.R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix() * frame.truth.R;
  turned.t = frame.truth.t;
  CHECK_FALSE(test.Check(turned).passed);

  // An occluder in front of the object (a bar at 0.5 m across the middle of
  // the image) hides part of it: consistent with free space at the truth.
  auto occluded = std::make_shared<DepthImage>(*frame.view.depth);
  for (int v = 200; v < 280; ++v) {
    for (int u = 0; u < occluded->width; ++u) occluded->z[static_cast<std::size_t>(v) * occluded->width + u] = 0.5f;
  }
  const FreeSpaceTest with_occluder(object, DepthView{occluded, frame.view.camera, std::nullopt, 0.0, nullptr, nullptr},
                                    options,
                                    object.spec().eps_oc);
  const FreeSpace behind_occluder = with_occluder.Check(frame.truth);
  CHECK(behind_occluder.passed);
  CHECK(behind_occluder.violations == 0);
  // Moved 5 cm towards the camera, the model would hide the surface the
  // camera saw behind it: a violation everywhere outside the occluder.
  Pose closer = frame.truth;
  closer.t.z() -= 0.05;
  CHECK_FALSE(test.Check(closer).passed);

  // Missing depth is unknown, not a violation.
  auto holes = std::make_shared<DepthImage>(*frame.view.depth);
  std::fill(holes->z.begin(), holes->z.end(), 0.0f);
  const FreeSpaceTest blind(object, DepthView{holes, frame.view.camera, std::nullopt, 0.0, nullptr, nullptr}, options,
                            object.spec().eps_oc);
  const FreeSpace unknown = blind.Check(shifted);
  CHECK(unknown.passed);
  CHECK(unknown.measured == 0);

  // Through the pipeline: the shifted pose's cloud-free certificate fails on
  // free space even though the given cloud (the object's points shifted) fits it.
  const PointSet cloud = shifted * SampleSurface(object.mesh(), 2000, 9);
  const PoseEstimate e = EstimateAndCertify(object, cloud, shifted * object.keypoints(), Options(object), &test);
  CHECK(e.certificate.free_space.checked);
  CHECK_FALSE(e.certificate.free_space.passed);
  CHECK_FALSE(e.certified());
  const FreeSpace& f = e.certificate.free_space;
  CheckRefusedOnlyBy(e, CertificatePart::kFreeSpace,
                     "free_space: " + std::to_string(f.violations) + " of " + std::to_string(f.measured) +
                         " measured pixels");
}

namespace {

// A 11 x 9 x 3.5 cm box (a pudding box) seen almost face-on at 0.6 m in
// front of a wall.
Pose PuddingBoxTruth() {
  Pose truth;
  truth.R = Eigen::AngleAxisd(0.15, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  truth.t = {0.01, -0.02, 0.6};
  return truth;
}

}  // namespace

TEST_CASE("free space: the whole silhouette shifts together (a pose within the tolerance passes, a turn that overhangs two sides fails)") {
  // The tolerance is 1 cm, so a pose 1 cm off moves the image by at most
  // f * 1 cm / z ~ 9 px.
  const ObjectModel box = PlainBox({0.11, 0.09, 0.035});
  const Pose truth = PuddingBoxTruth();
  const Frame frame = RenderFrame(box, truth);
  const FreeSpaceOptions options;
  const FreeSpaceTest test(box, frame.view, options, box.spec().eps_oc);
  const FreeSpace at_truth = test.Check(truth);
  REQUIRE(at_truth.checked);
  CHECK(at_truth.passed);
  CHECK(at_truth.violations == 0);
  CHECK(at_truth.shift_u == 0);
  CHECK(at_truth.shift_v == 0);
  const double focal = frame.view.camera.fx;
  double nearest = truth.t.z();
  for (Eigen::Index j = 0; j < box.mesh().vertices.cols(); ++j) nearest = std::min(nearest, (truth.R * box.mesh().vertices.col(j) + truth.t).z());
  CHECK(at_truth.reach == static_cast<int>(std::ceil(focal * at_truth.tolerance / nearest)));

  // Moved sideways by (6, -4) mm: the best shift brings the rendering back
  // by f * delta / z pixels (the face at ~0.6 m), up to the border of
  // counted pixels (any shift that keeps them over the box has no violation;
  // ties go to the smaller shift), and the pose passes.
  Pose moved = truth;
  moved.t += Eigen::Vector3d(0.006, -0.004, 0.0);
  const FreeSpace near = test.Check(moved);
  CHECK(near.passed);
  const double slack = options.border_pixels + 1.0;
  CHECK(std::abs(near.shift_u + focal * 0.006 / truth.t.z()) <= slack);
  CHECK(std::abs(near.shift_v - focal * 0.004 / truth.t.z()) <= slack);
  CHECK(near.shift_u < 0);
  CHECK(near.shift_v > 0);
  CHECK(near.violations <= 0.01 * near.measured);

  // Turned by 90 deg about the camera axis through the box: 9 x 11 cm over
  // an 11 x 9 cm face, 1 cm over the wall on two opposite sides. Each side
  // alone is within reach of some shift; no one shift explains both.
  Pose turned = truth;
  turned.R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix() * truth.R;
  const FreeSpace overhang = test.Check(turned);
  CHECK_FALSE(overhang.passed);
  CHECK(overhang.violations > options.max_fraction * overhang.measured);

  // Moved 3 cm sideways: beyond the reach of any shift.
  Pose far = truth;
  far.t.x() += 0.03;
  const FreeSpace beyond = test.Check(far);
  CHECK_FALSE(beyond.passed);
  CHECK(std::max(std::abs(beyond.shift_u), std::abs(beyond.shift_v)) <= beyond.reach);

  // Close up (0.25 m) the reach is ~23 px and the search coarse-to-fine
  // (grid step 6, then compass steps 3, 2, 1): a pose 8 mm off still finds
  // its shift, f * 8 mm / z ~ 17 px.
  Pose close = truth;
  close.t = {0.0, 0.0, 0.25};
  const Frame near_frame = RenderFrame(box, close);
  const FreeSpaceTest near_test(box, near_frame.view, options, box.spec().eps_oc);
  Pose close_moved = close;
  close_moved.t.y() += 0.008;
  const FreeSpace close_check = near_test.Check(close_moved);
  CHECK(close_check.reach > 20);
  CHECK(close_check.passed);
  CHECK(std::abs(close_check.shift_u) <= slack);
  CHECK(std::abs(close_check.shift_v + focal * 0.008 / close.t.z()) <= slack);
}

TEST_CASE("free space: two limits -- the estimate is judged at accept_fraction, a rival at max_fraction") {
  // The pudding box of the test above, turned by 90 deg: it overhangs the
  // observed face, so it sees through some fraction of its silhouette.
  const ObjectModel box = PlainBox({0.11, 0.09, 0.035});
  const Pose truth = PuddingBoxTruth();
  const Frame frame = RenderFrame(box, truth);
  Pose turned = truth;
  turned.R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix() * truth.R;
  // Oracle: with both limits 0 the shift search minimises the violations
  // themselves; no shift has fewer than v0 violations, and no shift measures
  // more than the whole silhouette.
  FreeSpaceOptions zero;
  zero.max_fraction = 0.0;
  zero.accept_fraction = 0.0;
  const FreeSpace fewest = FreeSpaceTest(box, frame.view, zero, box.spec().eps_oc).Check(turned);
  REQUIRE(fewest.violations > 0);
  REQUIRE(fewest.measured > 0);
  const double at_best = static_cast<double>(fewest.violations) / fewest.measured;
  FreeSpaceOptions options;
  options.max_fraction = std::min(0.9, at_best + 0.001);                              // some shift is within it
  options.accept_fraction = 0.5 * fewest.violations / static_cast<double>(fewest.silhouette);  // none is
  REQUIRE(options.accept_fraction < options.max_fraction);
  const FreeSpaceTest test(box, frame.view, options, box.spec().eps_oc);
  const FreeSpace as_estimate = test.Check(turned);
  CHECK_FALSE(as_estimate.passed);
  CHECK(as_estimate.limit == options.accept_fraction);
  int violations = -1;
  CHECK(test.Passes(turned, &violations));      // as a rival it is not refuted
  CHECK(violations <= options.max_fraction * fewest.silhouette);
  // The truth passes both; the limits' order is checked.
  CHECK(test.Check(truth).passed);
  CHECK(test.Passes(truth, nullptr));
  FreeSpaceOptions inverted;
  inverted.accept_fraction = inverted.max_fraction + 0.01;
  CHECK_THROWS_AS(inverted.Check(), std::invalid_argument);
}

namespace {

// The silhouette of `object` at `pose` as a mask, keeping the pixels with
// column < `split` (all: split = the image width).
Mask SilhouetteMask(const ObjectModel& object, const Pose& pose, int split) {
  CameraIntrinsics camera;
  DepthRenderer renderer(camera);
  renderer.Render(object.mesh(), pose);
  const std::size_t pixels = static_cast<std::size_t>(camera.width) * camera.height;
  Mask mask{camera.width, camera.height, std::vector<std::uint8_t>(pixels)};
  for (const int pixel : renderer.covered_pixels()) {
    mask.inside[static_cast<std::size_t>(pixel)] = pixel % camera.width < split;
  }
  return mask;
}

}  // namespace

TEST_CASE("the mask: a pose claiming surface the mask gives to something else is refused, and rivals are not judged by it") {
  const ObjectModel object = BumpedBox();
  Frame frame = RenderFrame(object);
  const Mask whole = SilhouetteMask(object, frame.truth, frame.view.depth->width);
  int left = frame.view.depth->width, right = 0;   // the silhouette's columns
  for (int v = 0; v < whole.height; ++v) {
    for (int u = 0; u < whole.width; ++u) {
      if (whole.at(u, v)) left = std::min(left, u), right = std::max(right, u);
    }
  }
  REQUIRE(right - left > 40);
  const int split = (left + right) / 2;
  FreeSpaceOptions options;
  const int border = options.border_pixels;
  const auto test_with = [&](const Mask& mask) {
    DepthView view = frame.view;
    view.mask = std::make_shared<const Mask>(mask);
    return FreeSpaceTest(object, view, options, object.spec().eps_oc);
  };

  // The segmenter gave the silhouette's right half to a neighbour: the true
  // pose claims that half's surface, which the camera sees at its depth.
  const FreeSpaceTest half = test_with(SilhouetteMask(object, frame.truth, split));
  const FreeSpace claimed = half.Check(frame.truth);
  CHECK(claimed.mask_checked);
  CHECK(claimed.silhouette_passed);
  CHECK(claimed.violations == 0);
  CHECK(claimed.seen_surface == claimed.measured);   // the frame is the render
  // Oracle: brute-force bounds on the pixels counted more than `border`
  // pixels from the mask (the best shift is 0 here): at most the
  // silhouette's pixels right of the split, at least those that far right of
  // it lying `border` deep inside the silhouette.
  REQUIRE(claimed.shift_u == 0);
  REQUIRE(claimed.shift_v == 0);
  const Mask deep = ErodeMask(whole, border);
  int upper = 0, lower = 0;
  for (int v = 0; v < whole.height; ++v) {
    for (int u = split; u < whole.width; ++u) {
      upper += whole.at(u, v);
      lower += u >= split + border && deep.at(u, v);
    }
  }
  REQUIRE(lower > 0);
  CHECK(claimed.seen_outside_mask >= lower);
  CHECK(claimed.seen_outside_mask <= upper);
  CHECK(claimed.seen_outside_mask > options.outside_mask_fraction * claimed.measured);
  CHECK_FALSE(claimed.mask_passed);
  CHECK_FALSE(claimed.passed);
  CHECK(half.Passes(frame.truth, nullptr));   // as a rival it stands

  // The whole silhouette, or a mask short of it by no more than the border: nothing claimed.
  CHECK(test_with(whole).Check(frame.truth).seen_outside_mask == 0);
  CHECK(test_with(whole).Check(frame.truth).passed);
  const FreeSpace short_mask = test_with(ErodeMask(whole, border)).Check(frame.truth);
  CHECK(short_mask.seen_outside_mask == 0);
  CHECK(short_mask.passed);
  // No mask, or the check off (fraction 1): not judged.
  CHECK_FALSE(FreeSpaceTest(object, frame.view, options, object.spec().eps_oc).Check(frame.truth).mask_checked);
  options.outside_mask_fraction = 1.0;
  CHECK(test_with(SilhouetteMask(object, frame.truth, split)).Check(frame.truth).passed);
  options.outside_mask_fraction = 1.5;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);

  // Through the pipeline: oc and nd pass, the mask refuses, the summary says why.
  CheckPipelineRefusedOnlyBy(object, frame.truth, half, CertificatePart::kMask, [](const FreeSpace& f) {
    return "mask: " + std::to_string(f.seen_outside_mask) + " of " + std::to_string(f.measured) + " measured pixels";
  });
}

namespace {

// Oracle for the uncovered count: the mask's pixels whose observed depth lies
// within the depth range of `object`'s render at `pose` (± tolerance), and
// of them those with no rendered pixel in the (2·border + 1)² window around
// them (brute force, no distance transform).
std::pair<int, int> UncoveredByBruteForce(const ObjectModel& object, const Pose& pose, const Mask& mask,
                                          const DepthImage& depth, int border, double tolerance) {
  CameraIntrinsics camera;
  DepthRenderer renderer(camera);
  renderer.Render(object.mesh(), pose);
  double nearest = 1e9, farthest = 0.0;
  for (const int pixel : renderer.covered_pixels()) {
    nearest = std::min(nearest, renderer.DepthAt(pixel % camera.width, pixel / camera.width));
    farthest = std::max(farthest, renderer.DepthAt(pixel % camera.width, pixel / camera.width));
  }
  int at_depth = 0, uncovered = 0;
  for (int v = 0; v < mask.height; ++v) {
    for (int u = 0; u < mask.width; ++u) {
      const float z = depth.at(u, v);
      if (!mask.at(u, v) || !DepthImage::Valid(z) || z < nearest - tolerance || z > farthest + tolerance) continue;
      ++at_depth;
      bool covered = false;
      for (int dv = -border; dv <= border; ++dv) {
        for (int du = -border; du <= border; ++du) {
          const int x = u + du, y = v + dv;
          covered = covered || (x >= 0 && y >= 0 && x < mask.width && y < mask.height && renderer.TriangleAt(x, y) >= 0);
        }
      }
      uncovered += !covered;
    }
  }
  return {at_depth, uncovered};
}

}  // namespace

TEST_CASE("the mask's uncovered pixels: a pose that explains only part of the segment is refused, and rivals are not judged by it") {
  const ObjectModel object = BumpedBox();
  // The segmented object: the bumped box with 3 cm of the same section glued to its +x end.
  ObjectModelOptions longer_options;
  longer_options.sample_size = 20000;
  const ObjectModel longer(object.spec(), test::MergeMeshes({BumpedBoxMesh(),
                                                             test::BoxMesh({0.115, 0.0, 0.0}, {0.03, 0.10, 0.06})}),
                           longer_options);
  Frame frame = RenderFrame(longer);
  FreeSpaceOptions options;
  const auto test_with = [&](const Frame& f, const Mask& mask) {
    DepthView view = f.view;
    view.mask = std::make_shared<const Mask>(mask);
    return FreeSpaceTest(object, view, options, object.spec().eps_oc);
  };
  const Mask segment = SilhouetteMask(longer, frame.truth, frame.view.depth->width);
  const FreeSpaceTest test = test_with(frame, segment);
  const FreeSpace part = test.Check(frame.truth);
  CHECK(part.mask_checked);
  CHECK(part.silhouette_passed);      // nothing seen through: the extension is in front of or at the model
  CHECK(part.mask_passed);            // and the model claims nothing outside the mask
  REQUIRE(part.shift_u == 0);
  REQUIRE(part.shift_v == 0);
  const auto [at_depth, uncovered] =
      UncoveredByBruteForce(object, frame.truth, segment, *frame.view.depth, options.border_pixels, part.tolerance);
  REQUIRE(uncovered > 0);
  CHECK(part.mask_at_depth == at_depth);
  CHECK(part.mask_uncovered == uncovered);
  CHECK(part.uncovered_limit == options.uncovered_mask_fraction);
  CHECK(part.mask_uncovered > options.uncovered_mask_fraction * part.mask_at_depth);
  CHECK_FALSE(part.uncovered_passed);
  CHECK_FALSE(part.passed);
  CHECK(test.Passes(frame.truth, nullptr));   // as a rival it stands

  // The object's own frame and mask: nothing uncovered.
  const Frame own = RenderFrame(object);
  const FreeSpace whole = test_with(own, SilhouetteMask(object, own.truth, own.view.depth->width)).Check(own.truth);
  CHECK(whole.mask_at_depth > 0);
  CHECK(whole.mask_uncovered == 0);
  CHECK(whole.passed);
  // Off (fraction 1); out of range.
  options.uncovered_mask_fraction = 1.0;
  CHECK(test_with(frame, segment).Check(frame.truth).passed);
  options.uncovered_mask_fraction = 1.5;
  CHECK_THROWS_AS(options.Check(), std::invalid_argument);

  // Through the pipeline: the cloud is the bumped box's (oc and nd pass), the uncovered pixels refuse.
  CheckPipelineRefusedOnlyBy(object, frame.truth, test, CertificatePart::kUncovered, [](const FreeSpace& f) {
    return "uncovered: " + std::to_string(f.mask_uncovered) + " of " + std::to_string(f.mask_at_depth) +
           " mask pixels";
  });
}

namespace {

// The object's points as the frame's camera sees them (DepthRenderer's
// partial cloud: 3000 pixels, 1 mm noise along the ray), optionally without
// the bump.
PointSet FrameCloud(const ObjectModel& object, const Pose& truth, bool keep_bump, Rng& rng) {
  CameraIntrinsics camera;
  DepthRenderer renderer(camera);
  renderer.Render(object.mesh(), truth);
  DepthSampleOptions sample;
  sample.points = 3000;
  sample.noise_sigma = 0.001;
  const PointSet seen = renderer.SampleCloud(sample, rng);
  if (keep_bump) return seen;
  const Pose model_from_scene = truth.Inverse();
  PointSet kept(3, seen.cols());
  Eigen::Index n = 0;
  for (Eigen::Index j = 0; j < seen.cols(); ++j) {
    if ((model_from_scene * Eigen::Vector3d(seen.col(j))).z() <= 0.031) kept.col(n++) = seen.col(j);   // above: the bump
  }
  return kept.leftCols(n);
}

}  // namespace

TEST_CASE("soundness with the frame: no certificate beyond the bound from any start, the bump's points or not") {
  // Random views of the bumped box in front of a wall. Candidates: the
  // pipeline from the true keypoints (perturbed) and from the half-turns about
  // the three principal axes (the two-fold near-symmetry), each with the
  // frame's free-space test (one shift for the whole silhouette). Without the
  // bump's points the cloud fits the half-turn, but the frame still shows the
  // bump: a certificate must never be issued beyond the bound.
  const ObjectModel object = BumpedBox();
  const PrincipalFrame principal = ModelPrincipalFrame(object);
  const double bound = object.spec().eps_oc + 0.001 * std::sqrt(3.0) + 2 * 2.0 * object.SampleSpacing();
  const PointSet queries = StridedColumns(object.sample(), 3000);
  int candidates = 0, certified = 0, turned_refused = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    Rng rng(seed);
    Pose truth;
    truth.R = rng.RotationUpTo(M_PI);
    truth.t = {rng.Uniform(-0.05, 0.05), rng.Uniform(-0.05, 0.05), rng.Uniform(0.6, 0.9)};
    const Frame frame = RenderFrame(object, truth);
    const FreeSpaceTest free_space(object, frame.view, FreeSpaceOptions{}, object.spec().eps_oc);
    for (const bool keep_bump : {true, false}) {
      CAPTURE(seed);
      CAPTURE(keep_bump);
      const PointSet cloud = FrameCloud(object, truth, keep_bump, rng);
      if (cloud.cols() < 200) continue;
      std::vector<PointSet> starts = {truth * object.keypoints()};
      starts[0] += 0.005 * PointSet::Random(3, starts[0].cols());
      for (int axis = 0; axis < 3; ++axis) starts.push_back((truth * HalfTurn(principal, axis)) * object.keypoints());
      for (std::size_t k = 0; k < starts.size(); ++k) {
        const PoseEstimate e = EstimateAndCertify(object, cloud, starts[k], Options(object), &free_space);
        if (!e.ok()) continue;
        ++candidates;
        const double hausdorff = PosedModelHausdorff(object, queries, truth, e.scene_from_model);
        if (k > 0 && hausdorff > bound) turned_refused += !e.certified();
        CHECK(RefusedBy(e.certificate).empty() == e.certified());   // every refusal is named
        if (!e.certified()) continue;
        ++certified;
        CHECK(hausdorff < bound);
      }
    }
  }
  MESSAGE("soundness with the frame: " << certified << " of " << candidates << " candidates certified; "
                                       << turned_refused << " turned fits beyond the bound refused");
  CHECK(candidates >= 48);
  CHECK(certified >= 5);         // the truth's basin is certified where the view shows the bump
  CHECK(turned_refused >= 8);    // wrong fits were offered and refused
}

TEST_CASE("soundness on a table: the segmenter's plane filters rivals, yet no certificate beyond the bound") {
  // The bumped box resting on a tilted table (bottom face down, random yaw),
  // the frame from the scene renderer; the cloud and the support plane come
  // from the segmenter (the box's mask, erosion off, plane at 1 cm), as for
  // real frames. The support test now refutes rivals that sink into the
  // table (the turns that put the box upside down): refuting a rival makes
  // certificates easier, so this checks that no certificate goes beyond the
  // bound from the true basin or from any half-turn start.
  const ObjectModel object = BumpedBox();
  const PrincipalFrame principal = ModelPrincipalFrame(object);
  const double bound = object.spec().eps_oc + 0.001 * std::sqrt(3.0) + 2 * 2.0 * object.SampleSpacing();
  const PointSet queries = StridedColumns(object.sample(), 3000);
  int candidates = 0, certified = 0, turned_refused = 0, through_refused = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    Rng rng(seed);
    Plane table;
    table.normal = (Eigen::Vector3d(0.0, -0.7, -0.7) + 0.2 * rng.UnitVector()).normalized();
    const Eigen::Vector3d foot(rng.Uniform(-0.03, 0.03), rng.Uniform(-0.03, 0.03), rng.Uniform(0.7, 0.9));
    table.offset = table.normal.dot(foot);
    Pose truth;
    truth.R = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), table.normal).toRotationMatrix() *
              Eigen::AngleAxisd(rng.Uniform(0.0, 2.0 * M_PI), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    truth.t = foot + 0.03 * table.normal;   // the box's bottom (z = -0.03) on the table
    CameraIntrinsics camera;
    DepthRenderer renderer(camera);
    const SceneImage scene = RenderScene(renderer, {{&object.mesh(), truth}}, table);
    DepthImage depth{camera.width, camera.height, {}};
    Mask mask{camera.width, camera.height, std::vector<std::uint8_t>(scene.depth.size(), 0)};
    for (std::size_t i = 0; i < scene.depth.size(); ++i) {
      const double noise = scene.depth[i] > 0.0 ? 0.001 * rng.Normal() : 0.0;
      depth.z.push_back(static_cast<float>(scene.depth[i] + noise));
      mask.inside[i] = scene.label[i] == 0;
    }
    SegmentOptions segment_options;
    segment_options.erode_mask_metres = 0.0;
    segment_options.erode_mask = 0;
    segment_options.max_points = 3000;
    const SegmentCloud segment = ExtractSegment(depth, mask, camera, segment_options, "table scene");
    REQUIRE(segment.support_plane.has_value());
    if (segment.cloud.cols() < 200) continue;
    const DepthView view{segment.depth, segment.camera, segment.support_plane, segment.support_plane_distance, nullptr,
                         segment.mask};
    const FreeSpaceTest free_space(object, view, FreeSpaceOptions{}, object.spec().eps_oc);
    CHECK(free_space.Check(truth).through_support == 0);
    std::vector<PointSet> starts = {truth * object.keypoints()};
    starts[0] += 0.005 * PointSet::Random(3, starts[0].cols());
    for (int axis = 0; axis < 3; ++axis) starts.push_back((truth * HalfTurn(principal, axis)) * object.keypoints());
    for (std::size_t k = 0; k < starts.size(); ++k) {
      const PoseEstimate e = EstimateAndCertify(object, segment.cloud, starts[k], Options(object), &free_space);
      if (!e.ok()) continue;
      ++candidates;
      const double hausdorff = PosedModelHausdorff(object, queries, truth, e.scene_from_model);
      if (k > 0 && hausdorff > bound) {
        turned_refused += !e.certified();
        through_refused += e.certificate.free_space.through_support > 0 && !e.certificate.free_space.passed;
      }
      CHECK(RefusedBy(e.certificate).empty() == e.certified());   // every refusal is named
      if (!e.certified()) continue;
      ++certified;
      CHECK(hausdorff < bound);
    }
  }
  MESSAGE("soundness on a table: " << certified << " of " << candidates << " candidates certified; " << turned_refused
                                   << " turned fits beyond the bound refused (" << through_refused
                                   << " of them sunk into the table)");
  CHECK(candidates >= 18);
  CHECK(certified >= 3);
  CHECK(turned_refused >= 6);
}

TEST_CASE("free space: lying intrinsics (focal 1e15 px) neither overflow the pixel reach nor crash") {
  const ObjectModel object = BumpedBox();
  Frame frame = RenderFrame(object);
  frame.view.camera.fx = frame.view.camera.fy = 1e15;
  const FreeSpaceTest test(object, frame.view, FreeSpaceOptions{}, object.spec().eps_oc);
  const FreeSpace result = test.Check(frame.truth);
  CHECK(result.checked);
  // The optical axis passes through the box, so at this focal length it
  // covers the whole image: the search runs, with its reach at the image size
  // (f·τ/z would be ~1e13 px).
  REQUIRE(result.silhouette > 0);
  CHECK(result.reach == std::max(frame.view.depth->width, frame.view.depth->height));
}

TEST_CASE("support: a box resting on the table passes, sunk into it fails (counts between brute-force bounds), raised passes") {
  // An 11 x 9 x 3.5 cm box lying on a table seen obliquely at ~0.8 m; the
  // frame and the box's mask come from the scene renderer, the support plane
  // from the segmenter's fit (io/support_plane.hpp).
  const ObjectModel box = PlainBox({0.11, 0.09, 0.035});
  Plane table;
  table.normal = Eigen::Vector3d(0.0, -0.6, -0.8).normalized();   // towards the camera
  table.offset = table.normal.dot(Eigen::Vector3d(0.0, 0.0, 0.8));
  Pose truth;
  truth.R = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), table.normal).toRotationMatrix() *
            Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  truth.t = Eigen::Vector3d(0.0, 0.0, 0.8) + 0.0175 * table.normal;   // the bottom face on the table
  CameraIntrinsics camera;
  DepthRenderer renderer(camera);
  const SceneImage scene = RenderScene(renderer, {{&box.mesh(), truth}}, table);
  auto depth = std::make_shared<DepthImage>();
  depth->width = camera.width;
  depth->height = camera.height;
  Mask mask{camera.width, camera.height, std::vector<std::uint8_t>(scene.depth.size(), 0)};
  for (std::size_t i = 0; i < scene.depth.size(); ++i) {
    depth->z.push_back(static_cast<float>(scene.depth[i]));
    mask.inside[i] = scene.label[i] == 0;
  }
  const double distance = 0.01;
  const std::optional<SupportPlaneFit> fit = FitSupportPlane(*depth, mask, camera, distance);
  REQUIRE(fit.has_value());
  CHECK(fit->plane.normal.dot(table.normal) > 1.0 - 1e-6);   // oriented towards the camera
  CHECK(std::abs(fit->plane.offset - table.offset) < 1e-5);
  DepthView view{depth, camera, fit->plane, distance, nullptr, nullptr};
  const FreeSpaceOptions options;
  const FreeSpaceTest test(box, view, options, box.spec().eps_oc);

  const FreeSpace at_truth = test.Check(truth);
  REQUIRE(at_truth.support_checked);
  CHECK(at_truth.passed);
  CHECK(at_truth.through_support == 0);
  CHECK(at_truth.support_points == box.sample().cols());

  // Sunk 3 cm into the table. Oracles: every counted point is more than
  // tau + D below the true table (upper bound, no visibility), and every such
  // point whose pixel the renderer labels table is counted (lower bound).
  const double margin = at_truth.tolerance + distance;
  Pose sunk = truth;
  sunk.t -= 0.03 * table.normal;
  int below = 0, below_on_table = 0;
  for (Eigen::Index j = 0; j < box.sample().cols(); ++j) {
    const Eigen::Vector3d x = sunk.R * box.sample().col(j) + sunk.t;
    if (!(table.normal.dot(x) - table.offset < -margin)) continue;
    ++below;
    const Eigen::Vector2d uv = view.camera.Project(x);
    const long u = std::lround(uv.x()), v = std::lround(uv.y());
    if (u >= 0 && v >= 0 && u < camera.width && v < camera.height &&
        scene.label[static_cast<std::size_t>(v) * camera.width + u] == SceneImage::kBackground) {
      ++below_on_table;
    }
  }
  const FreeSpace through = test.Check(sunk);
  CHECK(through.through_support >= below_on_table);
  CHECK(through.through_support <= below);
  CHECK(below_on_table > options.max_fraction * box.sample().cols());
  CHECK_FALSE(through.passed);
  CHECK_FALSE(through.support_passed);
  CHECK_FALSE(test.Passes(sunk, nullptr));   // a rival sunk into the table is no rival
  // With everything else passed, the refusal names the table (refusal.hpp).
  Certificate sunk_certificate;
  sunk_certificate.oc.passed = sunk_certificate.oc.points_passed = true;
  sunk_certificate.nd.passed = sunk_certificate.nd.sets_passed = true;
  sunk_certificate.free_space = through;
  const std::vector<CertificatePart> parts = RefusedBy(sunk_certificate);
  CHECK(std::find(parts.begin(), parts.end(), CertificatePart::kSupport) != parts.end());
  CHECK((parts.size() == 1) == through.silhouette_passed);

  // Raised 3 cm: floating is not the support test's business (none through).
  Pose raised = truth;
  raised.t += 0.03 * table.normal;
  CHECK(test.Check(raised).through_support == 0);

  // Without the plane, nothing is claimed about the table.
  DepthView no_plane{depth, camera, std::nullopt, 0.0, nullptr, nullptr};
  const FreeSpaceTest without(box, no_plane, options, box.spec().eps_oc);
  const FreeSpace unchecked = without.Check(sunk);
  CHECK_FALSE(unchecked.support_checked);
  CHECK(unchecked.through_support == 0);

  // Where the table is not seen (no depth under the sunk box's image), no
  // point counts: only a seen table is known to be solid.
  auto blind = std::make_shared<DepthImage>(*depth);
  for (Eigen::Index j = 0; j < box.sample().cols(); ++j) {
    const Eigen::Vector2d uv = view.camera.Project(sunk.R * box.sample().col(j) + sunk.t);
    const long u = std::lround(uv.x()), v = std::lround(uv.y());
    if (u >= 0 && v >= 0 && u < camera.width && v < camera.height) blind->z[static_cast<std::size_t>(v) * camera.width + u] = 0.0f;
  }
  const FreeSpaceTest blind_test(box, DepthView{blind, camera, fit->plane, distance, nullptr, nullptr}, options,
                                 box.spec().eps_oc);
  CHECK(blind_test.Check(sunk).through_support == 0);
}

TEST_CASE("global uniqueness: the rival slack has a floor in points (few discriminating points on a small cloud)") {
  const ObjectModel object = BumpedBox();
  const Pose truth = TestPose();
  const PipelineOptions options = Options(object);
  // A small cloud of the symmetric box plus 6 points on the bump's top face
  // (z = 0.07): 0.04 above the half-turned model's box top, so the half-turn
  // rival has exactly these 6 points beyond eps_oc = 0.01 and explains the rest.
  const PointSet box = BoxOnlyCloud(300, 5);
  PointSet cloud(3, box.cols() + 6);
  cloud.leftCols(box.cols()) = box;
  const double offsets[6][2] = {{-0.01, -0.01}, {0.0, -0.01}, {0.01, -0.01}, {-0.01, 0.01}, {0.0, 0.01}, {0.01, 0.01}};
  for (int i = 0; i < 6; ++i) cloud.col(box.cols() + i) = Eigen::Vector3d(0.07 + offsets[i][0], offsets[i][1], 0.07);
  cloud = truth * cloud;
  REQUIRE(static_cast<int>(std::floor(0.01 * cloud.cols())) < 6);   // the fraction alone forgives fewer than 6

  // Fraction only (the floor off): the rival has 6 > floor(1 % n) outliers and
  // does not count, so the estimate is certified although the 6 points are all
  // that tells the poses apart.
  PipelineOptions fraction_only = options;
  fraction_only.certificate.global.rival_extra_min = 0;
  const PoseEstimate loose = EstimateAndCertify(object, cloud, truth * object.keypoints(), fraction_only);
  REQUIRE(loose.ok());
  REQUIRE(loose.certificate.oc.passed);
  CHECK(loose.certificate.nd.global.passed);

  // Default (floor 10 points): the rival counts and the input is ambiguous.
  const PoseEstimate guarded = EstimateAndCertify(object, cloud, truth * object.keypoints(), options);
  REQUIRE(guarded.ok());
  CHECK(options.certificate.global.RivalSlack(cloud.cols()) == 10);
  CHECK_FALSE(guarded.certificate.nd.global.passed);
  CHECK_FALSE(guarded.certified());
  CHECK(guarded.certificate.nd.global.rival_outliers >= 1);
  CHECK(guarded.certificate.nd.global.rival_outliers <= 10);
  CHECK(guarded.certificate.nd.global.rival_hausdorff > 0.035);
}

namespace {

// Points on the top (z = 0.03) and front (y = 0.06) faces with |x| <= half_length:
// the faces share the edge along x, so the local test sees one weak motion
// (sliding along x); with half_length = 0.10 the faces are whole.
PointSet TwoFaces(double half_length, std::uint64_t seed) {
  const PointSet surface = SampleSurface(test::BoxMesh({0, 0, 0}, {0.20, 0.12, 0.06}), 12000, seed);
  PointSet kept(3, surface.cols());
  Eigen::Index n = 0;
  for (Eigen::Index j = 0; j < surface.cols(); ++j) {
    const Eigen::Vector3d p = surface.col(j);
    const bool on_face = std::abs(p.z() - 0.03) < 1e-9 || std::abs(p.y() - 0.06) < 1e-9;
    if (on_face && std::abs(p.x()) <= half_length) kept.col(n++) = p;
  }
  return kept.leftCols(n);
}

}  // namespace

TEST_CASE("weak motion: the displacement moves surface points by J(p)^T xi to first order") {
  const ObjectModel box = PlainBox({0.20, 0.12, 0.06});
  const Eigen::Vector3d centre = box.sample().rowwise().mean();
  const double radius = 0.5 * box.diameter();
  Eigen::Matrix<double, 6, 1> xi;
  xi << 0.3, -0.5, 0.2, 0.4, 0.1, -0.67;
  xi.normalize();
  const double s = 1e-5;
  const Pose displacement = WeakMotionDisplacement(box, xi, s);
  for (Eigen::Index i = 0; i < box.sample().cols(); i += 997) {
    const Eigen::Vector3d p = box.sample().col(i), n = box.sample_normals().col(i);
    Eigen::Matrix<double, 6, 1> J;   // the header's J(p) = ((p - c) x n / r, n), computed here
    J << (p - centre).cross(n) / radius, n;
    CHECK(std::abs((displacement * p - p).dot(n) / s - J.dot(xi)) < 1e-4);
  }
}

TEST_CASE("weak motion: a box seen on two whole faces is certified, the faces' middle part is refused") {
  const ObjectModel box = PlainBox({0.20, 0.12, 0.06});
  const Pose truth = TestPose();
  PipelineOptions options = Options(box);
  options.correct = false;   // certify the true pose itself

  const PointSet whole = truth * TwoFaces(0.10, 7);
  const PoseEstimate e = EstimateAndCertify(box, whole, truth * box.keypoints(), options);
  REQUIRE(e.ok());
  CHECK(e.certificate.oc.passed);
  // To first order the faces slide along their common edge ...
  CHECK_FALSE(e.certificate.nd.local.passed);
  CHECK(e.certificate.nd.local.weak_motions == 1);
  CHECK(std::abs(e.certificate.nd.local.motion(3)) > 0.9);   // mostly a translation along x
  // ... finitely they leave the faces' ends in the air: no rival, certified.
  REQUIRE(e.certificate.nd.weak_motion_checked);
  CHECK(e.certificate.nd.weak_motion.passed);
  CHECK(e.certificate.nd.weak_motion.starts >= 4);
  CHECK(e.certificate.nd.weak_motion.rivals_found == 0);
  CHECK(e.certified());

  // Switched off, the single weak motion fails nd as before.
  PipelineOptions off = options;
  off.certificate.local.weak_motion_check = false;
  const PoseEstimate strict = EstimateAndCertify(box, whole, truth * box.keypoints(), off);
  CHECK_FALSE(strict.certificate.nd.weak_motion_checked);
  CHECK_FALSE(strict.certified());

  // Only |x| <= 4 cm of the 10 cm half-length: the slid pose explains every
  // point, so the pose is not determined and the check finds the rival.
  const PointSet middle = truth * TwoFaces(0.04, 7);
  const PoseEstimate m = EstimateAndCertify(box, middle, truth * box.keypoints(), options);
  REQUIRE(m.ok());
  CHECK(m.certificate.oc.passed);
  CHECK(m.certificate.nd.local.weak_motions == 1);
  REQUIRE(m.certificate.nd.weak_motion_checked);
  CHECK_FALSE(m.certificate.nd.weak_motion.passed);
  CHECK(m.certificate.nd.weak_motion.rivals_found >= 1);
  CHECK(m.certificate.nd.weak_motion.rival_hausdorff > 2 * box.spec().eps_oc);
  CHECK_FALSE(m.certified());
  CHECK(RefusedBy(m.certificate) == std::vector<CertificatePart>{CertificatePart::kNdWeakMotion});
  CHECK(RefusalSummary(m.certificate).rfind("nd_weak_motion: the pose moved ", 0) == 0);
  CHECK(RefusedBy(e.certificate).empty());                                            // discharged
  CHECK(RefusedBy(strict.certificate) == std::vector<CertificatePart>{CertificatePart::kNdLocal});
}

TEST_CASE("weak motion: a single face (three weak motions) is never discharged") {
  const ObjectModel box = PlainBox({0.20, 0.12, 0.06});
  const Pose truth = TestPose();
  PipelineOptions options = Options(box);
  options.correct = false;
  const PointSet surface = SampleSurface(box.mesh(), 12000, 9);
  std::vector<Eigen::Index> top;
  for (Eigen::Index j = 0; j < surface.cols(); ++j) {
    if (std::abs(surface(2, j) - 0.03) < 1e-9) top.push_back(j);
  }
  PointSet face(3, static_cast<Eigen::Index>(top.size()));
  for (std::size_t k = 0; k < top.size(); ++k) face.col(static_cast<Eigen::Index>(k)) = surface.col(top[k]);
  const PoseEstimate e = EstimateAndCertify(box, truth * face, truth * box.keypoints(), options);
  REQUIRE(e.ok());
  CHECK(e.certificate.oc.passed);
  CHECK(e.certificate.nd.local.weak_motions >= 3);
  CHECK_FALSE(e.certificate.nd.weak_motion_checked);
  CHECK_FALSE(e.certified());
  CHECK(RefusedBy(e.certificate) == std::vector<CertificatePart>{CertificatePart::kNdLocal});
}

TEST_CASE("re-estimation: a flipped start is refuted, the restart at the half-turn is certified") {
  const ObjectModel object = BumpedBox();
  const Pose truth = TestPose();
  // The whole box with its bump: the half-turn leaves the bump's points in the air.
  const PointSet cloud = truth * SampleSurface(BumpedBoxMesh(), 4000, 11);
  const PrincipalFrame frame = ModelPrincipalFrame(object);
  // The detector's keypoints in the flipped basin: half-turned about the box's
  // smallest axis (z), the turn that swaps the bump's end.
  const PointSet flipped_keypoints = truth * HalfTurn(frame, 2) * object.keypoints();
  PipelineOptions options = Options(object);
  const PoseEstimate kept = EstimateAndCertify(object, cloud, flipped_keypoints, options);
  REQUIRE(kept.ok());
  CHECK_FALSE(kept.certificate.oc.passed);   // refuted by the bump's points
  CHECK_FALSE(kept.certified());
  CHECK(kept.restart_axis == -1);
  CHECK(kept.restarts_tried == 0);

  options.certificate.global.reestimate = true;
  const PoseEstimate restarted = EstimateAndCertify(object, cloud, flipped_keypoints, options);
  REQUIRE(restarted.ok());
  CHECK(restarted.restarts_tried == 13 * (options.certificate.global.reestimate_steps - 1));
  CHECK(restarted.restart_axis >= 0);
  CHECK(restarted.certificate.nd.global_checked);
  CHECK(restarted.certificate.nd.global.rivals_found == 0);   // no other restart explains the cloud
  CHECK(restarted.certified());
  // Oracle: the truth (the box alone is two-fold symmetric, the bump is not).
  const PointSet queries = StridedColumns(object.sample(), 1000);
  CHECK(PosedModelHausdorff(object, queries, truth, restarted.scene_from_model) < object.spec().eps_oc);
  // The detector's keypoints are reported as they were.
  CHECK((restarted.detected_keypoints - flipped_keypoints).norm() < 1e-12);

  // An estimate that is not refuted is never replaced.
  const PoseEstimate good = EstimateAndCertify(object, cloud, truth * object.keypoints(), options);
  CHECK(good.certified());
  CHECK(good.restart_axis == -1);
  CHECK(good.restarts_tried == 0);
}

TEST_CASE("re-estimation axes: the 13 rotation axes of a cube's symmetries in the principal frame") {
  const ObjectModel object = BumpedBox();
  const PrincipalFrame frame = ModelPrincipalFrame(object);
  const Eigen::Matrix<double, 3, 13> axes = ReestimateAxes(frame);
  // Oracle: in the principal frame the axes are the 3 coordinate axes, the 6
  // (±1, ±1, 0)/√2 permutations up to sign and the 4 (1, ±1, ±1)/√3.
  const Eigen::Matrix<double, 3, 13> local = frame.axes.transpose() * axes;
  int principal = 0, face = 0, body = 0;
  for (int a = 0; a < 13; ++a) {
    CHECK(axes.col(a).norm() == doctest::Approx(1.0));
    const Eigen::Vector3d v = local.col(a).cwiseAbs();
    const int zeros = (v.array() < 1e-9).count();
    if (zeros == 2) ++principal;
    if (zeros == 1) {
      ++face;
      CHECK(v.maxCoeff() == doctest::Approx(std::sqrt(0.5)));
    }
    if (zeros == 0) {
      ++body;
      CHECK(v.minCoeff() == doctest::Approx(1.0 / std::sqrt(3.0)));
    }
    for (int b = 0; b < a; ++b) CHECK(std::abs(axes.col(a).dot(axes.col(b))) < 1.0 - 1e-6);   // no axis twice
  }
  CHECK(principal == 3);
  CHECK(face == 6);
  CHECK(body == 4);
}

namespace {
// Refuses every pose whose translation has x > 0 (a stand-in for a frame's free space).
struct RefuseRight : RivalFilter {
  bool Passes(const Pose& scene_from_model, int* violations) const override {
    *violations = scene_from_model.t.x() > 0 ? 7 : 0;
    return scene_from_model.t.x() <= 0;
  }
};
}  // namespace

TEST_CASE("re-estimation: a restart that also explains the cloud is a rival of the chosen pose") {
  const ObjectModel object = BumpedBox();
  const Pose chosen = TestPose();
  const PointSet queries = StridedColumns(object.sample(), 1000);
  const auto fit_at = [&](const Pose& pose, bool ok, bool passes_oc) {
    RivalFit fit;
    fit.axis = 4;
    fit.angle = M_PI;
    fit.ok = ok;
    fit.passes_oc = passes_oc;
    fit.scene_from_model = pose;
    fit.outliers = 3;
    return fit;
  };
  Pose near = chosen, far_left = chosen, far_right = chosen;
  near.t.x() += 0.002;
  far_left.t.x() -= 0.05;
  far_right.t.x() += 0.05;
  GlobalUniqueness global;
  global.rival_distance = 2.0 * object.spec().eps_oc;
  std::vector<RivalFit> fits = {fit_at(near, true, true), fit_at(far_left, true, false), fit_at(far_left, false, true)};
  // Oracle: the Hausdorff distances by construction (a pure translation of the
  // posed model moves it by exactly its length).
  REQUIRE(PosedModelHausdorff(object, queries, chosen, near) < global.rival_distance);
  REQUIRE(PosedModelHausdorff(object, queries, chosen, far_left) > global.rival_distance);
  AddRestartRivals(object, fits, chosen, nullptr, &global);
  CHECK(global.passed);   // the chosen pose's own basin, a misfit, a failed fit: no rival
  CHECK(global.rivals_found == 0);
  CHECK(global.rivals_tried == 3);

  fits.push_back(fit_at(far_left, true, true));
  fits.push_back(fit_at(far_right, true, true));
  GlobalUniqueness unfiltered;
  unfiltered.rival_distance = global.rival_distance;
  AddRestartRivals(object, fits, chosen, nullptr, &unfiltered);
  CHECK_FALSE(unfiltered.passed);
  CHECK(unfiltered.rivals_found == 2);
  CHECK(unfiltered.rival_passes_oc);
  CHECK(unfiltered.rival_axis == 4);
  CHECK(unfiltered.rival_hausdorff == doctest::Approx(0.05).epsilon(0.02));

  const RefuseRight filter;   // the frame refutes the rival on the right, not the one on the left
  GlobalUniqueness filtered;
  filtered.rival_distance = global.rival_distance;
  AddRestartRivals(object, fits, chosen, &filter, &filtered);
  CHECK_FALSE(filtered.passed);
  CHECK(filtered.rivals_found == 1);
  CHECK((filtered.rival_scene_from_model.t - far_left.t).norm() < 1e-12);
  CHECK(filtered.rival_counts);

  // The global search reported a farther pose that passes oc but not free
  // space (it does not count); the restart rival that does count replaces it,
  // so the evidence names the pose that refused the estimate.
  Pose farther = chosen;
  farther.t.x() -= 0.09;
  GlobalUniqueness reported;
  reported.rival_distance = global.rival_distance;
  reported.rival_axis = 1;
  reported.rival_hausdorff = PosedModelHausdorff(object, queries, chosen, farther);
  reported.rival_passes_oc = true;
  reported.rival_counts = false;
  reported.rival_scene_from_model = farther;
  REQUIRE(reported.rival_hausdorff > 0.05 + 0.03);
  AddRestartRivals(object, fits, chosen, &filter, &reported);
  CHECK(reported.rivals_found == 1);
  CHECK(reported.rival_counts);
  CHECK(reported.rival_axis == 4);
  CHECK((reported.rival_scene_from_model.t - far_left.t).norm() < 1e-12);
}

TEST_CASE("global uniqueness: a mug seen side-on, flipped upside down, is refused (the flip axis is not principal)") {
  // The bundled mug without indicator sets. Its extents along the handle (x)
  // and the axis (z) are alike, so its principal axes are oblique to both;
  // seen exactly side-on, neither the rim's opening nor the base shows, and
  // the mug turned upside down (a half-turn about x through mid-height)
  // explains the cloud too. Found as a false certificate on rendered BOP
  // scenes (3.6 cm off, --erode-mask 2): no turn about a principal axis
  // reached the truth from the flipped estimate.
  ObjectModel object = LoadObject(test::SourceDir() + "/annotations/mug.json");
  object.mutable_spec().indicator_sets.clear();
  const PointSet queries = StridedColumns(object.sample(), 1000);
  const double height = object.keypoints().row(2).maxCoeff();
  Pose upside_down;   // model_from_model: x stays, z -> height - z
  upside_down.R = Eigen::Vector3d(1, -1, -1).asDiagonal();
  upside_down.t = {0, 0, height};
  for (const double handle_deg : {-60.0, -30.0, 0.0, 30.0, 60.0}) {
    CAPTURE(handle_deg);
    // Camera looks along +z: the mug's axis along camera x, its handle turned
    // by handle_deg from the camera's y axis towards the camera.
    const double a = handle_deg * M_PI / 180.0;
    Pose truth;
    truth.R.col(0) = Eigen::Vector3d(0, std::cos(a), -std::sin(a));
    truth.R.col(2) = Eigen::Vector3d(1, 0, 0);
    truth.R.col(1) = truth.R.col(2).cross(truth.R.col(0));
    truth.t = Eigen::Vector3d(0, 0, 0.8) - truth.R * Eigen::Vector3d(0, 0, 0.5 * height);
    DepthRenderer renderer(CameraIntrinsics{});
    renderer.Render(object.mesh(), truth);
    Rng rng(7);
    DepthSampleOptions sample;
    sample.points = 3000;
    const PointSet cloud = renderer.SampleCloud(sample, rng);
    const Pose flipped = truth * upside_down;
    REQUIRE(PosedModelHausdorff(object, queries, truth, flipped) > 0.03);
    // From the flipped basin and from the truth: the view is ambiguous, so
    // neither is certified (the previous search certified the flip at -30 deg).
    for (const Pose& start : {flipped, truth}) {
      const PoseEstimate estimate = EstimateAndCertify(object, cloud, start * object.keypoints(), Options(object));
      REQUIRE(estimate.ok());
      CHECK_FALSE(estimate.certified());
    }
  }
}

TEST_CASE("rival fits: fitted to the cloud, judged on the evidence (the re-estimation's restarts)") {
  // The cloud (the estimate's, eroded) shows only the symmetric box; the
  // evidence adds the bump's top. The half-turn about z explains the cloud
  // but not the evidence: judged on the evidence it must not pass the
  // rivals' oc (docs/method.md "Evidence: the whole mask").
  const ObjectModel object = BumpedBox();
  const Pose truth = TestPose();
  const PipelineOptions options = Options(object);
  const PointSet cloud = truth * BoxOnlyCloud(3000, 3);
  const PointSet bump_surface = SampleSurface(test::BoxMesh({0.07, 0.0, 0.05}, {0.04, 0.04, 0.04}), 4000, 5);
  std::vector<Eigen::Index> top;
  for (Eigen::Index j = 0; j < bump_surface.cols(); ++j) {
    if (bump_surface(2, j) > 0.065) top.push_back(j);
  }
  REQUIRE(top.size() > 200);
  PointSet evidence(3, cloud.cols() + 200);
  evidence.leftCols(cloud.cols()) = cloud;
  for (int k = 0; k < 200; ++k) evidence.col(cloud.cols() + k) = truth * Eigen::Vector3d(bump_surface.col(top[k]));

  Pose half_turn;
  half_turn.R = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  half_turn.t.setZero();
  const PoseEstimate at_truth = EstimateAndCertify(object, cloud, truth * object.keypoints(), options);
  REQUIRE(at_truth.ok());
  const std::vector<RivalStart> starts = {{2, M_PI, truth * half_turn}};
  for (bool refine : {false, true}) {
    CAPTURE(refine);
    const std::vector<RivalFit> on_cloud = FitRivals(object, cloud, at_truth, options, starts, refine);
    const std::vector<RivalFit> on_evidence = FitRivals(object, cloud, at_truth, options, starts, refine, &evidence);
    REQUIRE(on_cloud.size() == 1);
    REQUIRE(on_evidence.size() == 1);
    REQUIRE(on_cloud[0].ok);
    REQUIRE(on_evidence[0].ok);
    // The same fit (the evidence never moves it) ...
    CHECK((on_cloud[0].scene_from_model.R - on_evidence[0].scene_from_model.R).norm() < 1e-9);
    CHECK((on_cloud[0].scene_from_model.t - on_evidence[0].scene_from_model.t).norm() < 1e-9);
    CHECK(on_cloud[0].hausdorff > 0.035);   // the bump at the other end: a far pose
    CHECK(on_cloud[0].passes_oc);
    // ... judged on the points given: brute-force count of the evidence's
    // points at >= eps_oc from the model posed at the fit.
    const Eigen::VectorXd d = object.DistancesToPosedModel(evidence, on_evidence[0].scene_from_model);
    const int beyond = static_cast<int>((d.array() >= object.spec().eps_oc).count());
    CHECK(beyond >= 150);   // the bump's top points (0.04 above the rival's top face)
    CHECK(on_evidence[0].outliers == beyond);
    // Budget of the evidence: m = 0 + max(1 % of 3200, 10) = 32 < beyond.
    CHECK(options.certificate.global.RivalSlack(evidence.cols()) < beyond);
    CHECK_FALSE(on_evidence[0].passes_oc);
  }
}

namespace {

// The box translated by `x` along its own x axis (the faces' common edge).
Pose SlidAlongX(const Pose& pose, double x) {
  Pose slid = pose;
  slid.t += pose.R * Eigen::Vector3d(x, 0, 0);
  return slid;
}

}  // namespace

TEST_CASE("centring: the centre of fits is their midpoint (analytic) and a single pose is itself") {
  const ObjectModel box = PlainBox({0.20, 0.12, 0.06});
  const Eigen::Vector3d c = box.sample().rowwise().mean();
  const Pose base = TestPose();
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -1, 0.4).normalized();
  const double angle = 0.5;
  const Eigen::Vector3d shift(0.03, -0.02, 0.01);
  // Two poses turned by -angle/2 and +angle/2 about `axis` through the posed
  // centroid and moved by -shift/2, +shift/2: their centre is `base`.
  const auto turned = [&](double sign) {
    Pose turn;
    turn.R = Eigen::AngleAxisd(sign * angle / 2, axis).toRotationMatrix();
    const Eigen::Vector3d posed_centroid = base * c;
    turn.t = posed_centroid - turn.R * posed_centroid + sign * shift / 2;
    Pose composed;
    composed.R = turn.R * base.R;
    composed.t = turn.R * base.t + turn.t;
    return composed;
  };
  const Pose centre = CentreOfFits(box, {turned(1), turned(-1)});
  CHECK((centre.R - base.R).norm() < 1e-12);
  CHECK((centre.t - base.t).norm() < 1e-12);
  CHECK(centre.R.determinant() == doctest::Approx(1.0).epsilon(1e-12));
  const Pose single = CentreOfFits(box, {base});
  CHECK((single.R - base.R).norm() < 1e-12);
  CHECK((single.t - base.t).norm() < 1e-12);
  CHECK_THROWS_AS(CentreOfFits(box, {}), std::invalid_argument);
}

TEST_CASE("centring: an estimate at one end of a valley of fits narrower than 2*rho is replaced by its centre") {
  // The two faces of the box with |x| <= 8.5 cm of its 10 cm half-length:
  // every slide along x by s in [-1.5, 1.5] cm explains each point (the
  // valley, 3 cm wide: between rho = 2 eps_oc = 2 cm and 2 rho). The truth is
  // its centre; the estimate starts at its end, s = +1.5 cm.
  const ObjectModel box = PlainBox({0.20, 0.12, 0.06});
  const Pose truth = TestPose();
  const double rho = 2.0 * box.spec().eps_oc;
  const PointSet cloud = truth * TwoFaces(0.085, 11);
  const Pose end = SlidAlongX(truth, 0.015);

  PipelineOptions off = Options(box);
  off.certificate.global.centre = false;
  const PoseEstimate refused = EstimateAndCertify(box, cloud, end * box.keypoints(), off);
  REQUIRE(refused.ok());
  CHECK(refused.certificate.oc.passed);
  CHECK(RefusedBy(refused.certificate) == std::vector<CertificatePart>{CertificatePart::kNdWeakMotion});
  CHECK_FALSE(refused.centred);
  const std::vector<Pose>& rivals = refused.certificate.nd.weak_motion.rival_poses;
  REQUIRE_FALSE(rivals.empty());
  CHECK(static_cast<int>(rivals.size()) == refused.certificate.nd.weak_motion.rivals_found);
  const double end_error = test::BrutePosedHausdorff(box, refused.scene_from_model, truth, 500);
  CHECK(end_error > 0.5 * rho);   // the corrector stayed near the valley's end

  const PoseEstimate centred = EstimateAndCertify(box, cloud, end * box.keypoints(), Options(box));
  REQUIRE(centred.ok());
  CHECK(centred.certified());
  CHECK(centred.centred);
  CHECK(centred.centred_fits == static_cast<int>(rivals.size()) + 1);
  // Oracles: the brute-force Hausdorff distances. The centre lies within rho
  // of the refused estimate and of every rival it was refused for, and it is
  // the valley's centre, the truth, within the certificate's eps_oc.
  const Pose& centre = centred.scene_from_model;
  CHECK(test::BrutePosedHausdorff(box, centre, refused.scene_from_model, 500) <= rho);
  for (const Pose& rival : rivals) CHECK(test::BrutePosedHausdorff(box, centre, rival, 500) <= rho);
  const double centre_error = test::BrutePosedHausdorff(box, centre, truth, 500);
  CHECK(centre_error < box.spec().eps_oc);
  CHECK(centre_error < end_error);
  // Every test was applied to the centre itself.
  CHECK(centred.certificate.oc.outlier_count == 0);
  CHECK(centred.certificate.nd.weak_motion_checked);
  CHECK(centred.certificate.nd.weak_motion.passed);
  CHECK(centred.certificate.nd.global_checked);
  CHECK(centred.certificate.nd.global.passed);
}

TEST_CASE("centring: a valley wider than 2*rho stays refused wherever the estimate starts in it") {
  // |x| <= 6 cm of 10: slides in [-4, 4] cm fit, a valley of 8 cm = 4 rho.
  // No pose is within rho of every fit, so none may be certified.
  const ObjectModel box = PlainBox({0.20, 0.12, 0.06});
  const Pose truth = TestPose();
  const PointSet cloud = truth * TwoFaces(0.06, 13);
  for (const double s : {-0.04, -0.02, 0.0, 0.01, 0.03}) {
    CAPTURE(s);
    const PoseEstimate e =
        EstimateAndCertify(box, cloud, SlidAlongX(truth, s) * box.keypoints(), Options(box));
    REQUIRE(e.ok());
    CHECK(e.certificate.oc.passed);
    CHECK_FALSE(e.certified());
  }
}

TEST_CASE("soundness of centring: with the truth at a valley's end, no certificate farther than rho from it") {
  // The worst case for centring: the data are a valley of fits (two faces of
  // the box along |x| <= h, slides by up to 10 cm - h either way explain
  // them) and the truth is one of its ends, the estimate started anywhere in
  // it. A certified pose must lie within rho of the truth (the search's
  // bound: the truth's refit is a fit found from some start), whatever the
  // valley's width -- narrower than 2 rho (the centre is within rho of both
  // ends) or wider (refused).
  const ObjectModel box = PlainBox({0.20, 0.12, 0.06});
  const Pose middle = TestPose();
  const double rho = 2.0 * box.spec().eps_oc;
  Rng rng(29);
  int certified = 0, runs = 0;
  for (const double h : {0.09, 0.085, 0.08, 0.07, 0.06}) {
    PointSet cloud = middle * TwoFaces(h, 17);
    for (Eigen::Index j = 0; j < cloud.cols(); ++j) {
      cloud.col(j) += 0.0005 * Eigen::Vector3d(rng.Normal(), rng.Normal(), rng.Normal());
    }
    const double half_width = 0.10 - h;
    for (const double end : {-1.0, 1.0}) {
      const Pose truth = SlidAlongX(middle, end * half_width);
      for (const double start : {-1.0, 0.0, 1.0}) {
        CAPTURE(h);
        CAPTURE(end);
        CAPTURE(start);
        const PoseEstimate e = EstimateAndCertify(
            box, cloud, SlidAlongX(middle, start * half_width) * box.keypoints(), Options(box));
        ++runs;
        if (!e.certified()) continue;
        ++certified;
        // rho plus the sampling error of the brute force (500 strided points against all 20000).
        CHECK(test::BrutePosedHausdorff(box, e.scene_from_model, truth, 500) <= rho + 0.003);
        if (2.0 * half_width > 2.0 * rho + 0.003) CHECK_FALSE(e.certified());   // no pose within rho of both ends
      }
    }
  }
  MESSAGE(certified << " of " << runs << " certified");
  CHECK(certified > 0);   // the narrow valleys are certified (centred): the test is not vacuous
}
