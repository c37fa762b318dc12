#pragma once
// Synthetic BOP datasets (docs/synth_bop.md): rendered scenes with known
// truth in the layout of the BOP benchmark
// (bop_toolkit/docs/bop_datasets_format.md), with optional depth-sensor artefacts
// (depth_artefacts.hpp).
//
// Each image shows the target object (gt_id 0) and `distractors` further
// instances (of the distractor objects, or of the target itself when none are
// given) in front of a background plane (a table, tilted by up to
// `max_table_tilt` about the camera x axis, behind every object by at least
// `background_gap` target diameters). Poses come from synth's pose sampler
// (synth.hpp: easy | hard, distance range); instances whose bounding spheres
// overlap are redrawn, and a whole image is redrawn until the target shows at
// least `min_visible_pixels` pixels and `min_visib_fract` of its silhouette.
//
// Output folder = a BOP split folder: DIR/{scene_id:06d}/ with
//   scene_camera.json   {"im_id": {"cam_K": [9, row-major], "depth_scale": s}}
//   scene_gt.json       {"im_id": [{"cam_R_m2c": [9, row-major], "cam_t_m2c": [3, mm], "obj_id": k}, ...]}
//   scene_gt_info.json  {"im_id": [{"bbox_obj", "bbox_visib", "px_count_all", "px_count_valid",
//                                   "px_count_visib", "visib_fract"}, ...]}
//   depth/{im_id:06d}.png                 uint16, value * depth_scale = mm, 0 = no measurement
//   mask/{im_id:06d}_{gt_id:06d}.png      8-bit, 255 = full silhouette
//   mask_visib/{im_id:06d}_{gt_id:06d}.png 8-bit, 255 = visible part (dilated when bleeding)
// plus DIR/synth_bop.json (how it was made; also marks the folder as
// replaceable by the next run). Image i is im_id i % images_per_scene of scene
// i / images_per_scene. scene_gt_info describes the truth: bboxes and pixel
// counts of the rendered (unbled) masks, px_count_valid counted on the written
// depth image; bbox_obj is clipped to the image; empty boxes are [-1,-1,-1,-1].
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "c3po/base/random.hpp"
#include "c3po/synth/depth_artefacts.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/geometry/render.hpp"
#include "c3po/geometry/scene_render.hpp"
#include "c3po/synth/synth.hpp"

namespace c3po {

// An object that may appear in the scenes; the mesh is in the scene's units.
struct SynthBopObject {
  const Mesh* mesh = nullptr;
  int obj_id = 1;
};

// YCB-Video's camera (BOP ycbv camera_uw.json): 640 x 480.
CameraIntrinsics YcbvCamera();

// The finest depth scale (mm per unit) of the series 0.1, 0.2, 0.5, 1, 2, 5,
// 10, ... at which 16-bit units hold depths up to far_mm (BOP datasets use
// 0.1 and 1). far_mm must be finite and > 0.
double FinestDepthScale(double far_mm);

struct BopSynthOptions {
  int count = 1;                   // images
  int images_per_scene = 1000;
  PoseSamplerOptions pose;         // kPaper is refused
  CameraIntrinsics camera = YcbvCamera();
  double units_to_mm = 1000.0;     // scene (object) units -> mm: 1000 for m, 1 for mm
  // mm per depth-image unit; 0 = auto: FinestDepthScale of the deepest
  // surface (0.1 = YCB-V's whenever it fits, e.g. every YCB object at its
  // default distance; the bundled chair at 3-9 m gets 0.2).
  double depth_scale = 0.0;
  int distractors = 0;             // further instances per image
  bool background = true;          // the table plane
  double max_table_tilt = 0.5235987755982988;   // 30 deg
  double background_gap = 0.2;     // least plane distance behind the objects, x target diameter
  double min_visib_fract = 0.5;    // of the target
  int min_visible_pixels = 200;    // of the target
  DepthArtefactOptions artefacts;
  int max_attempts = 1000;         // image draws before giving up
  std::uint64_t seed = 0;
  void Check() const;              // throws InputError("--flag: problem")
};

// What one image holds (pure function of (options.seed, index)).
struct SynthBopInstance {
  int obj_id = 0;
  Pose camera_from_model;              // scene units
  std::vector<std::uint8_t> mask;      // full silhouette, 0 / 255
  std::vector<std::uint8_t> mask_visib;   // visible part (after bleeding), 0 / 255
  // scene_gt_info
  std::array<int, 4> bbox_obj{-1, -1, -1, -1};
  std::array<int, 4> bbox_visib{-1, -1, -1, -1};
  long px_count_all = 0, px_count_valid = 0, px_count_visib = 0;
  double visib_fract = 0.0;
};

struct SynthBopImage {
  int scene_id = 0;
  int im_id = 0;
  int width = 0, height = 0;
  std::vector<std::uint16_t> depth;   // depth-image units (x depth_scale = mm)
  std::vector<SynthBopInstance> instances; // gt_id order; instances[0] is the target
  ArtefactCounts artefacts;
  long out_of_range = 0;              // pixels beyond 65535 depth units, written as 0
  int attempts = 1;
};

class BopSceneGenerator {
 public:
  // `target` and `distractor_objects` (may be empty: distractors are then
  // copies of the target) must outlive the generator. Throws InputError for
  // empty meshes or bad options.
  BopSceneGenerator(SynthBopObject target, std::vector<SynthBopObject> distractor_objects,
                    const BopSynthOptions& options, std::string where = "object");

  SynthBopImage Generate(std::size_t index, DepthRenderer* renderer) const;
  std::unique_ptr<DepthRenderer> MakeRenderer() const;

  const BopSynthOptions& options() const { return options_; }
  double diameter() const { return objects_[0].diameter; }
  std::pair<double, double> distance_range() const { return distance_; }

 private:
  struct Placed {
    SynthBopObject object;
    bool closed = false;
    double diameter = 0.0;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();   // bounding-box centre, model frame
  };
  // One draw of the scene's instances: the target, then distractors whose
  // bounding spheres keep clear of every instance placed before.
  struct Arrangement {
    std::vector<const Placed*> placed;   // [i] = the object of instances[i]
    std::vector<SceneInstance> instances;
  };
  Placed Prepare(const SynthBopObject& object) const;
  std::optional<Arrangement> Arrange(Rng& rng) const;

  BopSynthOptions options_;
  std::string where_;
  std::vector<Placed> objects_;   // [0] = target, then the distractor objects
  std::pair<double, double> distance_{0.0, 0.0};
};

struct BopSynthReport {
  std::size_t images = 0;
  std::size_t instances = 0;
  int scenes = 0;
  double seconds = 0.0;
  double mean_attempts = 0.0;
  double mean_target_visib_fract = 0.0;
  long target_visible_pixels_min = 0;
  long flying = 0, dropped = 0, bled = 0, out_of_range = 0;   // totals
  std::pair<double, double> distance_range{0.0, 0.0};
  double diameter = 0.0;
};

// Writes options.count images on all cores into the BOP split folder `dir`
// (published atomically: StagedFolder, marker synth_bop.json). `provenance`
// is stored in synth_bop.json (e.g. the object file and the command line's
// options). Throws InputError (nothing left behind) or Interrupted.
BopSynthReport WriteBopDataset(const BopSceneGenerator& generator, const std::string& dir,
                               const std::string& provenance_json = "{}",
                               const SynthProgress& progress = {});

// Speed: images/s of generation + PNG encoding (no file output), repeated in
// batches of options.count images until `min_seconds` have passed.
struct BopSynthBenchmark {
  std::size_t images = 0;
  int threads = 1;
  double seconds = 0.0;
  double images_per_second = 0.0;
  double mean_attempts = 0.0;
  double megabytes_per_image = 0.0;   // PNG bytes
};
BopSynthBenchmark BenchmarkBopSynth(const BopSceneGenerator& generator, double min_seconds = 2.0);

}  // namespace c3po
