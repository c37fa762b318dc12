#pragma once
// Synthetic data (docs/method.md "Data"): simulated clouds (uniform
// surface samples of the whole mesh) and rendered depth clouds (what a pinhole
// depth camera sees), each with its ground-truth pose and posed keypoints.
//
// Pose conventions (scene_from_model = camera_from_model; camera frame x
// right, y down, z forward; the object's "centre" is its bounding-box centre):
// - hard:  uniform random rotation; the centre at a depth z uniform in the
//          distance range, at an image position uniform over the image shrunk
//          by the projected radius d/2 (so the whole object is in view when it
//          fits).
// - easy:  rotation = Delta * R_ref with Delta a rotation by an angle uniform
//          in [0, 0.8] rad about a uniform axis; R_ref shows the object upright
//          (model +z up in the image) from azimuth -60 deg, elevation 30 deg
//          (a three-quarter view from above: three faces of a box visible).
//          Translation as for hard.
// - paper: the reference's convention, uniform rotation and the centre
//          uniform in [0,1]^3. For depth clouds the cube is placed in front of
//          the camera: centre = u + (-0.5, -0.5, distance_max), u ~ U[0,1]^3;
//          views with too few points are redrawn.
// The same pose samplers serve sim and depth clouds (for sim clouds the camera
// only defines where the object is).
//
// Distance range: default [0.5, 1.5] * D0 with D0 = fy * d / (0.4 * height),
// the distance at which the diameter spans 40 % of the image height.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "c3po/base/random.hpp"
#include "c3po/io/shard.hpp"
#include "c3po/base/types.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

enum class CloudKind { kSim, kDepth };
enum class PoseMode { kEasy, kHard, kPaper };
const char* ToString(CloudKind kind);
const char* ToString(PoseMode mode);
CloudKind ParseCloudKind(const std::string& text);   // "sim" | "depth"; throws InputError
PoseMode ParsePoseMode(const std::string& text);     // "easy" | "hard" | "paper"

struct PoseSamplerOptions {
  PoseMode mode = PoseMode::kHard;
  double distance_min = 0.0;   // depth of the object centre; both 0 = default range
  double distance_max = 0.0;
  double easy_max_angle = 0.8;                      // radians
  double reference_azimuth = -1.0471975511965976;   // -60 deg, from +x towards +y
  double reference_elevation = 0.5235987755982988;  // 30 deg above the x-y plane
  void Check() const;   // throws InputError
};

// [0.5, 1.5] * fy * d / (0.4 * height).
std::pair<double, double> DefaultDistanceRange(double diameter, const CameraIntrinsics& camera);
// camera_from_model rotation of the easy poses' reference view.
Eigen::Matrix3d ReferenceRotation(const PoseSamplerOptions& options);

// One camera_from_model pose (see the conventions above). `distance` is the
// resolved range; `kind` only matters for paper poses.
Pose SamplePose(const PoseSamplerOptions& options, const CameraIntrinsics& camera,
                std::pair<double, double> distance, const Eigen::Vector3d& model_centre,
                double diameter, CloudKind kind, Rng& rng);

struct SynthOptions {
  CloudKind kind = CloudKind::kSim;
  int count = 1;                 // clouds to make
  int points = 1000;             // n (depth: fewer when fewer pixels are covered)
  PoseSamplerOptions pose;
  CameraIntrinsics camera;
  double noise = 0.0;            // sim: Gaussian sigma per coordinate; depth: of the depth z
  double dropout = 0.0;          // each point dropped with this probability, in [0, 1)
  int min_points = -1;           // depth: views with fewer points are redrawn; -1 = points / 2
  bool perturb = false;          // write detected_keypoints (paper's corrector experiment)
  double perturb_sigma = 0.0;    // noise uniform in [-sigma d / 2, sigma d / 2] per coordinate
  double perturb_fraction = 0.8; // probability that a keypoint is perturbed
  double visibility_tolerance = -1.0;   // object units; -1 = 1 % of d
  int max_attempts = 1000;       // depth: views drawn per cloud before giving up
  std::uint64_t seed = 0;
  // --shard K/N: write only samples [floor((K-1) count / N), floor(K count / N))
  // under their global names; `c3po merge` joins the parts into the dataset
  // the unsharded run writes.
  Shard shard;
  void Check() const;            // throws InputError("--flag: problem")
  int ResolvedMinPoints() const { return min_points >= 0 ? min_points : points / 2; }
};

struct SynthSample {
  PointSet cloud;                             // scene (camera) frame
  Pose scene_from_model;
  PointSet keypoints;                         // posed, 3 x N
  std::optional<PointSet> detected_keypoints; // when options.perturb
  std::optional<std::vector<bool>> visible;   // depth clouds
  int attempts = 1;                           // views drawn (depth)
};

// Makes samples of one object; Generate(i) is a pure function of
// (options.seed, i), so parallel runs are byte-identical to serial ones.
// The paper's keypoint perturbation (Section VIII-A): each keypoint, with
// probability `fraction`, moves by noise uniform in [-sigma d/2, sigma d/2]
// per coordinate. Draws 4 numbers per keypoint whether perturbed or not.
PointSet PerturbKeypoints(const PointSet& keypoints, double sigma, double fraction, double diameter, Rng& rng);

class SynthGenerator {
 public:
  // `where` names the object in error messages. Throws InputError for a mesh
  // without triangles, non-finite vertices or bad options. `mesh` must outlive
  // the generator.
  SynthGenerator(const Mesh& mesh, PointSet keypoints, const SynthOptions& options,
                 std::string where = "object");

  // `renderer` (one per thread, from MakeRenderer) is required for depth clouds.
  SynthSample Generate(std::size_t index, DepthRenderer* renderer) const;
  std::unique_ptr<DepthRenderer> MakeRenderer() const;

  const SynthOptions& options() const { return options_; }
  double diameter() const { return diameter_; }
  std::pair<double, double> distance_range() const { return distance_; }

 private:
  PointSet SampleSurfacePoints(int count, Rng& rng) const;
  SynthSample GenerateSim(Rng& rng) const;
  SynthSample GenerateDepth(Rng& rng, DepthRenderer* renderer) const;
  void Perturb(SynthSample* sample, Rng& rng) const;
  void BuildAliasTable();

  const Mesh& mesh_;
  PointSet keypoints_;
  SynthOptions options_;
  std::string where_;
  double diameter_ = 0.0;
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  std::pair<double, double> distance_{0.0, 0.0};
  std::vector<double> cumulative_area_;     // per triangle
  std::vector<double> alias_probability_;  // alias table for area-weighted sampling
  std::vector<int> alias_;
  bool cull_back_faces_ = false;           // the mesh is closed and outward
};

struct SynthReport {
  std::size_t count = 0;
  double seconds = 0.0;
  double mean_points = 0.0;
  int min_cloud_points = 0;
  int max_cloud_points = 0;
  double mean_attempts = 1.0;             // depth: views drawn per accepted cloud
  double visible_keypoint_fraction = 1.0; // depth: mean fraction of visible keypoints
  std::pair<double, double> distance_range{0.0, 0.0};
  double diameter = 0.0;
};

using SynthProgress = std::function<void(std::size_t done, std::size_t total)>;

// Generates options.count samples on all cores and writes them with
// DatasetWriter to `dir` (000000.ply ..., manifest.jsonl), committing only when
// complete. `progress` is called from the calling thread between batches.
// `where` names the object in messages (default: spec.name). Throws
// InputError (nothing left behind) or Interrupted.
SynthReport WriteSynthDataset(const Mesh& mesh, const ObjectSpec& spec,
                              const SynthOptions& options, const std::string& dir,
                              const SynthProgress& progress = {}, const std::string& where = "");

// Speed of cloud generation (no file output): repeats batches of
// options.count clouds on all cores until `min_seconds` have passed.
struct SynthBenchmark {
  CloudKind kind = CloudKind::kSim;
  std::size_t clouds = 0;
  int threads = 1;
  long triangles = 0;
  double seconds = 0.0;
  double clouds_per_second = 0.0;
  double mean_points = 0.0;
  double mean_attempts = 1.0;
};
SynthBenchmark BenchmarkSynth(const Mesh& mesh, const PointSet& keypoints,
                              const SynthOptions& options, double min_seconds = 2.0);

}  // namespace c3po
