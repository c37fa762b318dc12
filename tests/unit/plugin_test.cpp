// Detector registry and the shared-library plugin loader (plugin_api.h), with
// the test plugins built in tests/targets/test_plugin/.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "asymmetric_object.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/plugins/registry.hpp"
#include "c3po/plugins/svd_detector.hpp"
#include "test_helpers.hpp"

using namespace c3po;

namespace {

const DetectorInfo* FindInfo(const std::vector<DetectorInfo>& infos, const std::string& name) {
  for (const DetectorInfo& info : infos) {
    if (info.name == name) return &info;
  }
  return nullptr;
}

std::string InputErrorMessage(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Oracle of the "centroid" test plugin: model keypoints moved by the
// difference of the cloud centroid and the keypoint centroid.
PointSet CentroidOracle(const PointSet& keypoints, const PointSet& cloud) {
  const Eigen::Vector3d shift = cloud.rowwise().mean() - keypoints.rowwise().mean();
  return keypoints.colwise() + shift;
}

}  // namespace

// Runs first (doctest orders test cases by line): nothing has touched the
// registry yet, so this checks that the built-ins registered on first use do
// not silently replace a plugin that was loaded before them.
TEST_CASE("a plugin loaded before first registry use may replace a built-in detector") {
  LoadPlugin(C3PO_TEST_PLUGIN_NAMED_SVD);
  const ObjectModel object = test::AsymmetricObject(1000);
  const auto detector = CreateDetector("svd", object);
  const PointSet cloud = SampleSurface(object.mesh(), 200, 3);
  CHECK(detector->Detect(cloud).isApprox(CentroidOracle(object.keypoints(), cloud), 1e-12));
  const std::vector<DetectorInfo> infos = ListDetectors();   // outlives `info`
  const DetectorInfo* info = FindInfo(infos, "svd");
  REQUIRE(info != nullptr);
  CHECK(Contains(info->description, C3PO_TEST_PLUGIN_NAMED_SVD));

  // Put the built-in back for the other test cases.
  RegisterDetector({"svd", "built-in (restored by the test)", false},
                   [](const ObjectModel& model) -> std::unique_ptr<Detector> {
                     return std::make_unique<SvdDetector>(model);
                   });
}

TEST_CASE("the registry lists the built-in svd detector and creates it") {
  const std::vector<DetectorInfo> infos = ListDetectors();
  const DetectorInfo* svd = FindInfo(infos, "svd");
  REQUIRE(svd != nullptr);
  CHECK_FALSE(svd->needs_model_file);

  const ObjectModel object = test::AsymmetricObject(2000);
  const auto detector = CreateDetector("svd", object);
  REQUIRE(detector != nullptr);
  CHECK(detector->name() == "svd");
  CHECK(detector->num_keypoints() == object.num_keypoints());
  Rng rng(4);
  const Pose truth{rng.Rotation(), Eigen::Vector3d(0.1, 0.2, 0.7)};
  const PointSet keypoints = detector->Detect(truth * SampleSurface(object.mesh(), 600, 21));
  CHECK((keypoints - truth * object.keypoints()).colwise().norm().maxCoeff() < 0.02 * object.diameter());
}

TEST_CASE("unknown detector names are an InputError listing the known ones") {
  const ObjectModel object = test::AsymmetricObject(1000);
  const std::string message = InputErrorMessage([&] { CreateDetector("no-such-detector", object); });
  CHECK(Contains(message, "no-such-detector"));
  CHECK(Contains(message, "svd"));
}

TEST_CASE("LoadPlugin loads the centroid test plugin and its detector works") {
  LoadPlugin(C3PO_TEST_PLUGIN);
  const std::vector<DetectorInfo> infos = ListDetectors();   // outlives `info`
  const DetectorInfo* info = FindInfo(infos, "centroid");
  REQUIRE(info != nullptr);
  CHECK_FALSE(info->needs_model_file);
  CHECK(Contains(info->description, C3PO_TEST_PLUGIN));

  const ObjectModel object = test::AsymmetricObject(1000);
  const auto detector = CreateDetector("centroid", object);
  CHECK(detector->name() == "centroid");
  CHECK(detector->num_keypoints() == object.num_keypoints());

  std::vector<PointSet> clouds;
  Rng rng(8);
  for (int i = 0; i < 12; ++i) {
    const Pose pose{rng.Rotation(), Eigen::Vector3d(rng.Uniform(), rng.Uniform(), rng.Uniform())};
    clouds.push_back(pose * SampleSurface(object.mesh(), 50 + 10 * i, 100 + i));
  }
  const std::vector<PointSet> batch = detector->DetectBatch(clouds);   // both cores
  REQUIRE(batch.size() == clouds.size());
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    CAPTURE(i);
    CHECK(batch[i].isApprox(CentroidOracle(object.keypoints(), clouds[i]), 1e-12));
    CHECK(detector->Detect(clouds[i]) == batch[i]);
  }

  // A failure reported by the plugin becomes an InputError with its reason.
  const std::string message = InputErrorMessage([&] { detector->Detect(PointSet(3, 0)); });
  CHECK(Contains(message, "centroid"));
  CHECK(Contains(message, "empty cloud"));

  // Loading the same library again is harmless; the detector stays usable.
  CHECK_NOTHROW(LoadPlugin(C3PO_TEST_PLUGIN));
  CHECK(detector->Detect(clouds[0]) == batch[0]);
}

TEST_CASE("LoadPlugin takes a bare file name as a file in the working directory") {
  const std::filesystem::path plugin(C3PO_TEST_PLUGIN);
  const std::filesystem::path previous = std::filesystem::current_path();
  std::filesystem::current_path(plugin.parent_path());
  std::string message = "not thrown";
  try {
    LoadPlugin(plugin.filename().string());   // not searched on the library path
    message.clear();
  } catch (const InputError& error) {
    message = error.what();
  }
  std::filesystem::current_path(previous);
  CHECK(message.empty());
  CHECK(FindInfo(ListDetectors(), "centroid") != nullptr);
}

TEST_CASE("LoadPlugin rejects what is not a c3po plugin, naming the file") {
  SUBCASE("a library without the entry point") {
    const std::string message = InputErrorMessage([] { LoadPlugin(C3PO_TEST_NOT_A_PLUGIN); });
    CHECK(Contains(message, C3PO_TEST_NOT_A_PLUGIN));
    CHECK(Contains(message, "c3po_detector_plugin_v1"));
  }
  SUBCASE("a missing file") {
    for (const std::string path : {"/nonexistent/libnothing_here.so", "libnothing_here.so"}) {
      const std::string message = InputErrorMessage([&] { LoadPlugin(path); });
      CHECK(Contains(message, path));
      CHECK(Contains(message, "no such"));
    }
  }
  SUBCASE("a folder") {
    const std::string path = std::filesystem::path(C3PO_TEST_PLUGIN).parent_path().string();
    CHECK(Contains(InputErrorMessage([&] { LoadPlugin(path); }), path));
  }
  SUBCASE("a text file") {
    test::TempDir dir("plugin_test_text");
    const std::string path = dir / "libfake.so";
    std::ofstream(path) << "this is not a shared library\n";
    const std::string message = InputErrorMessage([&] { LoadPlugin(path); });
    CHECK(Contains(message, path));
  }
  SUBCASE("a plugin built for another ABI version") {
    const std::string message = InputErrorMessage([] { LoadPlugin(C3PO_TEST_PLUGIN_BAD_ABI); });
    CHECK(Contains(message, C3PO_TEST_PLUGIN_BAD_ABI));
    CHECK(Contains(message, "ABI"));
    CHECK(FindInfo(ListDetectors(), "bad_abi") == nullptr);
  }
}

TEST_CASE("pca is the training-free detector's name, svd stays an alias of it") {
  const std::vector<DetectorInfo> infos = ListDetectors();
  REQUIRE(FindInfo(infos, "pca") != nullptr);
  REQUIRE(FindInfo(infos, "svd") != nullptr);
  const ObjectModel object = test::AsymmetricObject(2000);
  Pose pose;
  pose.R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  pose.t = Eigen::Vector3d(0.1, -0.2, 0.5);
  const PointSet cloud = pose * SampleSurface(object.mesh(), 500, 11);
  const PointSet by_pca = CreateDetector("pca", object)->Detect(cloud);
  const PointSet by_svd = CreateDetector("svd", object)->Detect(cloud);
  CHECK((by_pca - by_svd).norm() == 0.0);
  // Same detector: it finds the pose of this asymmetric object.
  CHECK((by_pca - pose * object.keypoints()).cwiseAbs().maxCoeff() < 0.05 * object.diameter());
}
