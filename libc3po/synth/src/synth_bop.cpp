// Synthetic BOP scenes: composition, artefacts, masks and scene_gt_info
// (synth_bop.hpp). Writing the folder is in synth_bop_writer.cpp.
#include "c3po/synth/synth_bop.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "c3po/base/error.hpp"

namespace c3po {
namespace {

// BOP's (x, y, width, height) of the pixels where mask != 0; [-1, -1, -1, -1] when empty.
std::array<int, 4> BoundingBox(const std::vector<std::uint8_t>& mask, int width) {
  int u0 = std::numeric_limits<int>::max(), v0 = u0, u1 = -1, v1 = -1;
  for (std::size_t p = 0; p < mask.size(); ++p) {
    if (!mask[p]) continue;
    const int u = static_cast<int>(p % static_cast<std::size_t>(width));
    const int v = static_cast<int>(p / static_cast<std::size_t>(width));
    u0 = std::min(u0, u);
    v0 = std::min(v0, v);
    u1 = std::max(u1, u);
    v1 = std::max(v1, v);
  }
  if (u1 < 0) return {-1, -1, -1, -1};
  return {u0, v0, u1 - u0 + 1, v1 - v0 + 1};
}

std::vector<std::uint8_t> MaskOf(const std::vector<int>& pixels, std::size_t size) {
  std::vector<std::uint8_t> mask(size, 0);
  for (const int p : pixels) mask[static_cast<std::size_t>(p)] = 255;
  return mask;
}

// The table: normal (0, -sin a, -cos a) faces the camera and tilts the top of
// the image away (rows above the centre see farther); the plane lies behind
// every vertex of every instance by at least `gap`.
Plane TablePlane(const std::vector<SceneInstance>& instances, double tilt, double gap) {
  Plane plane;
  plane.normal = Eigen::Vector3d(0.0, -std::sin(tilt), -std::cos(tilt));
  double nearest = std::numeric_limits<double>::infinity();   // min over vertices of n . x
  for (const SceneInstance& instance : instances) {
    const PointSet posed = instance.camera_from_model * instance.mesh->vertices;
    nearest = std::min(nearest, (plane.normal.transpose() * posed).minCoeff());
  }
  // Points in front of the plane (camera side) have n . x > offset.
  plane.offset = nearest - gap;
  return plane;
}

// The image's depth from the rendered scene: the artefacts applied in metres
// (their parameters are physical; their own random stream per image), then
// depth-image units round(z_mm / depth_scale), 0 = no measurement; beyond 16
// bits there is none either (counted in out_of_range).
void WriteDepth(const BopSynthOptions& options, const SceneImage& scene, std::size_t index, SynthBopImage* image) {
  const CameraIntrinsics& camera = options.camera;
  const std::size_t pixels = static_cast<std::size_t>(camera.width) * camera.height;
  const double to_metres = options.units_to_mm / 1000.0;
  std::vector<double> depth_m(pixels);
  for (std::size_t p = 0; p < pixels; ++p) depth_m[p] = scene.depth[p] * to_metres;
  if (options.artefacts.AnyDepth()) {
    std::vector<int> blob_centres;
    for (std::size_t p = 0; p < pixels; ++p) {
      if (scene.label[p] != SceneImage::kBackground) blob_centres.push_back(static_cast<int>(p));
    }
    Rng artefact_rng = Rng::ForItem(options.seed ^ 0xa5f1c3e2d4b69788ULL, index);
    image->artefacts =
        ApplyDepthArtefacts(options.artefacts, camera.width, camera.height, blob_centres, &depth_m, artefact_rng);
  }
  image->depth.assign(pixels, 0);
  for (std::size_t p = 0; p < pixels; ++p) {
    if (!(depth_m[p] > 0.0)) continue;
    const double units = std::round(depth_m[p] * 1000.0 / options.depth_scale);
    if (units > 65535.0) {
      ++image->out_of_range;
    } else {
      image->depth[p] = static_cast<std::uint16_t>(units);
    }
  }
}

// Instance i of the scene as BOP records it: pose, masks, boxes, pixel counts
// (valid: with a depth in `image`); its mask_visib bled by the artefacts
// (counted in image->artefacts.bled).
SynthBopInstance InstanceRecord(const BopSynthOptions& options, const SceneImage& scene, int i, int obj_id,
                                const Pose& camera_from_model, SynthBopImage* image) {
  const CameraIntrinsics& camera = options.camera;
  const std::size_t pixels = static_cast<std::size_t>(camera.width) * camera.height;
  const std::vector<int>& silhouette = scene.silhouettes[static_cast<std::size_t>(i)];
  SynthBopInstance instance;
  instance.obj_id = obj_id;
  instance.camera_from_model = camera_from_model;
  instance.mask = MaskOf(silhouette, pixels);
  instance.mask_visib = MaskOf(scene.VisiblePixels(i), pixels);
  instance.bbox_obj = BoundingBox(instance.mask, camera.width);
  instance.bbox_visib = BoundingBox(instance.mask_visib, camera.width);
  instance.px_count_all = static_cast<long>(silhouette.size());
  instance.px_count_visib = static_cast<long>(std::count(instance.mask_visib.begin(), instance.mask_visib.end(), 255));
  for (const int p : silhouette) {
    if (image->depth[static_cast<std::size_t>(p)] > 0) ++instance.px_count_valid;
  }
  instance.visib_fract = instance.px_count_all > 0 ? static_cast<double>(instance.px_count_visib) /
                                                         static_cast<double>(instance.px_count_all)
                                                   : 0.0;
  if (options.artefacts.bleed > 0) {
    image->artefacts.bled += BleedMask(camera.width, camera.height, options.artefacts.bleed, &instance.mask_visib);
  }
  return instance;
}

}  // namespace

CameraIntrinsics YcbvCamera() {
  CameraIntrinsics camera;
  camera.fx = 1066.778;
  camera.fy = 1067.487;
  camera.cx = 312.9869;
  camera.cy = 241.3109;
  camera.width = 640;
  camera.height = 480;
  return camera;
}

double FinestDepthScale(double far_mm) {
  if (!(far_mm > 0.0) || !std::isfinite(far_mm)) throw std::invalid_argument("FinestDepthScale: far_mm must be > 0");
  double decade = 0.1;
  for (;;) {
    for (const double step : {1.0, 2.0, 5.0}) {
      const double scale = step * decade;
      if (far_mm / scale <= 65535.0) return scale;
    }
    decade *= 10.0;
  }
}

void BopSynthOptions::Check() const {
  if (count < 1) throw InputError("--count: must be at least 1");
  if (images_per_scene < 1 || images_per_scene > 1000000) {
    throw InputError("--images-per-scene: must be in [1, 1000000]");
  }
  if (pose.mode == PoseMode::kPaper) throw InputError("--pose: paper poses are not supported for --format bop");
  pose.Check();
  camera.Check();
  if (!(units_to_mm > 0.0) || !std::isfinite(units_to_mm)) throw InputError("units: scale to mm must be > 0");
  if (depth_scale != 0.0 && (!(depth_scale > 0.0) || !std::isfinite(depth_scale) || depth_scale > 1000.0)) {
    throw InputError("--depth-scale: must be auto or in (0, 1000] mm per unit");
  }
  if (distractors < 0 || distractors > 100) throw InputError("--distractors: must be in [0, 100]");
  if (!(max_table_tilt >= 0.0 && max_table_tilt <= 1.0)) {
    throw InputError("table tilt: must be in [0, 1] rad");
  }
  if (!(background_gap >= 0.0) || !std::isfinite(background_gap)) {
    throw InputError("--background-gap: must be >= 0");
  }
  if (!(min_visib_fract >= 0.0 && min_visib_fract <= 1.0)) {
    throw InputError("--min-visib-fract: must be in [0, 1]");
  }
  if (min_visible_pixels < 1) throw InputError("--min-points: must be at least 1");
  if (max_attempts < 1) throw InputError("max attempts: must be at least 1");
  artefacts.Check();
}

BopSceneGenerator::BopSceneGenerator(SynthBopObject target, std::vector<SynthBopObject> distractor_objects,
                                     const BopSynthOptions& options, std::string where)
    : options_(options), where_(std::move(where)) {
  options_.Check();
  objects_.push_back(Prepare(target));
  for (const SynthBopObject& object : distractor_objects) objects_.push_back(Prepare(object));
  const auto& pose = options_.pose;
  distance_ = (pose.distance_min == 0.0 && pose.distance_max == 0.0)
                  ? DefaultDistanceRange(objects_[0].diameter, options_.camera)
                  : std::make_pair(pose.distance_min, pose.distance_max);
  // The deepest surface must fit in 16-bit depth units.
  const double far_mm = (distance_.second + objects_[0].diameter) * options_.units_to_mm;
  if (options_.depth_scale == 0.0 && std::isfinite(far_mm) && far_mm > 0.0) {
    options_.depth_scale = FinestDepthScale(far_mm);
  }
  if (!(options_.depth_scale > 0.0 && options_.depth_scale <= 1000.0) || far_mm / options_.depth_scale > 65535.0) {
    char message[256];
    std::snprintf(message, sizeof message,
                  "--depth-scale: %g mm per unit cannot store depths up to %.0f mm in 16 bits "
                  "(raise --depth-scale or lower --distance)",
                  options_.depth_scale, far_mm);
    throw InputError(message);
  }
}

BopSceneGenerator::Placed BopSceneGenerator::Prepare(const SynthBopObject& object) const {
  if (!object.mesh || object.mesh->empty()) throw InputError(where_ + ": the mesh has no triangles");
  try {
    object.mesh->Validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(where_ + ": " + e.what());
  }
  if (object.obj_id < 1) throw InputError("--obj-id: must be a positive integer");
  Placed placed;
  placed.object = object;
  const Eigen::AlignedBox3d box = object.mesh->BoundingBox();
  placed.centre = box.center();
  placed.diameter = box.diagonal().norm();
  if (!(placed.diameter > 0.0)) throw InputError(where_ + ": the mesh has zero extent");
  placed.closed = IsClosedOutward(*object.mesh);
  return placed;
}

std::unique_ptr<DepthRenderer> BopSceneGenerator::MakeRenderer() const {
  return std::make_unique<DepthRenderer>(options_.camera);
}

std::optional<BopSceneGenerator::Arrangement> BopSceneGenerator::Arrange(Rng& rng) const {
  Arrangement scene;
  std::vector<Eigen::Vector3d> centres;
  const auto place = [&](const Placed& object) {
    const Pose pose = SamplePose(options_.pose, options_.camera, distance_, object.centre, object.diameter,
                                 CloudKind::kDepth, rng);
    const Eigen::Vector3d centre = pose * object.centre;
    for (std::size_t j = 0; j < scene.instances.size(); ++j) {
      const double clearance = 0.5 * (object.diameter + scene.placed[j]->diameter);
      if ((centre - centres[j]).norm() < clearance) return false;
    }
    scene.instances.push_back({object.object.mesh, pose, object.closed});
    centres.push_back(centre);
    return true;
  };
  scene.placed.push_back(&objects_[0]);
  place(objects_[0]);
  for (int k = 0; k < options_.distractors; ++k) {
    const std::size_t choice =
        objects_.size() == 1 ? 0
                             : 1 + static_cast<std::size_t>(rng.UniformInt(static_cast<int>(objects_.size() - 1)));
    const Placed& object = objects_[choice];
    scene.placed.push_back(&object);
    bool ok = false;
    for (int draw = 0; draw < 20 && !ok; ++draw) ok = place(object);
    if (!ok) return std::nullopt;   // no room for this distractor: draw the scene again
  }
  return scene;
}

namespace {

// The target's visible pixels pass the options' count and fraction of its silhouette.
bool TargetVisibleEnough(const SceneImage& scene, const BopSynthOptions& options) {
  const std::vector<int> visible = scene.VisiblePixels(0);
  const double fraction = scene.silhouettes[0].empty() ? 0.0
                                                        : static_cast<double>(visible.size()) /
                                                              static_cast<double>(scene.silhouettes[0].size());
  return static_cast<int>(visible.size()) >= options.min_visible_pixels && fraction >= options.min_visib_fract;
}

}  // namespace

SynthBopImage BopSceneGenerator::Generate(std::size_t index, DepthRenderer* renderer) const {
  if (!renderer) throw std::invalid_argument("BopSceneGenerator: needs a renderer");
  Rng rng = Rng::ForItem(options_.seed, index);
  for (int attempt = 1; attempt <= options_.max_attempts; ++attempt) {
    const std::optional<Arrangement> drawn = Arrange(rng);
    if (!drawn) continue;
    std::optional<Plane> table;
    if (options_.background) {
      const double tilt = rng.Uniform(0.0, options_.max_table_tilt);
      table = TablePlane(drawn->instances, tilt, options_.background_gap * objects_[0].diameter);
    }
    const SceneImage scene = RenderScene(*renderer, drawn->instances, table);
    if (!TargetVisibleEnough(scene, options_)) continue;

    SynthBopImage image;
    image.scene_id = static_cast<int>(index / static_cast<std::size_t>(options_.images_per_scene));
    image.im_id = static_cast<int>(index % static_cast<std::size_t>(options_.images_per_scene));
    image.width = options_.camera.width;
    image.height = options_.camera.height;
    image.attempts = attempt;
    WriteDepth(options_, scene, index, &image);
    for (std::size_t i = 0; i < drawn->instances.size(); ++i) {
      image.instances.push_back(InstanceRecord(options_, scene, static_cast<int>(i), drawn->placed[i]->object.obj_id,
                                               drawn->instances[i].camera_from_model, &image));
    }
    return image;
  }
  throw InputError(where_ + ": no image with the target at least " +
                   std::to_string(options_.min_visible_pixels) + " pixels and " +
                   std::to_string(options_.min_visib_fract) + " visible in " +
                   std::to_string(options_.max_attempts) +
                   " attempts (object too small or too far, or too many distractors)");
}

}  // namespace c3po
