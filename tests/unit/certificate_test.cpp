// Certificates against hand-built cases with known answers.
#include <doctest/doctest.h>

#include "c3po/base/random.hpp"
#include "c3po/method/certificate.hpp"
#include "test_objects.hpp"

using namespace c3po;

namespace {

// A 0.2 x 0.1 x 0.3 box with its 8 corners as keypoints and the paper's 8
// "three visible faces" indicator sets: corner c with its 3 edge neighbours.
ObjectModel CornerBox() {
  const Eigen::Vector3d size(0.2, 0.1, 0.3);
  ObjectSpec spec;
  spec.name = "box";
  spec.keypoints.resize(3, 8);
  for (int i = 0; i < 8; ++i) {
    spec.keypoints.col(i) = 0.5 * Eigen::Vector3d((i & 1) ? 1 : -1, (i & 2) ? 1 : -1,
                                                  (i & 4) ? 1 : -1).cwiseProduct(size);
  }
  for (int c = 0; c < 8; ++c) spec.indicator_sets.push_back({c, c ^ 1, c ^ 2, c ^ 4});
  spec.eps_oc = 0.01;
  spec.delta_nd = 0.01;
  ObjectModelOptions options;
  options.sample_size = 20000;
  return ObjectModel(spec, test::BoxMesh({0, 0, 0}, size), options);
}

// Points of the box surface whose outward normal axis/sign is in `faces`
// (e.g. {+z}) — a view that sees exactly those faces.
PointSet FacePoints(const ObjectModel& box, const std::vector<Eigen::Vector3d>& faces) {
  std::vector<Eigen::Vector3d> kept;
  const Eigen::Vector3d half = 0.5 * Eigen::Vector3d(0.2, 0.1, 0.3);
  const PointSet sample = SampleSurface(box.mesh(), 4000, 9);
  for (Eigen::Index i = 0; i < sample.cols(); ++i) {
    const Eigen::Vector3d p = sample.col(i);
    for (const auto& normal : faces) {
      const int axis = normal.cwiseAbs().maxCoeff() == std::abs(normal.x()) ? 0 : (std::abs(normal.y()) > 0.5 ? 1 : 2);
      if (std::abs(p(axis) - normal(axis) * half(axis)) < 1e-9) {
        kept.push_back(p);
        break;
      }
    }
  }
  PointSet points(3, static_cast<Eigen::Index>(kept.size()));
  for (std::size_t i = 0; i < kept.size(); ++i) points.col(i) = kept[i];
  return points;
}

}  // namespace

TEST_CASE("observable correctness: the true pose passes, one far outlier fails") {
  // 20000 samples: sample spacing well below eps_oc (Theorem 12's eps_s).
  const ObjectModel object = test::AsymmetricObject(20000);
  Rng rng(1);
  Pose truth;
  truth.R = rng.Rotation();
  truth.t = {0.1, -0.2, 0.8};
  PointSet cloud = truth * SampleSurface(object.mesh(), 500, 42);
  const CertificateOptions options = CertificateOptions::FromObject(object.spec());
  const PointSet keypoints = truth * object.keypoints();

  const ObservableCorrectness good = CheckObservableCorrectness(object, cloud, truth, keypoints, options);
  CHECK(good.passed);
  CHECK(good.max_point_distance < options.eps_oc);
  CHECK(good.max_keypoint_distance == doctest::Approx(0.0).epsilon(1e-12));

  // Move one point 5 cm further from the object's centre (away from every surface).
  const Eigen::Vector3d centre = truth * Eigen::Vector3d(object.sample().rowwise().mean());
  cloud.col(17) += 0.05 * (cloud.col(17) - centre).normalized();
  const ObservableCorrectness bad = CheckObservableCorrectness(object, cloud, truth, keypoints, options);
  CHECK_FALSE(bad.passed);
  CHECK(bad.worst_point == 17);
  // Oracle: brute-force distance of the moved point to the posed sample.
  const PointSet posed_sample = truth * object.sample();
  const double expected = std::sqrt((posed_sample.colwise() - cloud.col(17)).colwise().squaredNorm().minCoeff());
  CHECK(expected > 2 * options.eps_oc);
  CHECK(bad.max_point_distance == doctest::Approx(expected));

  SUBCASE("corrected keypoints that disagree with the posed model fail") {
    PointSet moved = keypoints;
    moved(0, 3) += 2 * options.eps_oc;
    const ObservableCorrectness r = CheckObservableCorrectness(object, cloud.leftCols(10), truth, moved, options);
    CHECK(r.max_keypoint_distance == doctest::Approx(2 * options.eps_oc));
    CHECK_FALSE(r.passed);
  }
  SUBCASE("a wrong pose fails") {
    Pose wrong = truth;
    wrong.t += Eigen::Vector3d(0.03, 0, 0);
    CHECK_FALSE(CheckObservableCorrectness(object, cloud.leftCols(200), wrong, wrong * object.keypoints(), options).passed);
  }
}

TEST_CASE("non-degeneracy: a box seen face-on fails, three faces pass") {
  const ObjectModel box = CornerBox();
  const CertificateOptions options = CertificateOptions::FromObject(box.spec());
  const Pose identity;
  const PointSet one_face = FacePoints(box, {{0, 0, 1}});
  const NonDegeneracy face_on = CheckNonDegeneracy(box, one_face, identity, options);
  CHECK_FALSE(face_on.passed);
  CHECK(face_on.passing_set == -1);
  REQUIRE(face_on.set_worst_distance.size() == 8);
  for (double worst : face_on.set_worst_distance) CHECK(worst >= options.delta_nd);

  const PointSet three_faces = FacePoints(box, {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}});
  const NonDegeneracy corner_view = CheckNonDegeneracy(box, three_faces, identity, options);
  CHECK(corner_view.passed);
  // Oracle: a corner is seen iff it lies on a visible face (+x, +y or +z, i.e.
  // one of its sign bits is set); the first set with all corners seen passes.
  int expected = -1;
  for (int c = 0; c < 8 && expected < 0; ++c) {
    bool all_seen = true;
    for (int k : box.spec().indicator_sets[c]) all_seen = all_seen && k != 0;
    if (all_seen) expected = c;
  }
  CHECK(corner_view.passing_set == expected);
  CHECK(expected == 3);
}

TEST_CASE("non-degeneracy: removing the handle's points flips nd") {
  // Body plus a small side 'handle' block; the handle keypoint alone is the
  // indicator set (the paper's mug).
  const Mesh mesh = test::MugLikeMesh();
  const ObjectSpec spec = test::MugLikeSpec();
  const ObjectModel mug(spec, mesh);
  const CertificateOptions options = CertificateOptions::FromObject(spec);
  const PointSet all = SampleSurface(mesh, 3000, 5);
  CHECK(CheckNonDegeneracy(mug, all, Pose(), options).passed);

  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < all.cols(); ++i) {
    if (all(0, i) < 0.04 + 1e-9) kept.push_back(i);   // drop everything of the handle
  }
  PointSet without_handle(3, static_cast<Eigen::Index>(kept.size()));
  for (std::size_t i = 0; i < kept.size(); ++i) without_handle.col(i) = all.col(kept[i]);
  const NonDegeneracy nd = CheckNonDegeneracy(mug, without_handle, Pose(), options);
  CHECK_FALSE(nd.passed);
  CHECK(nd.keypoint_distances(0) > options.delta_nd);
}

TEST_CASE("no indicator sets means nd = 1, empty cloud fails both") {
  const ObjectModel object = test::AsymmetricObject();
  const CertificateOptions options = CertificateOptions::FromObject(object.spec());
  CHECK(CheckNonDegeneracy(object, object.sample(), Pose(), options).passed);
  const Certificate empty = Certify(object, PointSet(3, 0), Pose(), object.keypoints(), options);
  CHECK_FALSE(empty.oc.passed);
  CHECK_FALSE(empty.nd.passed);
  CHECK_FALSE(empty.certified());
}

TEST_CASE("DistancesToCloud matches a brute-force double loop") {
  Rng rng(2);
  const PointSet queries = PointSet::Random(3, 7);
  const PointSet cloud = PointSet::Random(3, 50);
  const Eigen::VectorXd d = DistancesToCloud(queries, cloud);
  for (int i = 0; i < 7; ++i) {
    double best = 1e300;
    for (int j = 0; j < 50; ++j) best = std::min(best, (queries.col(i) - cloud.col(j)).norm());
    CHECK(d(i) == doctest::Approx(best));
  }
}
