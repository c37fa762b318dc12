#pragma once
// BOP datasets (Benchmark for 6D Object Pose Estimation;
// bop_toolkit/docs/bop_datasets_format.md) as c3po inputs and outputs (issue 15,
// docs/camera_inputs.md):
//  - a scene folder NNNNNN/ with scene_camera.json, depth/{im_id:06d}.png,
//    mask_visib/ (or mask/) {im_id:06d}_{gt_id:06d}.png, optional
//    scene_gt.json (per image a list of {obj_id, cam_R_m2c row-major,
//    cam_t_m2c mm}; the list index is gt_id), or a split folder of such scenes;
//  - test_targets_bop19.json-style targets ({scene_id, im_id, obj_id,
//    inst_count} list) restricting the images;
//  - detections JSON (BOP/COCO: a list of {scene_id, image_id, category_id,
//    score, bbox, segmentation: COCO RLE}) instead of ground-truth masks;
//  - models_info.json (diameter in mm, symmetries);
//  - the BOP results CSV.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "c3po/io/camera_io.hpp"
#include "c3po/io/rle.hpp"
#include "c3po/io/segment.hpp"
#include "c3po/base/types.hpp"

namespace c3po {

// A ground-truth pose from scene_gt.json: camera_from_model in metres.
// Ground truth is only ever reported (never used to certify), so a pose that is
// not one -- a rotation not orthonormal within kDatasetRotationTolerance
// (1e-3, rotation.hpp; projected onto SO(3) within it), non-finite or
// missing numbers -- does not stop a run: camera_from_model is nullopt and
// `problem` says why ("1[0]: cam_R_m2c: not orthonormal (...)").
struct BopGroundTruth {
  int obj_id = 0;
  std::optional<Pose> camera_from_model;
  std::string problem;
};
// scene_gt.json: im_id -> list (index = gt_id). InputError for what the
// listing needs: the document's structure, image keys, obj_id.
std::map<int, std::vector<BopGroundTruth>> ParseSceneGt(const std::string& text, const std::string& name);

struct BopDetection {
  int scene_id = 0, image_id = 0, category_id = 0;
  double score = 0.0;
  double time = -1.0;            // seconds, when the file gives it
  int height = 0, width = 0;     // segmentation size
  RleCounts counts;              // decoded (compressed strings are parsed)
};
std::vector<BopDetection> ParseDetections(const std::string& text, const std::string& name);

struct BopTarget {
  int scene_id = 0, im_id = 0, obj_id = 0, inst_count = 0;
};
std::vector<BopTarget> ParseTargets(const std::string& text, const std::string& name);

struct BopModelInfo {
  double diameter_mm = 0.0;
  int discrete_symmetries = 0;     // number of symmetries_discrete entries
  bool continuous_symmetry = false;
};
std::map<int, BopModelInfo> ParseModelsInfo(const std::string& text, const std::string& name);

struct BopOptions {
  int obj_id = -1;                 // required, >= 0
  std::string targets_path;        // optional
  std::string detections_path;     // optional: masks from detections
  double min_score = 0.0;          // detections below are skipped
  void Check() const;              // throws InputError("--obj-id", ...)
};

// One object instance to process.
struct BopInstance {
  int scene_id = 0, im_id = 0, gt_id = 0, obj_id = 0;   // gt_id: scene_gt index or detection index
  std::string depth_path;
  std::string mask_path;                     // ground-truth mask file, or empty
  const BopDetection* detection = nullptr;   // into BopInstances::detections
  double score = 1.0;                        // detection score (1 for ground-truth masks)
  CameraInfo camera;
  std::optional<Pose> ground_truth;          // camera_from_model, metres (GT masks only)
  std::string ground_truth_problem;          // why scene_gt.json's pose is not used (BopGroundTruth::problem)
};

struct BopInstances {
  std::vector<BopDetection> detections;      // kept alive for BopInstance::detection
  std::vector<BopInstance> instances;        // sorted by scene_id, im_id, gt_id
  std::vector<std::string> scene_dirs;
  // One line per listed instance whose ground-truth pose is not used
  // ("DIR/scene_gt.json: 3[0]: cam_R_m2c: ...; its ground truth is reported as null").
  std::vector<std::string> warnings;
};

// Lists the instances of options.obj_id under `dir` (a scene or a split).
// Throws InputError naming the file for non-numbered scene folders, missing
// scene_camera.json entries, scene_gt.json lists that disagree with the mask
// files, unreadable JSON, malformed RLE. Images are not read here.
BopInstances ListBopInstances(const std::string& dir, const BopOptions& options);

// Reads depth + mask of one instance and back-projects it (segment.hpp).
SegmentCloud LoadBopInstance(const BopInstance& instance, const SegmentOptions& options);
// The instance's depth image alone (metres), as LoadBopInstance reads it.
DepthImage LoadBopDepth(const BopInstance& instance);

// The BOP results CSV (bop_toolkit docs/bop_challenge_*.md):
// header "scene_id,im_id,obj_id,score,R,t,time"; R 9 numbers row-major and t
// 3 numbers in mm, space-separated; time in seconds for the whole image.
struct BopResultRow {
  int scene_id = 0, im_id = 0, obj_id = 0;
  double score = 0.0;
  Pose camera_from_model;   // metres (converted to mm on writing)
  double time = 0.0;        // seconds per image
};
std::string BopCsv(const std::vector<BopResultRow>& rows);

// The score written to the BOP CSV: certified estimates first, then by the
// observable-correctness margin: (certified ? 1 : 0) + eps_oc / (eps_oc +
// oc_distance), so certified scores lie in (1, 2], others in [0, 1].
double CertificateScore(bool certified, double oc_distance, double eps_oc);

}  // namespace c3po
