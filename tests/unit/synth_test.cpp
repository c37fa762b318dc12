// Synthetic data: pose samplers, sim and depth samples, datasets
// (determinism, counts, manifest round trip, bad inputs), YCB meshes.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <tuple>

#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/io/mesh_io.hpp"
#include "c3po/object/procedural.hpp"
#include "c3po/synth/synth.hpp"
#include "test_helpers.hpp"

namespace fs = std::filesystem;

namespace {

double Angle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return std::acos(std::clamp(((a.transpose() * b).trace() - 1.0) / 2.0, -1.0, 1.0));
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// Largest distance of the points to the mesh posed by `pose`.
double MaxDistanceToPosedMesh(const c3po::Mesh& mesh, const c3po::Pose& pose,
                              const c3po::PointSet& points, int stride = 1) {
  const c3po::Mesh posed{pose * mesh.vertices, mesh.triangles};
  double worst = 0.0;
  for (Eigen::Index i = 0; i < points.cols(); i += stride) {
    worst = std::max(worst, c3po::ClosestSurfacePoint(posed, points.col(i)).distance);
  }
  return worst;
}

c3po::SynthOptions SmallOptions(c3po::CloudKind kind) {
  c3po::SynthOptions options;
  options.kind = kind;
  options.count = 24;
  options.points = 300;
  options.seed = 42;
  return options;
}

}  // namespace

TEST_CASE("hard, easy and paper poses follow their conventions") {
  const c3po::CameraIntrinsics camera;
  const Eigen::Vector3d centre(0.01, -0.02, 0.1);
  const double d = 0.2;
  const auto range = c3po::DefaultDistanceRange(d, camera);
  // D0: d spans 40 % of the image height.
  CHECK(camera.fy * d / ((range.first + range.second) / 2.0) ==
        doctest::Approx(0.4 * camera.height));
  CHECK(range.second == doctest::Approx(3.0 * range.first));
  c3po::Rng rng(1);
  c3po::PoseSamplerOptions options;
  for (const auto mode : {c3po::PoseMode::kHard, c3po::PoseMode::kEasy}) {
    options.mode = mode;
    double largest_angle = 0.0;
    for (int i = 0; i < 500; ++i) {
      const c3po::Pose pose =
          c3po::SamplePose(options, camera, range, centre, d, c3po::CloudKind::kDepth, rng);
      CHECK((pose.R.transpose() * pose.R - Eigen::Matrix3d::Identity()).norm() < 1e-12);
      CHECK(pose.R.determinant() == doctest::Approx(1.0));
      const Eigen::Vector3d c = pose * centre;
      CHECK(c.z() >= range.first);
      CHECK(c.z() <= range.second);
      // The bounding sphere of radius d/2 projects inside the image.
      const double u = camera.fx * c.x() / c.z() + camera.cx;
      const double v = camera.fy * c.y() / c.z() + camera.cy;
      const double r = camera.fx * 0.5 * d / c.z();
      CHECK(u - r >= -0.5 - 1e-9);
      CHECK(u + r <= camera.width - 0.5 + 1e-9);
      CHECK(v - r >= -0.5 - 1e-9);
      CHECK(v + r <= camera.height - 0.5 + 1e-9);
      largest_angle = std::max(largest_angle, Angle(pose.R, c3po::ReferenceRotation(options)));
    }
    if (mode == c3po::PoseMode::kEasy) {
      CHECK(largest_angle <= 0.8 + 1e-9);
      CHECK(largest_angle > 0.7);
    } else {
      CHECK(largest_angle > 2.5);   // hard poses reach far from the reference
    }
  }
  options.mode = c3po::PoseMode::kPaper;
  for (int i = 0; i < 200; ++i) {
    const c3po::Pose sim = c3po::SamplePose(options, camera, range, centre, d, c3po::CloudKind::kSim, rng);
    const Eigen::Vector3d c = sim * centre;
    CHECK((c.array() >= 0.0).all());
    CHECK((c.array() <= 1.0).all());
    const c3po::Pose depth =
        c3po::SamplePose(options, camera, range, centre, d, c3po::CloudKind::kDepth, rng);
    const Eigen::Vector3d cd = depth * centre;
    CHECK(cd.z() >= range.second);
    CHECK(cd.z() <= range.second + 1.0);
    CHECK(std::abs(cd.x()) <= 0.5);
  }
}

TEST_CASE("the easy reference view shows a box upright with three faces") {
  const c3po::BundledObject box = c3po::MakeBundledObject("box");
  c3po::PoseSamplerOptions options;
  const Eigen::Matrix3d R = c3po::ReferenceRotation(options);
  CHECK((R * Eigen::Vector3d::UnitZ()).y() < -0.5);   // model up is image up (y down)
  c3po::Pose pose;
  pose.R = R;
  pose.t = Eigen::Vector3d(0, 0, 1.0) - R * box.mesh.BoundingBox().center();
  c3po::DepthRenderer renderer(c3po::CameraIntrinsics{});
  renderer.Render(box.mesh, pose);
  std::set<std::tuple<int, int, int>> normals;
  for (const int pixel : renderer.covered_pixels()) {
    const int t = renderer.TriangleAt(pixel % 640, pixel / 640);
    const Eigen::Vector3d a = box.mesh.vertices.col(box.mesh.triangles(0, t));
    const Eigen::Vector3d n = (box.mesh.vertices.col(box.mesh.triangles(1, t)) - a)
                                  .cross(box.mesh.vertices.col(box.mesh.triangles(2, t)) - a)
                                  .normalized();
    normals.emplace(static_cast<int>(std::lround(n.x())), static_cast<int>(std::lround(n.y())),
                    static_cast<int>(std::lround(n.z())));
  }
  CHECK(normals.size() == 3);
  CHECK(normals.count({0, 0, 1}) == 1);   // the top
}

TEST_CASE("sim samples: n points on the posed surface, posed keypoints") {
  const c3po::BundledObject drill = c3po::MakeBundledObject("drill");
  const c3po::SynthOptions options = SmallOptions(c3po::CloudKind::kSim);
  const c3po::SynthGenerator generator(drill.mesh, drill.spec.keypoints, options, "drill");
  const double d = drill.mesh.Diameter();
  for (std::size_t i = 0; i < 3; ++i) {
    const c3po::SynthSample sample = generator.Generate(i, nullptr);
    CHECK(sample.cloud.cols() == 300);
    CHECK(MaxDistanceToPosedMesh(drill.mesh, sample.scene_from_model, sample.cloud) < 1e-9 * d);
    CHECK((sample.keypoints - sample.scene_from_model * drill.spec.keypoints).norm() < 1e-12);
    CHECK_FALSE(sample.visible.has_value());
    CHECK_FALSE(sample.detected_keypoints.has_value());
  }
  // Noise: points leave the surface by about sigma.
  c3po::SynthOptions noisy = options;
  noisy.noise = 0.002;
  const c3po::SynthSample sample =
      c3po::SynthGenerator(drill.mesh, drill.spec.keypoints, noisy).Generate(0, nullptr);
  CHECK(MaxDistanceToPosedMesh(drill.mesh, sample.scene_from_model, sample.cloud) > 0.002);
}

TEST_CASE("sim samples are uniform by area") {
  // Two parts of a box: the big +-y faces hold 2 * 0.16 * 0.22 of the area.
  const c3po::BundledObject box = c3po::MakeBundledObject("box");
  c3po::SynthOptions options = SmallOptions(c3po::CloudKind::kSim);
  options.points = 20000;
  options.pose.mode = c3po::PoseMode::kPaper;
  const c3po::SynthGenerator generator(box.mesh, box.spec.keypoints, options);
  const c3po::SynthSample sample = generator.Generate(0, nullptr);
  const c3po::PointSet model = sample.scene_from_model.InverseApply(sample.cloud);
  const Eigen::Vector3d size = box.mesh.BoundingBox().sizes();
  const double half_y = box.mesh.BoundingBox().max().y();
  int on_big_faces = 0;
  for (Eigen::Index i = 0; i < model.cols(); ++i) {
    on_big_faces += std::abs(std::abs(model(1, i)) - half_y) < 1e-12;
  }
  const double p = 2 * size.x() * size.z() / box.mesh.SurfaceArea();
  const double sd = std::sqrt(p * (1 - p) / 20000.0);
  CHECK(std::abs(on_big_faces / 20000.0 - p) < 5 * sd);
}

TEST_CASE("depth samples: on the posed surface, visible keypoints, min points") {
  const c3po::BundledObject mug = c3po::MakeBundledObject("mug");
  c3po::SynthOptions options = SmallOptions(c3po::CloudKind::kDepth);
  options.min_points = 250;
  const c3po::SynthGenerator generator(mug.mesh, mug.spec.keypoints, options, "mug");
  auto renderer = generator.MakeRenderer();
  const double d = mug.mesh.Diameter();
  int visible = 0, total = 0;
  for (std::size_t i = 0; i < 6; ++i) {
    const c3po::SynthSample sample = generator.Generate(i, renderer.get());
    CHECK(sample.cloud.cols() <= 300);
    CHECK(sample.cloud.cols() >= 250);
    CHECK(MaxDistanceToPosedMesh(mug.mesh, sample.scene_from_model, sample.cloud, 5) < 1e-9 * d);
    REQUIRE(sample.visible.has_value());
    REQUIRE(sample.visible->size() == 11);
    for (bool v : *sample.visible) visible += v;
    total += 11;
  }
  CHECK(visible > 0);
  CHECK(visible < total);   // a mug never shows rim, base and handle all at once
  // The same index gives the same sample; another index another one.
  const c3po::SynthSample a = generator.Generate(3, renderer.get());
  const c3po::SynthSample b = generator.Generate(3, generator.MakeRenderer().get());
  CHECK(a.cloud == b.cloud);
  CHECK(a.scene_from_model.R == b.scene_from_model.R);
  const c3po::PointSet other = generator.Generate(4, renderer.get()).cloud;
  CHECK((other.cols() != a.cloud.cols() || other != a.cloud));
}

TEST_CASE("perturbed detected keypoints: fraction and range") {
  const c3po::BundledObject chair = c3po::MakeBundledObject("chair");
  c3po::SynthOptions options = SmallOptions(c3po::CloudKind::kSim);
  options.perturb = true;
  options.perturb_sigma = 0.4;
  options.perturb_fraction = 0.6;
  options.points = 10;
  const c3po::SynthGenerator generator(chair.mesh, chair.spec.keypoints, options);
  const double half_width = 0.5 * 0.4 * chair.mesh.Diameter();
  int moved = 0, total = 0;
  for (std::size_t i = 0; i < 300; ++i) {
    const c3po::SynthSample sample = generator.Generate(i, nullptr);
    REQUIRE(sample.detected_keypoints.has_value());
    const c3po::PointSet offset = *sample.detected_keypoints - sample.keypoints;
    CHECK(offset.cwiseAbs().maxCoeff() <= half_width + 1e-12);
    for (Eigen::Index k = 0; k < offset.cols(); ++k) moved += offset.col(k).norm() > 0.0;
    total += static_cast<int>(offset.cols());
  }
  const double sd = std::sqrt(0.6 * 0.4 / total);
  CHECK(std::abs(static_cast<double>(moved) / total - 0.6) < 5 * sd);
}

TEST_CASE("datasets: counts, manifest round trip, same seed => same bytes") {
  const c3po::BundledObject box = c3po::MakeBundledObject("box");
  c3po::test::TempDir dir("synth_dataset");
  c3po::SynthOptions options = SmallOptions(c3po::CloudKind::kDepth);
  options.perturb = true;
  options.perturb_sigma = 0.2;
  options.noise = 0.001;
  const c3po::SynthReport report = c3po::WriteSynthDataset(box.mesh, box.spec, options, dir / "a");
  CHECK(report.count == 24);
  c3po::WriteSynthDataset(box.mesh, box.spec, options, dir / "b");
  const c3po::Dataset a = c3po::ReadDataset(dir / "a");
  REQUIRE(a.entries.size() == 24);
  CHECK(a.HasGroundTruth());
  CHECK(ReadBytes(dir / "a/manifest.jsonl") == ReadBytes(dir / "b/manifest.jsonl"));
  const c3po::SynthGenerator generator(box.mesh, box.spec.keypoints, options);
  auto renderer = generator.MakeRenderer();
  for (std::size_t i = 0; i < a.entries.size(); ++i) {
    CAPTURE(i);
    const auto& entry = a.entries[i];
    CHECK(ReadBytes(a.CloudPath(i)) == ReadBytes(dir / ("b/" + entry.cloud)));
    // The dataset holds exactly what the generator makes for item i.
    const c3po::SynthSample sample = generator.Generate(i, renderer.get());
    REQUIRE(entry.pose.has_value());
    CHECK((entry.pose->R - sample.scene_from_model.R).norm() < 1e-12);
    CHECK((entry.pose->t - sample.scene_from_model.t).norm() < 1e-12);
    CHECK((*entry.keypoints - sample.keypoints).norm() < 1e-12);
    CHECK((*entry.keypoints - *entry.pose * box.spec.keypoints).norm() < 1e-12);
    CHECK((*entry.detected_keypoints - *sample.detected_keypoints).norm() < 1e-12);
    CHECK(*entry.visible == *sample.visible);
    const c3po::PointSet cloud = a.LoadCloud(i);
    REQUIRE(cloud.cols() == sample.cloud.cols());
    CHECK((cloud - sample.cloud).cwiseAbs().maxCoeff() < 1e-6);   // float PLY
    CHECK(cloud.cols() >= options.ResolvedMinPoints());
  }
  options.seed = 43;
  c3po::WriteSynthDataset(box.mesh, box.spec, options, dir / "c");
  CHECK(ReadBytes(dir / "a/manifest.jsonl") != ReadBytes(dir / "c/manifest.jsonl"));
}

TEST_CASE("bad inputs throw InputError and leave no dataset behind") {
  const c3po::BundledObject box = c3po::MakeBundledObject("box");
  c3po::test::TempDir dir("synth_bad");
  c3po::SynthOptions options = SmallOptions(c3po::CloudKind::kDepth);
  const auto leaves_nothing = [&](const c3po::Mesh& mesh, const c3po::SynthOptions& o,
                                  const std::string& out) {
    CHECK_THROWS_AS(c3po::WriteSynthDataset(mesh, box.spec, o, out), c3po::InputError);
    CHECK_FALSE(fs::exists(out));
  };
  c3po::Mesh empty;
  empty.vertices.resize(3, 3);
  empty.vertices.setZero();
  empty.triangles.resize(3, 0);
  leaves_nothing(empty, options, dir / "empty_mesh");
  c3po::SynthOptions zero = options;
  zero.count = 0;
  leaves_nothing(box.mesh, zero, dir / "zero");
  c3po::SynthOptions too_many = options;
  too_many.min_points = options.points + 1;
  leaves_nothing(box.mesh, too_many, dir / "min_points");
  // A view can never have this many points: far away, tiny.
  c3po::SynthOptions far = options;
  far.points = 5000;
  far.min_points = 5000;
  far.pose.distance_min = 40.0;
  far.pose.distance_max = 50.0;
  far.max_attempts = 5;
  leaves_nothing(box.mesh, far, dir / "far");
  // Unwritable: the parent is a regular file.
  std::ofstream(dir / "file") << "x";
  leaves_nothing(box.mesh, options, dir / "file/sub");
  // Interrupted runs leave nothing either.
  c3po::RequestInterrupt();
  CHECK_THROWS_AS(c3po::WriteSynthDataset(box.mesh, box.spec, options, dir / "interrupted"),
                  c3po::Interrupted);
  c3po::ClearInterrupt();
  CHECK_FALSE(fs::exists(dir / "interrupted"));
  std::size_t left = 0;
  for (const auto& item : fs::directory_iterator(dir.path())) left += item.path().filename() != "file";
  CHECK(left == 0);   // no temporary folders either
}

TEST_CASE("synth on the shared YCB meshes") {
  if (!c3po::test::HaveSharedYcb()) {
    MESSAGE("skipping: " << c3po::test::SharedData() << "/ycb not found");
    return;
  }
  for (const char* name : {"035_power_drill", "006_mustard_bottle"}) {
    CAPTURE(name);
    const std::string path = c3po::test::SharedData() + "/ycb/" + name + "/textured.obj";
    if (!fs::exists(path)) {
      MESSAGE("skipping " << path << ": not found");
      continue;
    }
    const c3po::Mesh mesh = c3po::LoadMesh(path);
    const double d = mesh.Diameter();
    const c3po::PointSet keypoints = c3po::SampleSurface(mesh, 8, 1);
    for (const auto kind : {c3po::CloudKind::kSim, c3po::CloudKind::kDepth}) {
      c3po::SynthOptions options = SmallOptions(kind);
      options.points = 1000;
      const c3po::SynthGenerator generator(mesh, keypoints, options, name);
      auto renderer = generator.MakeRenderer();
      const c3po::SynthSample sample = generator.Generate(0, renderer.get());
      CHECK(sample.cloud.cols() >= 500);
      CHECK(MaxDistanceToPosedMesh(mesh, sample.scene_from_model, sample.cloud, 20) < 1e-6 * d);
    }
  }
}
