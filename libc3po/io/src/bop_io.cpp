// BOP dataset files (bop.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "c3po/base/atomic_file.hpp"
#include "c3po/io/bop.hpp"
#include "c3po/base/error.hpp"
#include "c3po/geometry/rotation.hpp"

#include "json_input_internal.hpp"

namespace c3po {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using io_detail::ParseJson;
double Number(const json& value, const std::string& name, const std::string& field) {
  return io_detail::FiniteNumber(value, name, field);
}

int Id(const json& value, const std::string& name, const std::string& field) {
  if (!value.is_number_integer() || value.get<long long>() < 0 || value.get<long long>() > 999999999) {
    throw InputError(name, field + ": expected an id (integer >= 0)");
  }
  return static_cast<int>(value.get<long long>());
}

const json& Field(const json& object, const char* key, const std::string& name, const std::string& where) {
  if (!object.is_object()) throw InputError(name, where + "expected a JSON object");
  const auto it = object.find(key);
  if (it == object.end()) throw InputError(name, where + key + ": missing");
  return *it;
}

bool IsNumbered(const std::string& text) {
  return !text.empty() && text.size() <= 9 && text.find_first_not_of("0123456789") == std::string::npos;
}

int ImageKey(const std::string& key, const std::string& name) {
  if (!IsNumbered(key)) throw InputError(name, "key '" + key.substr(0, 40) + "' is not an image id");
  return std::stoi(key);
}

std::string Id6(int id) {
  char text[16];
  std::snprintf(text, sizeof text, "%06d", id);
  return text;
}

bool Exists(const std::string& path) {
  std::error_code ec;
  return fs::exists(path, ec);
}

// One scene folder being listed: its cameras and which of its images are wanted.
struct SceneListing {
  std::string dir;
  int scene_id = 0;
  std::string camera_path;
  std::map<int, CameraInfo> cameras;
  const std::set<std::pair<int, int>>* target_images = nullptr;

  const CameraInfo& CameraOf(int im_id) const {
    const auto it = cameras.find(im_id);
    if (it == cameras.end()) throw InputError(camera_path, "no entry for image " + std::to_string(im_id));
    return it->second;
  }
  bool Wanted(int im_id) const { return !target_images || target_images->count({scene_id, im_id}) > 0; }
};

// Instances from --detections: the scene's detections of the object scoring at least min_score.
void ListDetectedInstances(const SceneListing& scene, const BopOptions& options, BopInstances* out) {
  for (std::size_t i = 0; i < out->detections.size(); ++i) {
    const BopDetection& detection = out->detections[i];
    if (detection.scene_id != scene.scene_id || detection.category_id != options.obj_id ||
        detection.score < options.min_score || !scene.Wanted(detection.image_id)) {
      continue;
    }
    BopInstance instance;
    instance.scene_id = scene.scene_id;
    instance.im_id = detection.image_id;
    instance.gt_id = static_cast<int>(i);
    instance.obj_id = detection.category_id;
    instance.depth_path = scene.dir + "/depth/" + Id6(detection.image_id) + ".png";
    instance.detection = &detection;
    instance.score = detection.score;
    instance.camera = scene.CameraOf(detection.image_id);
    out->instances.push_back(instance);
  }
}

// im_id -> gt_ids of the instance masks (IMAGE_GTID.png, six digits each) in mask_dir.
std::map<int, std::set<int>> InstanceMasks(const std::string& mask_dir) {
  std::map<int, std::set<int>> masks;
  std::error_code ec;
  for (fs::directory_iterator it(mask_dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string leaf = it->path().filename().string();
    if (leaf.size() != 17 || leaf.compare(13, 4, ".png") != 0 || leaf[6] != '_' ||
        !IsNumbered(leaf.substr(0, 6)) || !IsNumbered(leaf.substr(7, 6))) {
      continue;   // not an instance mask
    }
    masks[std::stoi(leaf.substr(0, 6))].insert(std::stoi(leaf.substr(7, 6)));
  }
  if (ec) throw InputError(mask_dir, "cannot list: " + ec.message());
  return masks;
}

// The mask files must be exactly the scene_gt.json instances.
void RequireMasksOfGroundTruth(const std::map<int, std::vector<BopGroundTruth>>& gt,
                               const std::map<int, std::set<int>>& masks, const std::string& gt_path,
                               const std::string& mask_dir) {
  const std::string mask_folder = fs::path(mask_dir).filename().string();
  for (const auto& [im_id, list] : gt) {
    const auto it = masks.find(im_id);
    const std::size_t files = it == masks.end() ? 0 : it->second.size();
    const int last_gt_id = static_cast<int>(list.size()) - 1;
    const bool complete = list.empty() ? files == 0 : files == list.size() && *it->second.rbegin() == last_gt_id;
    if (!complete) {
      throw InputError(gt_path, "image " + std::to_string(im_id) + " lists " + std::to_string(list.size()) +
                                    " instances but " + mask_folder + "/ holds " +
                                    std::to_string(files) + " masks " + Id6(im_id) + "_*.png (expected gt_id 0.." +
                                    std::to_string(static_cast<int>(list.size()) - 1) + ")");
    }
  }
  for (const auto& [im_id, ids] : masks) {
    if (!gt.count(im_id)) {
      throw InputError(gt_path, "no entry for image " + std::to_string(im_id) + " but " + mask_folder +
                                    "/ holds its masks");
    }
  }
}

// Instances from the ground truth: the object's entries in scene_gt.json with their masks.
void ListGroundTruthInstances(const SceneListing& scene, const BopOptions& options, BopInstances* out) {
  const std::string gt_path = scene.dir + "/scene_gt.json";
  if (!Exists(gt_path)) {
    throw InputError(scene.dir, "no scene_gt.json: ground-truth masks need it (or give --detections FILE)");
  }
  const auto gt = ParseSceneGt(ReadFileToString(gt_path), gt_path);
  std::string mask_dir = scene.dir + "/mask_visib";
  if (!Exists(mask_dir)) mask_dir = scene.dir + "/mask";
  if (!Exists(mask_dir)) throw InputError(scene.dir, "no mask_visib/ or mask/ folder");
  RequireMasksOfGroundTruth(gt, InstanceMasks(mask_dir), gt_path, mask_dir);
  for (const auto& [im_id, list] : gt) {
    if (!scene.Wanted(im_id)) continue;
    for (std::size_t gt_id = 0; gt_id < list.size(); ++gt_id) {
      if (list[gt_id].obj_id != options.obj_id) continue;
      BopInstance instance;
      instance.scene_id = scene.scene_id;
      instance.im_id = im_id;
      instance.gt_id = static_cast<int>(gt_id);
      instance.obj_id = options.obj_id;
      instance.depth_path = scene.dir + "/depth/" + Id6(im_id) + ".png";
      instance.mask_path = mask_dir + "/" + Id6(im_id) + "_" + Id6(static_cast<int>(gt_id)) + ".png";
      instance.camera = scene.CameraOf(im_id);
      instance.ground_truth = list[gt_id].camera_from_model;
      instance.ground_truth_problem = list[gt_id].problem;
      if (!instance.ground_truth) out->warnings.push_back(list[gt_id].problem + "; its ground truth is reported as null");
      out->instances.push_back(instance);
    }
  }
}

// Instances of one scene folder.
void ListScene(const std::string& scene_dir, int scene_id, const BopOptions& options,
               const std::set<std::pair<int, int>>* target_images, BopInstances* out) {
  SceneListing scene;
  scene.dir = scene_dir;
  scene.scene_id = scene_id;
  scene.camera_path = scene_dir + "/scene_camera.json";
  scene.cameras = ParseSceneCamera(ReadFileToString(scene.camera_path), scene.camera_path);
  scene.target_images = target_images;
  if (!options.detections_path.empty()) {
    ListDetectedInstances(scene, options, out);
  } else {
    ListGroundTruthInstances(scene, options, out);
  }
}

std::string FormatNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", value);
  return text;
}

// One entry's cam_R_m2c / cam_t_m2c as a pose in metres; InputError naming the field.
Pose GroundTruthPose(const json& entry, const std::string& name, const std::string& where) {
  const json& r = Field(entry, "cam_R_m2c", name, where);
  const json& t = Field(entry, "cam_t_m2c", name, where);
  if (!r.is_array() || r.size() != 9) throw InputError(name, where + "cam_R_m2c: expected 9 numbers");
  if (!t.is_array() || t.size() != 3) throw InputError(name, where + "cam_t_m2c: expected 3 numbers");
  Eigen::Matrix3d R;
  for (int k = 0; k < 9; ++k) R(k / 3, k % 3) = Number(r[static_cast<std::size_t>(k)], name, where + "cam_R_m2c");
  std::string problem;
  const auto rotation = NearestRotation(R, &problem, kDatasetRotationTolerance);
  if (!rotation) throw InputError(name, where + "cam_R_m2c: " + problem);
  Pose pose;
  pose.R = *rotation;
  for (int k = 0; k < 3; ++k) {
    pose.t(k) = Number(t[static_cast<std::size_t>(k)], name, where + "cam_t_m2c") * kMetresPerMillimetre;
  }
  if (!pose.t.allFinite()) throw InputError(name, where + "cam_t_m2c: non-finite");
  return pose;
}

}  // namespace

std::map<int, std::vector<BopGroundTruth>> ParseSceneGt(const std::string& text, const std::string& name) {
  const json doc = ParseJson(text, name);
  if (!doc.is_object()) throw InputError(name, "expected an object keyed by image id");
  std::map<int, std::vector<BopGroundTruth>> gt;
  for (const auto& item : doc.items()) {
    const int im_id = ImageKey(item.key(), name);
    if (!item.value().is_array()) throw InputError(name, item.key() + ": expected a list of instances");
    auto& list = gt[im_id];
    for (std::size_t i = 0; i < item.value().size(); ++i) {
      const json& entry = item.value()[i];
      const std::string where = item.key() + "[" + std::to_string(i) + "]: ";
      BopGroundTruth instance;
      instance.obj_id = Id(Field(entry, "obj_id", name, where), name, where + "obj_id");
      try {
        instance.camera_from_model = GroundTruthPose(entry, name, where);
      } catch (const InputError& e) {
        instance.problem = e.what();
      }
      list.push_back(instance);
    }
  }
  return gt;
}

std::vector<BopDetection> ParseDetections(const std::string& text, const std::string& name) {
  const json doc = ParseJson(text, name);
  if (!doc.is_array()) throw InputError(name, "expected a list of detections");
  std::vector<BopDetection> detections;
  for (std::size_t i = 0; i < doc.size(); ++i) {
    const json& entry = doc[i];
    const std::string where = "detection " + std::to_string(i) + ": ";
    BopDetection detection;
    detection.scene_id = Id(Field(entry, "scene_id", name, where), name, where + "scene_id");
    detection.image_id = Id(Field(entry, "image_id", name, where), name, where + "image_id");
    detection.category_id = Id(Field(entry, "category_id", name, where), name, where + "category_id");
    detection.score = Number(Field(entry, "score", name, where), name, where + "score");
    if (entry.contains("time")) detection.time = Number(entry["time"], name, where + "time");
    const json& segmentation = Field(entry, "segmentation", name, where);
    const json& size = Field(segmentation, "size", name, where + "segmentation: ");
    if (!size.is_array() || size.size() != 2) throw InputError(name, where + "segmentation: size: expected [height, width]");
    detection.height = Id(size[0], name, where + "segmentation: size");
    detection.width = Id(size[1], name, where + "segmentation: size");
    const json& counts = Field(segmentation, "counts", name, where + "segmentation: ");
    const std::string rle_name = name + ": " + where + "segmentation";
    if (counts.is_string()) {
      detection.counts = ParseRleString(counts.get<std::string>(), rle_name);
    } else if (counts.is_array()) {
      for (const json& run : counts) {
        if (!run.is_number_integer() || run.get<long long>() < 0) throw InputError(rle_name, "malformed RLE: counts must be integers >= 0");
        detection.counts.push_back(run.get<long long>());
      }
    } else {
      throw InputError(rle_name, "malformed RLE: counts must be a string or a list of integers");
    }
    // Checks the runs against the size now (a bad RLE fails the listing,
    // not a worker later), without keeping the decoded mask.
    const std::int64_t pixels = static_cast<std::int64_t>(detection.height) * detection.width;
    std::int64_t sum = 0;
    for (std::int64_t run : detection.counts) {
      sum += std::min<std::int64_t>(run, pixels + 1);
      if (sum > pixels) break;   // too many already (and no overflow)
    }
    if (sum != pixels) {
      throw InputError(rle_name, "malformed RLE: runs cover " + std::string(sum > pixels ? "more than " + std::to_string(pixels) : std::to_string(sum)) + " pixels, size " +
                                     std::to_string(detection.height) + " x " + std::to_string(detection.width));
    }
    detections.push_back(std::move(detection));
  }
  return detections;
}

std::vector<BopTarget> ParseTargets(const std::string& text, const std::string& name) {
  const json doc = ParseJson(text, name);
  if (!doc.is_array()) throw InputError(name, "expected a list of targets");
  std::vector<BopTarget> targets;
  for (std::size_t i = 0; i < doc.size(); ++i) {
    const std::string where = "target " + std::to_string(i) + ": ";
    BopTarget target;
    target.scene_id = Id(Field(doc[i], "scene_id", name, where), name, where + "scene_id");
    target.im_id = Id(Field(doc[i], "im_id", name, where), name, where + "im_id");
    target.obj_id = Id(Field(doc[i], "obj_id", name, where), name, where + "obj_id");
    if (doc[i].contains("inst_count")) target.inst_count = Id(doc[i]["inst_count"], name, where + "inst_count");
    targets.push_back(target);
  }
  return targets;
}

std::map<int, BopModelInfo> ParseModelsInfo(const std::string& text, const std::string& name) {
  const json doc = ParseJson(text, name);
  if (!doc.is_object()) throw InputError(name, "expected an object keyed by obj_id");
  std::map<int, BopModelInfo> info;
  for (const auto& item : doc.items()) {
    const int obj_id = ImageKey(item.key(), name);
    const std::string where = item.key() + ": ";
    BopModelInfo model;
    model.diameter_mm = Number(Field(item.value(), "diameter", name, where), name, where + "diameter");
    if (model.diameter_mm <= 0) throw InputError(name, where + "diameter: must be positive");
    if (item.value().contains("symmetries_discrete")) {
      const json& list = item.value()["symmetries_discrete"];
      if (!list.is_array()) throw InputError(name, where + "symmetries_discrete: expected a list");
      for (const json& m : list) {
        if (!m.is_array() || m.size() != 16) throw InputError(name, where + "symmetries_discrete: expected 4x4 matrices (16 numbers)");
        for (const json& v : m) Number(v, name, where + "symmetries_discrete");
      }
      model.discrete_symmetries = static_cast<int>(list.size());
    }
    if (item.value().contains("symmetries_continuous")) {
      const json& list = item.value()["symmetries_continuous"];
      if (!list.is_array()) throw InputError(name, where + "symmetries_continuous: expected a list");
      model.continuous_symmetry = !list.empty();
    }
    info[obj_id] = model;
  }
  return info;
}

void BopOptions::Check() const {
  if (obj_id < 0) throw InputError("--obj-id", "required with --bop (an object id >= 0)");
  if (!std::isfinite(min_score)) throw InputError("--min-score", "not a finite number");
}

BopInstances ListBopInstances(const std::string& dir_argument, const BopOptions& options) {
  options.Check();
  std::string dir = dir_argument;
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir, "not a folder (expected a BOP scene or split folder)");
  BopInstances result;
  if (!options.detections_path.empty()) {
    result.detections = ParseDetections(ReadFileToString(options.detections_path), options.detections_path);
  }
  std::set<std::pair<int, int>> target_images;
  if (!options.targets_path.empty()) {
    for (const BopTarget& target : ParseTargets(ReadFileToString(options.targets_path), options.targets_path)) {
      if (target.obj_id == options.obj_id) target_images.insert({target.scene_id, target.im_id});
    }
  }
  const auto* targets = options.targets_path.empty() ? nullptr : &target_images;
  std::vector<std::pair<int, std::string>> scenes;
  if (Exists(dir + "/scene_camera.json")) {
    const std::string leaf = fs::path(dir).filename().string();
    if (!IsNumbered(leaf)) throw InputError(dir, "scene folder name is not a number (the scene id)");
    scenes.push_back({std::stoi(leaf), dir});
  } else {
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      if (!it->is_directory()) continue;
      const std::string leaf = it->path().filename().string();
      if (!IsNumbered(leaf)) {
        throw InputError(it->path().string(), "non-numbered scene folder in a BOP split (expected NNNNNN/)");
      }
      if (!Exists(it->path().string() + "/scene_camera.json")) {
        throw InputError(it->path().string(), "no scene_camera.json (not a BOP scene)");
      }
      scenes.push_back({std::stoi(leaf), it->path().string()});
    }
    if (ec) throw InputError(dir, "cannot list: " + ec.message());
    if (scenes.empty()) throw InputError(dir, "no scene_camera.json and no numbered scene folders (not a BOP scene or split)");
  }
  std::sort(scenes.begin(), scenes.end());
  for (std::size_t i = 1; i < scenes.size(); ++i) {
    if (scenes[i].first == scenes[i - 1].first) throw InputError(scenes[i].second, "duplicate scene id");
  }
  for (const auto& [scene_id, scene_dir] : scenes) {
    ListScene(scene_dir, scene_id, options, targets, &result);
    result.scene_dirs.push_back(scene_dir);
  }
  std::stable_sort(result.instances.begin(), result.instances.end(), [](const BopInstance& a, const BopInstance& b) {
    return std::tie(a.scene_id, a.im_id, a.gt_id) < std::tie(b.scene_id, b.im_id, b.gt_id);
  });
  return result;
}

DepthImage LoadBopDepth(const BopInstance& instance) {
  return DepthFromPng(ReadDepthPng(instance.depth_path), instance.camera.depth_scale);
}

SegmentCloud LoadBopInstance(const BopInstance& instance, const SegmentOptions& options) {
  const DepthImage depth = LoadBopDepth(instance);
  Mask mask;
  std::string mask_name = instance.mask_path;
  if (instance.detection) {
    mask_name = "detection " + std::to_string(instance.gt_id);
    mask = DecodeRle(instance.detection->height, instance.detection->width, instance.detection->counts, mask_name);
  } else {
    mask = MaskFromImage(ReadPng(instance.mask_path));
  }
  return ExtractSegment(depth, mask, instance.camera.K, options, mask_name + " with " + instance.depth_path);
}

std::string BopCsv(const std::vector<BopResultRow>& rows) {
  std::ostringstream out;
  out << "scene_id,im_id,obj_id,score,R,t,time\n";
  for (const BopResultRow& row : rows) {
    const Pose& T = row.camera_from_model;
    out << row.scene_id << ',' << row.im_id << ',' << row.obj_id << ',' << FormatNumber(row.score) << ',';
    for (int k = 0; k < 9; ++k) out << (k ? " " : "") << FormatNumber(T.R(k / 3, k % 3));
    out << ',';
    for (int k = 0; k < 3; ++k) out << (k ? " " : "") << FormatNumber(T.t(k) / kMetresPerMillimetre);
    out << ',' << FormatNumber(row.time) << '\n';
  }
  return out.str();
}

double CertificateScore(bool certified, double oc_distance, double eps_oc) {
  const double margin = std::isfinite(oc_distance) && eps_oc > 0.0 ? eps_oc / (eps_oc + std::max(0.0, oc_distance)) : 0.0;
  return (certified ? 1.0 : 0.0) + margin;
}

}  // namespace c3po
