// Round trip synth --format bop -> certify --bop (the c3po executable): every
// instance of the object gets a line with its ids, and every certified pose is
// correct, judged by the Hausdorff distance between the model posed at the
// ground truth and at the estimate (symmetry-aware by construction). Clean
// and realistic-artefact scenes of a bundled object; a YCB mesh when
// ../shared/data/ycb is there.
#include <doctest/doctest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "c3po/io/bop.hpp"
#include "c3po/geometry/distances.hpp"
#include "c3po/synth/synth_bop.hpp"
#include "c3po/object/object_io.hpp"
#include "test_helpers.hpp"

namespace {

using c3po::test::RunC3po;

c3po::Pose PoseOf(const nlohmann::json& R, const nlohmann::json& t) {
  c3po::Pose pose;
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) pose.R(r, k) = R.at(static_cast<std::size_t>(r)).at(static_cast<std::size_t>(k)).get<double>();
    pose.t[r] = t.at(static_cast<std::size_t>(r)).get<double>();
  }
  return pose;
}

struct RoundTrip {
  int lines = 0, certified = 0, errors = 0;
  double worst_certified = 0.0;   // largest Hausdorff of a certified pose, fraction of d
};

// synth --format bop into DIR, certify --bop with the svd detector, check ids
// and poses; `correct` = Hausdorff <= 10 % of d.
RoundTrip Run(const std::string& object_file, const std::string& dir, const std::string& synth_args,
              int expected_instances) {
  const c3po::ObjectModel object = c3po::LoadObject(object_file);
  const auto synth = RunC3po("synth " + object_file + " -o " + dir + "/split --format bop --obj-id 5 " + synth_args);
  REQUIRE_MESSAGE(synth.status == 0, synth.output);
  const auto certify = RunC3po("certify " + object_file + " --bop " + dir + "/split --obj-id 5 --detector svd --json -o " +
                               dir + "/out.jsonl");
  // 2: some instance had no usable segment (e.g. a sliver left visible by a
  // distractor, eroded away): it is an error line, the others go on.
  REQUIRE_MESSAGE((certify.status == 0 || certify.status == 1 || certify.status == 2), certify.output);
  std::ifstream in(dir + "/out.jsonl");
  std::string line;
  RoundTrip result;
  const c3po::PointSet model = c3po::StridedColumns(object.sample(), 2000);
  while (std::getline(in, line)) {
    const nlohmann::json j = nlohmann::json::parse(line);
    ++result.lines;
    CHECK(j.at("obj_id") == 5);
    CHECK(j.contains("scene_id"));
    CHECK(j.contains("im_id"));
    CHECK(j.contains("gt_id"));
    if (j.contains("error")) {
      ++result.errors;
      const std::string error = j.at("error").get<std::string>();
      CHECK_MESSAGE((error.find("no pixels") != std::string::npos || error.find("no valid depth") != std::string::npos ||
                     error.find("points left") != std::string::npos),
                    error);
      CHECK(j.contains("pixels"));   // the preprocessing counts say why
      continue;
    }
    if (!j.value("certified", false)) continue;
    ++result.certified;
    const c3po::Pose truth = PoseOf(j.at("gt_R"), j.at("gt_t"));
    const c3po::Pose estimate = PoseOf(j.at("R"), j.at("t"));
    const double hausdorff = c3po::HausdorffDistance(truth * model, estimate * model) / object.diameter();
    result.worst_certified = std::max(result.worst_certified, hausdorff);
    if (hausdorff > 0.10) FAIL_CHECK("false certificate: " << j.at("cloud") << " Hausdorff " << hausdorff << " d");
  }
  CHECK(result.lines == expected_instances);
  CHECK((certify.status == 2) == (result.errors > 0));
  MESSAGE(object_file << " (" << synth_args << "): " << result.certified << " of " << result.lines
                      << " certified (" << result.errors << " error lines), worst certified Hausdorff " << result.worst_certified << " d");
  return result;
}

}  // namespace

TEST_CASE("synth --format bop -> certify --bop: certified poses are correct (bundled drill)"
          * doctest::test_suite("heavy")) {  // left out of the sanitizer run (scripts/sanitize.sh)
  c3po::test::TempDir tmp("bop_round_trip");
  const std::string drill = c3po::test::SourceDir() + "/annotations/drill.json";
  // The drill with a box (obj_id 6) as a distractor that may hide part of it.
  const std::string box = c3po::test::SourceDir() + "/annotations/box.json:6";
  const RoundTrip clean =
      Run(drill, tmp / "clean", "--count 8 --distractors 1 --distractor " + box + " --distance 0.6,1.2 --seed 3", 8);
  CHECK(clean.certified >= 4);
  const RoundTrip real = Run(drill, tmp / "real",
                             "--count 8 --distractors 1 --distractor " + box +
                                 " --distance 0.6,1.2 --artefacts realistic --seed 4",
                             8);
  CHECK(real.certified >= 1);
}

TEST_CASE("synth --format bop -> certify --bop: a YCB mesh") {
  const std::string ycb = c3po::test::SharedData() + "/ycb/035_power_drill";
  if (!std::filesystem::exists(ycb + "/textured.obj")) {
    MESSAGE("skipped: " << ycb << " not found");
    return;
  }
  c3po::test::TempDir tmp("bop_round_trip_ycb");
  const auto annotate = RunC3po("annotate " + ycb + "/textured.obj -o " + (tmp / "drill.json") + " --from-json " + ycb +
                                "/keypoints.json --key farthest8");
  REQUIRE_MESSAGE(annotate.status == 0, annotate.output);
  const RoundTrip ycb_run = Run(tmp / "drill.json", tmp.path(),
                                "--count 6 --distance 0.6,1.2 --artefacts realistic --seed 5", 6);
  CHECK(ycb_run.lines == 6);
}

TEST_CASE("synth --format bop read by the BOP reader (ListBopInstances): instances, cameras, poses") {
  const c3po::ObjectModel drill = c3po::LoadObject(c3po::test::SourceDir() + "/annotations/drill.json");
  c3po::BopSynthOptions options;
  options.count = 5;
  options.images_per_scene = 3;
  options.distractors = 2;   // copies of the drill: three instances of obj 4 per image
  options.seed = 8;
  const c3po::BopSceneGenerator generator({&drill.mesh(), 4}, {}, options, "drill");
  c3po::test::TempDir tmp("bop_reader");
  c3po::WriteBopDataset(generator, tmp / "split");
  c3po::BopOptions read;
  read.obj_id = 4;
  const c3po::BopInstances listed = c3po::ListBopInstances(tmp / "split", read);
  REQUIRE(listed.instances.size() == 15);
  CHECK(listed.scene_dirs.size() == 2);
  auto renderer = generator.MakeRenderer();
  for (const c3po::BopInstance& instance : listed.instances) {
    const std::size_t index = static_cast<std::size_t>(instance.scene_id * 3 + instance.im_id);
    const c3po::SynthBopImage image = generator.Generate(index, renderer.get());
    REQUIRE(instance.gt_id < static_cast<int>(image.instances.size()));
    const c3po::Pose& truth = image.instances[static_cast<std::size_t>(instance.gt_id)].camera_from_model;
    REQUIRE(instance.ground_truth.has_value());
    CHECK((instance.ground_truth->R - truth.R).norm() < 1e-9);
    CHECK((instance.ground_truth->t - truth.t).norm() < 1e-9);
    CHECK(instance.camera.depth_scale == 0.1);
    CHECK(instance.camera.K.fx == options.camera.fx);
    CHECK(instance.camera.K.cy == options.camera.cy);
    CHECK(std::filesystem::exists(instance.depth_path));
    CHECK(std::filesystem::exists(instance.mask_path));
  }
}
