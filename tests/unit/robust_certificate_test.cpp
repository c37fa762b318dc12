// Outlier-robust certificates (issue 16): oc_m, nd_m, the local
// non-degeneracy test, the robust corrector, and a soundness property test.
// Oracles: brute-force counts and quantiles, analytic degenerate clouds,
// finite differences, the ground-truth pose and Hausdorff distances.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "c3po/method/auto_threshold.hpp"
#include "c3po/method/certificate.hpp"
#include "c3po/method/corrector.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/method/refusal.hpp"
#include "c3po/base/error.hpp"
#include "c3po/method/local_nondegeneracy.hpp"
#include "c3po/eval/metrics.hpp"
#include "c3po/base/random.hpp"
#include "c3po/geometry/registration.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/synth/stray_points.hpp"
#include "c3po/synth/synth.hpp"
#include "c3po/object/procedural.hpp"
#include "test_objects.hpp"

using namespace c3po;

namespace {

PointSet Columns(const PointSet& points, const std::vector<Eigen::Index>& kept) {
  PointSet out(3, static_cast<Eigen::Index>(kept.size()));
  for (std::size_t i = 0; i < kept.size(); ++i) out.col(i) = points.col(kept[i]);
  return out;
}

// Closed cylinder (axis z) with `segments` sides: a body of revolution up to
// its facets.
Mesh CylinderMesh(double radius, double height, int segments) {
  Mesh mesh;
  mesh.vertices.resize(3, 2 * segments + 2);
  for (int s = 0; s < segments; ++s) {
    const double a = 2 * M_PI * s / segments;
    mesh.vertices.col(s) << radius * std::cos(a), radius * std::sin(a), -height / 2;
    mesh.vertices.col(segments + s) << radius * std::cos(a), radius * std::sin(a), height / 2;
  }
  mesh.vertices.col(2 * segments) << 0, 0, -height / 2;
  mesh.vertices.col(2 * segments + 1) << 0, 0, height / 2;
  mesh.triangles.resize(3, 4 * segments);
  for (int s = 0; s < segments; ++s) {
    const int n = (s + 1) % segments;
    mesh.triangles.col(4 * s) << s, n, segments + n;
    mesh.triangles.col(4 * s + 1) << s, segments + n, segments + s;
    mesh.triangles.col(4 * s + 2) << 2 * segments, n, s;
    mesh.triangles.col(4 * s + 3) << 2 * segments + 1, segments + s, segments + n;
  }
  return mesh;
}

ObjectSpec Spec(const std::string& name, const Eigen::Matrix3d& keypoints, double eps_oc, double delta_nd) {
  ObjectSpec spec;
  spec.name = name;
  spec.keypoints = keypoints;
  spec.eps_oc = eps_oc;
  spec.delta_nd = delta_nd;
  return spec;
}

CertificateOptions WithBudget(const ObjectModel& object, OutlierBudget budget) {
  CertificateOptions options = CertificateOptions::FromObject(object.spec());
  options.max_outliers = budget;
  return options;
}

OutlierBudget Count(int m) {
  OutlierBudget budget;
  budget.count = m;
  return budget;
}

}  // namespace

TEST_CASE("--max-outliers parses a count or a percentage and rejects the rest") {
  CHECK(ParseOutlierBudget("10").count == 10);
  CHECK(ParseOutlierBudget("0").IsZero());
  CHECK(ParseOutlierBudget("2%").fraction == doctest::Approx(0.02));
  CHECK(ParseOutlierBudget("2%").Resolve(1000) == 20);
  CHECK(ParseOutlierBudget("2%").Resolve(49) == 0);   // floor(0.98)
  CHECK(ParseOutlierBudget("0.5%").Resolve(1000) == 5);
  CHECK(ParseOutlierBudget("7").Resolve(3) == 7);
  for (const char* bad : {"", "%", "-1", "abc", "100%", "2.5", "1e3", "3 %", "nan", "2%%"}) {
    CAPTURE(bad);
    CHECK_THROWS_AS(ParseOutlierBudget(bad), InputError);
  }
}

TEST_CASE("oc_m: a cloud whose m farthest points are moved far away passes oc_m and fails oc_{m-1}") {
  const ObjectModel object = test::AsymmetricObject(20000);
  Rng rng(5);
  Pose truth;
  truth.R = rng.Rotation();
  truth.t = {0.05, 0.1, 0.7};
  PointSet cloud = truth * SampleSurface(object.mesh(), 400, 8);
  const PointSet keypoints = truth * object.keypoints();
  const Eigen::Vector3d centre = truth * Eigen::Vector3d(object.sample().rowwise().mean());
  const std::vector<int> moved = {3, 50, 51, 200, 399};
  for (size_t k = 0; k < moved.size(); ++k) {
    cloud.col(moved[k]) += (0.05 + 0.1 * k) * (cloud.col(moved[k]) - centre).normalized();
  }
  const int m = static_cast<int>(moved.size());
  const ObservableCorrectness pass = CheckObservableCorrectness(object, cloud, truth, keypoints, WithBudget(object, Count(m)));
  const ObservableCorrectness fail = CheckObservableCorrectness(object, cloud, truth, keypoints, WithBudget(object, Count(m - 1)));
  CHECK(pass.passed);
  CHECK_FALSE(fail.passed);
  CHECK(pass.outlier_count == m);
  CHECK(pass.outlier_indices == moved);
  CHECK(pass.max_inlier_distance < pass.eps_oc);
  // Oracle: brute-force distances to the posed sample.
  const PointSet posed = truth * object.sample();
  std::vector<double> distances;
  for (Eigen::Index j = 0; j < cloud.cols(); ++j) {
    distances.push_back(std::sqrt((posed.colwise() - cloud.col(j)).colwise().squaredNorm().minCoeff()));
  }
  std::vector<double> sorted = distances;
  std::sort(sorted.begin(), sorted.end());
  CHECK(pass.max_point_distance == doctest::Approx(sorted.back()));
  CHECK(pass.budget_distance == doctest::Approx(sorted[sorted.size() - 1 - m]));
  CHECK(fail.budget_distance == doctest::Approx(sorted[sorted.size() - m]));
  CHECK(pass.max_inlier_distance == doctest::Approx(sorted[sorted.size() - 1 - m]));
  CHECK(pass.quantile50 == doctest::Approx(SampleQuantile(distances, 0.5)));
  CHECK(pass.quantile90 == doctest::Approx(SampleQuantile(distances, 0.9)));
  CHECK(pass.quantile99 == doctest::Approx(SampleQuantile(distances, 0.99)));
  // A percentage: 5 of 400 points = 1.25 %.
  CHECK(CheckObservableCorrectness(object, cloud, truth, keypoints, WithBudget(object, ParseOutlierBudget("1.25%"))).passed);
  CHECK_FALSE(CheckObservableCorrectness(object, cloud, truth, keypoints, WithBudget(object, ParseOutlierBudget("1%"))).passed);
  // --eps-oc auto's re-decision agrees with a fresh certificate.
  ObservableCorrectness rethresholded = pass;
  RethresholdObservableCorrectness(&rethresholded, 0.5 * pass.eps_oc);
  CertificateOptions half = WithBudget(object, Count(m));
  half.eps_oc = 0.5 * pass.eps_oc;
  const ObservableCorrectness fresh = CheckObservableCorrectness(object, cloud, truth, keypoints, half);
  CHECK(rethresholded.passed == fresh.passed);
  CHECK(rethresholded.outlier_indices == fresh.outlier_indices);
}

TEST_CASE("oc with m = 0 is the paper's eq. 19 (one far point fails)") {
  const ObjectModel object = test::AsymmetricObject(20000);
  const Pose truth;
  PointSet cloud = SampleSurface(object.mesh(), 300, 3);
  const CertificateOptions options = CertificateOptions::FromObject(object.spec());
  CHECK(CheckObservableCorrectness(object, cloud, truth, object.keypoints(), options).passed);
  cloud(2, 10) += 1.0;
  const ObservableCorrectness oc = CheckObservableCorrectness(object, cloud, truth, object.keypoints(), options);
  CHECK_FALSE(oc.passed);
  CHECK(oc.outlier_indices == std::vector<int>{10});
  CHECK(oc.budget_distance == oc.max_point_distance);
}

TEST_CASE("nd_m fails when an indicator keypoint has only m supporting points") {
  // The mug-like object: body + handle; the handle keypoint alone is the set.
  const Mesh mesh = test::MugLikeMesh();
  const ObjectSpec spec = test::MugLikeSpec();
  ObjectModelOptions model_options;
  model_options.sample_size = 20000;
  const ObjectModel mug(spec, mesh, model_options);
  const PointSet all = SampleSurface(mesh, 6000, 5);
  const Eigen::Vector3d handle = spec.keypoints.col(0);
  std::vector<Eigen::Index> body, near_handle;
  for (Eigen::Index i = 0; i < all.cols(); ++i) {
    const double to_handle = (all.col(i) - handle).norm();
    if (to_handle < spec.delta_nd - 1e-4) near_handle.push_back(i);
    else if (to_handle > spec.delta_nd + 1e-4) body.push_back(i);
  }
  REQUIRE(near_handle.size() >= 6);
  for (int m : {1, 3, 5}) {
    CAPTURE(m);
    std::vector<Eigen::Index> kept = body;
    kept.insert(kept.end(), near_handle.begin(), near_handle.begin() + m);   // exactly m supports
    const PointSet cloud = Columns(all, kept);
    const NonDegeneracy exactly_m = CheckNonDegeneracy(mug, cloud, Pose(), WithBudget(mug, Count(m)));
    CHECK(exactly_m.keypoint_support[0] == m);
    CHECK(exactly_m.set_min_support == std::vector<int>{m});
    CHECK_FALSE(exactly_m.sets_passed);
    CHECK_FALSE(exactly_m.passed);
    const NonDegeneracy fewer = CheckNonDegeneracy(mug, cloud, Pose(), WithBudget(mug, Count(m - 1)));
    CHECK(fewer.sets_passed);
  }
  SUBCASE("supports rejected by oc_m do not count") {
    // m + 1 supports near the handle keypoint, but pushed off the surface by
    // more than eps_oc: all rejected by oc, so they support nothing.
    const PointSet cloud = Columns(all, body);
    const int m = 2;
    // The handle keypoint lies on the handle's face x = 0.07: 7 mm outside it
    // is within delta_nd (8 mm) of the keypoint and 7 mm off the surface.
    PointSet off(3, m + 1);
    for (int k = 0; k <= m; ++k) off.col(k) = handle + Eigen::Vector3d(0.007, 0.001 * k, 0.0);
    PointSet with_off(3, cloud.cols() + off.cols());
    with_off << cloud, off;
    CertificateOptions options = WithBudget(mug, Count(m));
    options.eps_oc = 0.005;
    const NonDegeneracy nd = CheckNonDegeneracy(mug, with_off, Pose(), options);
    CHECK(nd.keypoint_support[0] == 0);
    CHECK_FALSE(nd.sets_passed);
    options.eps_oc = 0.01;   // now accepted: m + 1 supports
    CHECK(CheckNonDegeneracy(mug, with_off, Pose(), options).keypoint_support[0] == m + 1);
  }
  SUBCASE("sets off (the camera-frame default): the object is judged as if it had none") {
    // The body alone: the handle keypoint has no support at all, so its set
    // fails for every m; with the sets off nothing about them is decided.
    const PointSet cloud = Columns(all, body);
    for (int m : {0, 2}) {
      CAPTURE(m);
      CertificateOptions options = WithBudget(mug, Count(m));
      const NonDegeneracy on = CheckNonDegeneracy(mug, cloud, Pose(), options);
      CHECK(on.sets_used);
      CHECK(on.keypoint_support[0] == 0);
      CHECK_FALSE(on.sets_passed);
      options.use_indicator_sets = false;
      const NonDegeneracy off = CheckNonDegeneracy(mug, cloud, Pose(), options);
      CHECK_FALSE(off.sets_used);
      CHECK(off.sets_passed);
      CHECK(off.passing_set == -1);
      CHECK(off.set_min_support.empty());
      CHECK(off.local.passed == on.local.passed);   // the local test does not depend on the sets
      CHECK(off.passed == off.local.passed);
    }
  }
}

TEST_CASE("degenerate clouds of a non-planar object are never certified") {
  const ObjectModel object = test::AsymmetricObject(20000);
  Rng rng(9);
  Pose truth;
  truth.R = rng.Rotation();
  truth.t = {0.0, 0.0, 0.8};
  const PointSet keypoints = truth * object.keypoints();
  const CertificateOptions options = CertificateOptions::FromObject(object.spec());
  // The top face of the main block (z = 0.03, outside the tower footprint).
  const PointSet surface = SampleSurface(object.mesh(), 20000, 4);
  std::vector<Eigen::Index> top;
  for (Eigen::Index i = 0; i < surface.cols(); ++i) {
    const Eigen::Vector3d p = surface.col(i);
    if (std::abs(p.z() - 0.03) < 1e-9 && p.x() < 0.035 && !(p.x() > -0.07 && p.x() < -0.03 && p.y() > 0.05)) top.push_back(i);
  }
  REQUIRE(top.size() > 100);
  PointSet line(3, 40);
  for (int k = 0; k < 40; ++k) line.col(k) = Eigen::Vector3d(-0.1 + 0.0025 * k, 0.0, 0.03);
  struct Case { const char* name; PointSet model_points; };
  const std::vector<Case> cases = {
      {"one point", surface.col(top[0])},
      {"two points", Columns(surface, {top[0], top[50]})},
      {"collinear points", line},
      {"a single plane", Columns(surface, top)},
  };
  for (const Case& c : cases) {
    CAPTURE(c.name);
    const PointSet cloud = truth * c.model_points;
    const Certificate certificate = Certify(object, cloud, truth, keypoints, options);
    CHECK(certificate.oc.passed);              // the points do lie on the posed surface
    CHECK_FALSE(certificate.nd.local.passed);
    CHECK_FALSE(certificate.nd.passed);
    CHECK_FALSE(certificate.certified());
    CHECK(certificate.nd.local.min_eigenvalue < 1e-6);
  }
  // The whole surface is as informative as the model: λ_min ≈ 1.
  const Certificate whole = Certify(object, truth * surface, truth, keypoints, options);
  CHECK(whole.certified());
  CHECK(whole.nd.local.min_eigenvalue == doctest::Approx(1.0).epsilon(0.1));
  CHECK(whole.nd.local.model_rank == 6);
}

TEST_CASE("refusal: every failed part is named with its evidence, nothing when certified") {
  const ObjectModel object = test::AsymmetricObject(20000);
  Rng rng(21);
  Pose truth;
  truth.R = rng.Rotation();
  truth.t = {0.02, -0.03, 0.6};
  const PointSet keypoints = truth * object.keypoints();
  const PointSet surface = SampleSurface(object.mesh(), 3000, 6);
  const PointSet cloud = truth * surface;
  const CertificateOptions options = CertificateOptions::FromObject(object.spec());
  const double eps_oc = options.eps_oc;
  using Parts = std::vector<CertificatePart>;

  const Certificate whole = Certify(object, cloud, truth, keypoints, options);
  REQUIRE(whole.certified());
  CHECK(RefusedBy(whole).empty());
  CHECK(RefusalSummary(whole).empty());

  SUBCASE("far points beyond the budget: oc, with the count and the budget") {
    PointSet far = cloud;
    for (int j : {7, 8, 9}) far(2, j) += 0.5;
    const Certificate c = Certify(object, far, truth, keypoints, WithBudget(object, Count(2)));
    CHECK(RefusedBy(c) == Parts{CertificatePart::kOcPoints});
    CHECK(RefusalSummary(c).rfind("oc: 3 of 3000 points at >= eps_oc", 0) == 0);
    CHECK(RefusalSummary(c).find("(budget 2)") != std::string::npos);
    CHECK(RefusedBy(Certify(object, far, truth, keypoints, WithBudget(object, Count(3)))).empty());
  }
  SUBCASE("a counting rival: nd_global names where it is, the own refit in words") {
    Certificate c = whole;
    c.nd.global_checked = true;
    c.nd.global.passed = false;
    c.nd.passed = false;
    c.nd.global.rival_axis = 0;
    c.nd.global.rival_hausdorff = 0.031;
    c.nd.global.rival_outliers = 4;
    c.nd.global.rival_distance = 0.02;
    c.nd.global.rival_angle_deg = 180.0;
    CHECK(RefusedBy(c) == Parts{CertificatePart::kNdGlobal});
    CHECK(RefusalSummary(c).rfind("nd_global: a pose 0.031 away (180 deg about axis 0) leaves 4 points", 0) == 0);
    c.nd.global.rival_angle_deg = 0.0;   // RivalHypotheses' last start: the estimate itself
    CHECK(RefusalSummary(c).rfind("nd_global: the corrector moves the pose 0.031 away, where it leaves 4 points",
                                  0) == 0);
  }
  SUBCASE("another known object certified too: identity names it, unchecked identity passes") {
    Certificate c = whole;
    REQUIRE(c.certified());
    c.identity.checked = true;   // checked, nothing else certified
    c.identity.objects_tried = 2;
    CHECK(c.certified());
    c.identity.passed = false;
    c.identity.rival = "twin.json";
    c.identity.rival_oc_distance = 0.004;
    CHECK_FALSE(c.certified());
    CHECK(RefusedBy(c) == Parts{CertificatePart::kIdentity});
    CHECK(RefusalSummary(c) == "identity: twin.json is certified on the cloud too (its oc distance 0.004; 2 other "
                               "objects tried)");
  }
  SUBCASE("corrected keypoints off the posed model's: oc_keypoints only") {
    PointSet off = keypoints;
    off.col(1) += Eigen::Vector3d(0.0, 2.0 * eps_oc, 0.0);
    const Certificate c = Certify(object, cloud, truth, off, options);
    CHECK(c.oc.points_passed);
    CHECK(RefusedBy(c) == Parts{CertificatePart::kOcKeypoints});
    CHECK(RefusalSummary(c).rfind("oc_keypoints: keypoints ", 0) == 0);
  }
  SUBCASE("a single plane: nd_local, with the unseen motions") {
    std::vector<Eigen::Index> top;
    for (Eigen::Index i = 0; i < surface.cols(); ++i) {
      if (std::abs(surface(2, i) - 0.03) < 1e-9) top.push_back(i);
    }
    REQUIRE(top.size() > 50);
    const Certificate c = Certify(object, truth * Columns(surface, top), truth, keypoints, options);
    CHECK(RefusedBy(c) == Parts{CertificatePart::kNdLocal});
    CHECK(RefusalSummary(c).rfind("nd_local: ", 0) == 0);
    CHECK(RefusalSummary(c).find("motions the accepted points do not constrain") != std::string::npos);
  }
  SUBCASE("no points: oc and nd both refuse") {
    const Certificate c = Certify(object, PointSet(3, 0), truth, keypoints, options);
    CHECK(RefusedBy(c) == Parts{CertificatePart::kOcPoints, CertificatePart::kNdSets, CertificatePart::kNdLocal});
    CHECK(RefusalSummary(c).rfind("oc: no input points; nd_sets: no input points; nd_local: ", 0) == 0);
  }
  std::vector<std::string> names;   // distinct names for every part
  for (std::size_t k = 0; k < kCertificatePartCount; ++k) names.push_back(ToString(static_cast<CertificatePart>(k)));
  CHECK(names == std::vector<std::string>{"oc", "oc_keypoints", "free_space", "support", "mask", "uncovered",
                                          "nd_sets", "nd_local", "nd_weak_motion", "nd_global", "identity"});
}

TEST_CASE("local non-degeneracy: a box seen face-on fails, a corner view passes") {
  const Eigen::Vector3d size(0.2, 0.1, 0.3);
  const ObjectSpec spec = Spec("box", 0.5 * Eigen::Matrix3d(size.asDiagonal()), 0.01, 0.01);
  ObjectModelOptions model_options;
  model_options.sample_size = 20000;
  const ObjectModel box(spec, test::BoxMesh({0, 0, 0}, size), model_options);
  const PointSet surface = SampleSurface(box.mesh(), 6000, 2);
  std::vector<Eigen::Index> face, corner;
  for (Eigen::Index i = 0; i < surface.cols(); ++i) {
    const Eigen::Vector3d p = surface.col(i);
    const bool on_z = std::abs(p.z() - 0.15) < 1e-9, on_x = std::abs(p.x() - 0.1) < 1e-9, on_y = std::abs(p.y() - 0.05) < 1e-9;
    if (on_z) face.push_back(i);
    if (on_z || on_x || on_y) corner.push_back(i);
  }
  const CertificateOptions options = CertificateOptions::FromObject(spec);
  const NonDegeneracy face_on = CheckNonDegeneracy(box, Columns(surface, face), Pose(), options);
  CHECK_FALSE(face_on.passed);
  CHECK(face_on.local.min_eigenvalue < 1e-6);
  // The unseen motions are in-plane: v_z = 0 and ω_x = ω_y = 0.
  CHECK(std::abs(face_on.local.motion(5)) < 1e-6);
  const NonDegeneracy corner_view = CheckNonDegeneracy(box, Columns(surface, corner), Pose(), options);
  CHECK(corner_view.passed);
  CHECK(corner_view.local.min_eigenvalue > kDefaultLocalNdMinEigenvalue);
}

TEST_CASE("local non-degeneracy: a body of revolution's spin is a harmless symmetry") {
  const ObjectSpec spec = Spec("cylinder", Eigen::Matrix3d::Identity() * 0.03, 0.005, 0.005);
  ObjectModelOptions model_options;
  model_options.sample_size = 20000;
  const ObjectModel cylinder(spec, CylinderMesh(0.04, 0.12, 512), model_options);
  const PointSet surface = SampleSurface(cylinder.mesh(), 6000, 3);
  std::vector<Eigen::Index> half;   // the side facing +x and the top cap
  for (Eigen::Index i = 0; i < surface.cols(); ++i) {
    if (surface(0, i) > 0.0 || surface(2, i) > 0.06 - 1e-9) half.push_back(i);
  }
  const NonDegeneracy nd = CheckNonDegeneracy(cylinder, Columns(surface, half), Pose(), CertificateOptions::FromObject(spec));
  CHECK(nd.local.model_rank == 5);
  CHECK(nd.passed);
  // The side alone (no cap) leaves sliding along the axis unseen: fails.
  std::vector<Eigen::Index> side;
  for (Eigen::Index i : half) {
    if (std::abs(surface(2, i)) < 0.06 - 1e-9) side.push_back(i);
  }
  CHECK_FALSE(CheckNonDegeneracy(cylinder, Columns(surface, side), Pose(), CertificateOptions::FromObject(spec)).passed);
}

namespace {

// A bowl (YCB's 024_bowl is one): a spherical-cap shell 16 cm wide, 5.5 cm tall, with a wall of 3 mm -- thinner
// than the 10 000-point sample's spacing, so each sample's 8 nearest neighbours reach the other face.
Mesh BowlMesh() {
  const double R = 0.08, h = 0.055, wall = 0.003, foot = 0.03;
  const double c = (R * R + h * h) / (2 * h);   // sphere centre height (radius c) through the rim and the bottom
  std::vector<Eigen::Vector2d> profile{{0.0, 0.0}, {foot, 0.0}};
  const double a0 = std::asin(foot / c), a1 = std::asin(R / c);
  for (int k = 1; k <= 24; ++k) {
    const double a = a0 + (a1 - a0) * k / 24;
    profile.emplace_back(c * std::sin(a), c - c * std::cos(a));
  }
  const double inner = c - wall, a1i = std::asin((R - wall) / inner);
  profile.emplace_back(R - wall, h);
  for (int k = 1; k < 24; ++k) {
    const double a = a1i * (1.0 - k / 24.0);
    profile.emplace_back(inner * std::sin(a), c - inner * std::cos(a));
  }
  profile.emplace_back(0.0, c - inner);
  return MakeRevolution(profile, 128);
}

}  // namespace

TEST_CASE("local non-degeneracy: a thin-walled bowl -- its two faces are no crease, its spin is harmless") {
  const ObjectSpec spec = Spec("bowl", Eigen::Matrix3d::Identity() * 0.05, 0.007, 0.0035);
  const ObjectModel bowl(spec, BowlMesh(), ObjectModelOptions{});
  // Brute force over 500 samples: how many have, among their 8 nearest, a normal facing the other way (the
  // other face of the wall)? Those a "> 30 degrees off" crease rule would all drop.
  const PointSet& sample = bowl.sample();
  const PointSet& normals = bowl.sample_normals();
  int opposite = 0, crease = 0, probed = 0;
  for (Eigen::Index i = 0; i < sample.cols(); i += sample.cols() / 500) {
    std::vector<std::pair<double, Eigen::Index>> by_distance;
    for (Eigen::Index j = 0; j < sample.cols(); ++j) by_distance.emplace_back((sample.col(j) - sample.col(i)).squaredNorm(), j);
    std::partial_sort(by_distance.begin(), by_distance.begin() + 9, by_distance.end());
    bool has_opposite = false;
    for (int k = 0; k < 9; ++k) has_opposite |= normals.col(by_distance[k].second).dot(normals.col(i)) < -std::cos(M_PI / 6);
    opposite += has_opposite;
    crease += bowl.sample_on_crease()[i];
    ++probed;
  }
  MESSAGE(opposite << " of " << probed << " samples see the other face among their 8 nearest; " << crease << " creases");
  CHECK(opposite > probed / 2);      // the case: a wall thinner than the sample's reach
  CHECK(crease < probed / 5);        // only the rim's and the foot's edges
  // A view from above and to the side: the inside and the outer wall facing the camera.
  const PointSet surface = SampleSurface(bowl.mesh(), 6000, 4);
  std::vector<Eigen::Index> seen, inside;
  const double c = (0.08 * 0.08 + 0.055 * 0.055) / (2 * 0.055);
  for (Eigen::Index i = 0; i < surface.cols(); ++i) {
    const Eigen::Vector3d p = surface.col(i);
    const Eigen::Vector3d centre_to_p = p - Eigen::Vector3d(0, 0, c);
    const bool on_inner_cap = std::abs(centre_to_p.norm() - (c - 0.003)) < 1e-4 && p.z() < 0.0549;
    const bool outer_facing = std::abs(centre_to_p.norm() - c) < 1e-4 && p.x() > 0.0;
    if (on_inner_cap) inside.push_back(i);
    if (on_inner_cap || outer_facing) seen.push_back(i);
  }
  const CertificateOptions options = CertificateOptions::FromObject(spec);
  const NonDegeneracy nd = CheckNonDegeneracy(bowl, Columns(surface, seen), Pose(), options);
  CHECK(nd.local.model_rank == 5);   // the spin about the axis moves no surface: excluded
  CHECK(nd.local.observed_points > static_cast<int>(seen.size()) / 2);
  CHECK(nd.passed);
  // The bottom of the inside alone (within 1 cm of the axis), a nearly flat dish: sliding along it and tilting
  // about the sphere's centre move no seen point -- the test can fail on this object.
  std::vector<Eigen::Index> bottom;
  for (Eigen::Index i : inside) {
    if (surface.col(i).head<2>().norm() < 0.01) bottom.push_back(i);
  }
  REQUIRE(bottom.size() > 10);
  const NonDegeneracy dish = CheckNonDegeneracy(bowl, Columns(surface, bottom), Pose(), options);
  CHECK_FALSE(dish.passed);
  CHECK(dish.local.min_eigenvalue < kDefaultLocalNdMinEigenvalue);
}

TEST_CASE("local non-degeneracy: m informative outliers cannot rescue a degenerate view") {
  const ObjectModel object = test::AsymmetricObject(20000);
  const PointSet surface = SampleSurface(object.mesh(), 20000, 4);
  std::vector<Eigen::Index> top, other;
  for (Eigen::Index i = 0; i < surface.cols(); ++i) {
    const Eigen::Vector3d p = surface.col(i);
    if (std::abs(p.z() - 0.03) < 1e-9 && p.x() < 0.035 && !(p.x() > -0.07 && p.x() < -0.03 && p.y() > 0.05)) top.push_back(i);
    else if (std::abs(p.x() + 0.1) < 1e-9 || std::abs(p.y() + 0.05) < 1e-9) other.push_back(i);
  }
  REQUIRE(top.size() > 300);
  REQUIRE(other.size() > 10);
  std::vector<Eigen::Index> kept(top.begin(), top.begin() + 300);
  kept.insert(kept.end(), other.begin(), other.begin() + 6);   // 6 points on two side faces
  const PointSet cloud = Columns(surface, kept);
  CertificateOptions options = WithBudget(object, Count(0));
  const double with_six = CheckNonDegeneracy(object, cloud, Pose(), options).local.eigenvalue_all_points;
  MESSAGE("lambda_min with the 6 points counted: " << with_six);
  options.max_outliers = Count(6);
  const NonDegeneracy robust = CheckNonDegeneracy(object, cloud, Pose(), options);
  CHECK(robust.local.min_eigenvalue < 1e-3);   // numerically 0 up to the sampled normals
  CHECK(robust.local.min_eigenvalue < 0.1 * with_six);
  CHECK_FALSE(robust.passed);
}

TEST_CASE("robust corrector objective: analytic gradient matches finite differences (tls, gm)") {
  const ObjectModel object = test::AsymmetricObject(100);   // sparse sample: stable neighbours
  Rng rng(3);
  Pose truth;
  truth.R = rng.Rotation();
  truth.t = {0.1, -0.1, 0.3};
  PointSet cloud(3, 34);
  for (int j = 0; j < 30; ++j) {
    cloud.col(j) = truth * Eigen::Vector3d(object.sample().col(3 * j)) + 0.001 * Eigen::Vector3d::Random();
  }
  // Four far points: beyond the truncation (tls weight 0), in gm's tail.
  for (int j = 30; j < 34; ++j) cloud.col(j) = truth.t + Eigen::Vector3d(0.3, 0.1 * (j - 30), 0.2);
  const PointSet y = PerturbKeypoints(truth * object.keypoints(), 0.02, 1.0, object.diameter(), rng);
  for (RobustLoss kernel : {RobustLoss::kTruncated, RobustLoss::kGemanMcClure}) {
    CAPTURE(ToString(kernel));
    CorrectorOptions options;
    options.robust_loss = kernel;
    options.robust_scale = 0.02;
    PointSet gradient;
    const CorrectorObjectiveTerms terms = EvaluateCorrectorObjective(object, cloud, y, options, &gradient);
    // Oracle of the value: the kernel applied to brute-force nearest distances.
    const PointSet posed = terms.scene_from_model * object.sample();
    double expected = 0.0;
    for (Eigen::Index j = 0; j < cloud.cols(); ++j) {
      expected += RobustRho(kernel, (posed.colwise() - cloud.col(j)).colwise().squaredNorm().minCoeff(), 0.02);
    }
    CHECK(terms.point_cloud_loss == doctest::Approx(expected / cloud.cols()));
    const double h = 1e-7;
    for (Eigen::Index i = 0; i < y.cols(); ++i) {
      for (int k = 0; k < 3; ++k) {
        PointSet plus = y, minus = y;
        plus(k, i) += h;
        minus(k, i) -= h;
        const double numeric = (EvaluateCorrectorObjective(object, cloud, plus, options).value -
                                EvaluateCorrectorObjective(object, cloud, minus, options).value) / (2 * h);
        CHECK(gradient(k, i) == doctest::Approx(numeric).epsilon(1e-4).scale(1e-3));
      }
    }
  }
  // The kernels' weights are their derivatives (finite differences in s).
  for (RobustLoss kernel : {RobustLoss::kNone, RobustLoss::kTruncated, RobustLoss::kGemanMcClure}) {
    for (double s : {1e-6, 1e-4, 3e-4, 1e-2}) {
      const double h = 1e-9;
      const double numeric = (RobustRho(kernel, s + h, 0.02) - RobustRho(kernel, s - h, 0.02)) / (2 * h);
      CHECK(RobustWeight(kernel, s, 0.02) == doctest::Approx(numeric).epsilon(1e-5));
    }
  }
}

namespace {

struct Scene {
  Pose truth;
  PointSet cloud;      // object points (bounded noise)
};

// A rendered depth view of `object` at a random pose, uniform noise of at
// most `noise` along each coordinate direction... bounded: |w| <= noise * sqrt(3).
Scene RenderScene(const ObjectModel& object, std::uint64_t seed, double noise, int points = 600) {
  Rng rng(seed);
  Scene scene;
  scene.truth.R = rng.Rotation();
  scene.truth.t = {rng.Uniform(-0.05, 0.05), rng.Uniform(-0.05, 0.05), rng.Uniform(0.6, 0.9)};
  DepthRenderer renderer(CameraIntrinsics{});
  renderer.Render(object.mesh(), scene.truth);
  DepthSampleOptions sample;
  sample.points = points;
  scene.cloud = renderer.SampleCloud(sample, rng);
  for (Eigen::Index j = 0; j < scene.cloud.cols(); ++j) {
    for (int a = 0; a < 3; ++a) scene.cloud(a, j) += rng.Uniform(-noise, noise);
  }
  return scene;
}

}  // namespace

TEST_CASE("robust corrector: no outliers = today's result, k <= budget outliers cost little") {
  const ObjectModel object = test::AsymmetricObject(8000);
  const double d = object.diameter();
  int trials = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    CAPTURE(seed);
    const Scene scene = RenderScene(object, seed, 0.0005);
    if (scene.cloud.cols() < 200) continue;
    ++trials;
    Rng rng(100 + seed);
    const PointSet detected = PerturbKeypoints(scene.truth * object.keypoints(), 0.1, 0.8, d, rng);
    for (CorrectorSolver solver : {CorrectorSolver::kFast, CorrectorSolver::kGradientDescent}) {
      CAPTURE(ToString(solver));
      CorrectorOptions plain;
      plain.solver = solver;
      CorrectorOptions robust = plain;
      robust.robust_loss = RobustLoss::kTruncated;
      const CorrectorResult clean_plain = CorrectKeypoints(object, scene.cloud, detected, plain);
      const CorrectorResult clean_robust = CorrectKeypoints(object, scene.cloud, detected, robust);
      REQUIRE(clean_plain.ok());
      REQUIRE(clean_robust.ok());
      CHECK(clean_robust.robust_scale == object.spec().eps_oc);
      const double inlier_rotation = RotationError(clean_plain.scene_from_model.R, scene.truth.R);
      const double inlier_translation = TranslationError(clean_plain.scene_from_model.t, scene.truth.t);
      // No outliers: the same pose within the noise.
      CHECK(RotationError(clean_robust.scene_from_model.R, clean_plain.scene_from_model.R) < 0.01);
      CHECK(TranslationError(clean_robust.scene_from_model.t, clean_plain.scene_from_model.t) < 0.002);
      // 2 % stray points (k = budget): the robust pose stays within the
      // inlier-only error + 0.6 degrees and 2 mm.
      Rng stray_rng(200 + seed);
      const int k = static_cast<int>(0.02 * scene.cloud.cols());
      const PointSet dirty = AddStrayPoints(scene.cloud, k, d, stray_rng);
      const CorrectorResult dirty_robust = CorrectKeypoints(object, dirty, detected, robust);
      REQUIRE(dirty_robust.ok());
      CHECK(RotationError(dirty_robust.scene_from_model.R, scene.truth.R) < inlier_rotation + 0.01);
      CHECK(TranslationError(dirty_robust.scene_from_model.t, scene.truth.t) < inlier_translation + 0.002);
      // Geman-McClure too.
      CorrectorOptions gm = robust;
      gm.robust_loss = RobustLoss::kGemanMcClure;
      const CorrectorResult dirty_gm = CorrectKeypoints(object, dirty, detected, gm);
      CHECK(RotationError(dirty_gm.scene_from_model.R, scene.truth.R) < inlier_rotation + 0.01);
    }
  }
  CHECK(trials >= 5);
}

TEST_CASE("soundness: no certificate for a pose beyond the bound when at most m points are outliers") {
  // Random rendered views with bounded noise, stray points and adversarial
  // outliers on the surface of a WRONG pose (together at most m); candidate
  // poses: the corrector from perturbed true keypoints, from the wrong pose's
  // keypoints, and the wrong pose itself. Every certified candidate must be
  // within eps_oc + eps_w (+ 2 eps_s for the sampled Hausdorff) of the truth.
  const ObjectModel object = test::AsymmetricObject(20000);
  const double d = object.diameter();
  const double noise = 0.001;                      // per coordinate
  const double eps_w = noise * std::sqrt(3.0);
  const double eps_s = 2.0 * object.SampleSpacing();
  const double bound = object.spec().eps_oc + eps_w + 2 * eps_s;
  const PointSet queries = StridedColumns(object.sample(), 3000);
  int certified = 0, candidates = 0, rival_searches = 0, rivals_found = 0;
  for (std::uint64_t seed = 1; seed <= 24; ++seed) {
    CAPTURE(seed);
    const Scene scene = RenderScene(object, 1000 + seed, noise, 500);
    if (scene.cloud.cols() < 100) continue;
    Rng rng(seed);
    const int m = static_cast<int>(0.04 * scene.cloud.cols());
    Pose wrong;
    const Eigen::Vector3d centre = scene.truth * Eigen::Vector3d(object.sample().rowwise().mean());
    const Eigen::Matrix3d turn = rng.RotationUpTo(M_PI);
    wrong.R = turn * scene.truth.R;
    wrong.t = turn * (scene.truth.t - centre) + centre + 0.01 * rng.UnitVector();
    // Adversarial outliers: m/2 points on the wrong pose's surface, near the cloud.
    const PointSet wrong_surface = wrong * SampleSurface(object.mesh(), 4 * m, seed);
    PointSet cloud = AddStrayPoints(scene.cloud, m - m / 2, d, rng);
    PointSet with_adversarial(3, cloud.cols() + m / 2);
    with_adversarial << cloud, wrong_surface.leftCols(m / 2);
    cloud = with_adversarial;
    CertificateOptions options = WithBudget(object, Count(m));
    CorrectorOptions corrector;
    corrector.robust_loss = RobustLoss::kTruncated;
    std::vector<std::pair<Pose, PointSet>> poses;
    for (const PointSet& start : {PerturbKeypoints(scene.truth * object.keypoints(), 0.2, 0.8, d, rng),
                                  PointSet(wrong * object.keypoints())}) {
      const CorrectorResult result = CorrectKeypoints(object, cloud, start, corrector);
      if (result.ok()) poses.push_back({result.scene_from_model, result.keypoints});
    }
    poses.push_back({wrong, wrong * object.keypoints()});
    // The whole certificate, with the global rival search (pipeline.hpp).
    PipelineOptions pipeline;
    pipeline.corrector = corrector;
    pipeline.certificate = options;
    for (const auto& [pose, keypoints] : poses) {
      ++candidates;
      PoseEstimate estimate;
      estimate.scene_from_model = pose;
      estimate.keypoints = keypoints;
      estimate.certificate = Certify(object, cloud, pose, keypoints, options);
      CompleteCertificate(object, cloud, pipeline, nullptr, &estimate);
      if (estimate.certificate.nd.global_checked) {
        ++rival_searches;
        rivals_found += estimate.certificate.nd.global.rivals_found > 0;
      }
      CHECK(RefusedBy(estimate.certificate).empty() == estimate.certified());
      if (!estimate.certified()) continue;
      ++certified;
      const double hausdorff = PosedModelHausdorff(object, queries, scene.truth, pose);
      CHECK(hausdorff < bound);
    }
  }
  MESSAGE("soundness: " << certified << " of " << candidates << " candidate poses certified; " << rival_searches
                         << " rival searches, " << rivals_found << " found a rival");
  CHECK(rival_searches >= certified);   // every certified pose went through the global search
  CHECK(candidates > 40);
  CHECK(certified > 10);   // the test must exercise certified poses, not only rejections
}
