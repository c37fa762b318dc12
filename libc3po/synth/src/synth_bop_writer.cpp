// BOP split folders from BopSceneGenerator: PNGs written by the workers,
// scene JSON files at the end, all inside a StagedFolder (synth_bop.hpp).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/base/version.hpp"
#include "c3po/io/png_io.hpp"
#include "c3po/synth/synth_bop.hpp"
#include "run_batch.hpp"

namespace c3po {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

std::string Numbered(int id) {
  char text[16];
  std::snprintf(text, sizeof text, "%06d", id);
  return text;
}

Image ToImage(int width, int height, int bit_depth, const std::vector<std::uint16_t>& pixels) {
  Image image(width, height, bit_depth);
  image.pixels = pixels;
  return image;
}

Image MaskImage(int width, int height, const std::vector<std::uint8_t>& mask) {
  Image image(width, height, 8);
  std::copy(mask.begin(), mask.end(), image.pixels.begin());
  return image;
}

// The PNG files of one image: (path relative to the split folder, bytes).
std::vector<std::pair<std::string, std::string>> EncodeImage(const SynthBopImage& image) {
  std::vector<std::pair<std::string, std::string>> files;
  const std::string scene = Numbered(image.scene_id) + "/";
  const std::string im = Numbered(image.im_id);
  files.emplace_back(scene + "depth/" + im + ".png",
                     EncodePng(ToImage(image.width, image.height, 16, image.depth)));
  for (std::size_t gt = 0; gt < image.instances.size(); ++gt) {
    const std::string name = im + "_" + Numbered(static_cast<int>(gt)) + ".png";
    files.emplace_back(scene + "mask/" + name,
                       EncodePng(MaskImage(image.width, image.height, image.instances[gt].mask)));
    files.emplace_back(scene + "mask_visib/" + name,
                       EncodePng(MaskImage(image.width, image.height, image.instances[gt].mask_visib)));
  }
  return files;
}

// The JSON entries of one image (kept until the end; the pixels are not).
struct ImageRecord {
  int scene_id = 0, im_id = 0;
  Json camera, gt, gt_info;
  ArtefactCounts artefacts;
  long out_of_range = 0;
  int attempts = 0;
  double target_visib_fract = 0.0;
  long target_visible_pixels = 0;
  std::size_t instances = 0;
};

ImageRecord RecordOf(const SynthBopImage& image, const BopSynthOptions& options) {
  ImageRecord record;
  record.scene_id = image.scene_id;
  record.im_id = image.im_id;
  const CameraIntrinsics& c = options.camera;
  record.camera = Json{{"cam_K", {c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0}},
                       {"depth_scale", options.depth_scale}};
  record.gt = Json::array();
  record.gt_info = Json::array();
  for (const SynthBopInstance& instance : image.instances) {
    const Eigen::Matrix3d& R = instance.camera_from_model.R;
    const Eigen::Vector3d t_mm = instance.camera_from_model.t * options.units_to_mm;
    Json rotation = Json::array();
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) rotation.push_back(R(r, k));   // row-major
    }
    record.gt.push_back(Json{{"cam_R_m2c", rotation},
                             {"cam_t_m2c", {t_mm.x(), t_mm.y(), t_mm.z()}},
                             {"obj_id", instance.obj_id}});
    record.gt_info.push_back(Json{{"bbox_obj", instance.bbox_obj},
                                  {"bbox_visib", instance.bbox_visib},
                                  {"px_count_all", instance.px_count_all},
                                  {"px_count_valid", instance.px_count_valid},
                                  {"px_count_visib", instance.px_count_visib},
                                  {"visib_fract", instance.visib_fract}});
  }
  record.artefacts = image.artefacts;
  record.out_of_range = image.out_of_range;
  record.attempts = image.attempts;
  record.target_visib_fract = image.instances.front().visib_fract;
  record.target_visible_pixels = image.instances.front().px_count_visib;
  record.instances = image.instances.size();
  return record;
}

// One image per line, as bop_toolkit writes its scene files.
std::string DumpByKey(const Json& json) {
  std::string text = "{";
  bool first = true;
  for (const auto& [key, value] : json.items()) {
    text += first ? "\n  " : ",\n  ";
    text += Json(key).dump() + ": " + value.dump();
    first = false;
  }
  return text + "\n}\n";
}

// Inside the staged folder, which StagedFolder::Commit syncs once.
void WriteUnsynced(const std::string& path, const std::string& bytes) {
  WriteFileAtomically(path, [&](std::ostream& out) { out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); }, false);
}

// The scene folders 000000, 000001, ... with their image subfolders, inside the staged folder.
void MakeSceneFolders(const StagedFolder& folder, const std::string& dir, int scenes) {
  for (int s = 0; s < scenes; ++s) {
    for (const char* sub : {"depth", "mask", "mask_visib"}) {
      std::error_code ec;
      fs::create_directories(folder.path() + "/" + Numbered(s) + "/" + sub, ec);
      if (ec) throw InputError(dir, "cannot write: " + ec.message());
    }
  }
}

// Each scene's scene_camera.json, scene_gt.json and scene_gt_info.json from the images' records.
void WriteSceneFiles(const StagedFolder& folder, int scenes, const std::vector<ImageRecord>& records) {
  for (int s = 0; s < scenes; ++s) {
    Json camera = Json::object(), gt = Json::object(), gt_info = Json::object();
    for (const ImageRecord& record : records) {
      if (record.scene_id != s) continue;
      const std::string key = std::to_string(record.im_id);
      camera[key] = record.camera;
      gt[key] = record.gt;
      gt_info[key] = record.gt_info;
    }
    const std::string scene = folder.path() + "/" + Numbered(s) + "/";
    WriteUnsynced(scene + "scene_camera.json", DumpByKey(camera));
    WriteUnsynced(scene + "scene_gt.json", DumpByKey(gt));
    WriteUnsynced(scene + "scene_gt_info.json", DumpByKey(gt_info));
  }
}

// The report's counts and means over the images' records.
BopSynthReport ReportOf(const BopSceneGenerator& generator, int scenes, const std::vector<ImageRecord>& records) {
  const std::size_t total = records.size();
  BopSynthReport report;
  report.images = total;
  report.scenes = scenes;
  report.distance_range = generator.distance_range();
  report.diameter = generator.diameter();
  report.target_visible_pixels_min = total > 0 ? records[0].target_visible_pixels : 0;
  for (const ImageRecord& record : records) {
    report.instances += record.instances;
    report.mean_attempts += record.attempts;
    report.mean_target_visib_fract += record.target_visib_fract;
    report.target_visible_pixels_min = std::min(report.target_visible_pixels_min, record.target_visible_pixels);
    report.flying += record.artefacts.flying;
    report.dropped += record.artefacts.dropped;
    report.bled += record.artefacts.bled;
    report.out_of_range += record.out_of_range;
  }
  report.mean_attempts /= static_cast<double>(total);
  report.mean_target_visib_fract /= static_cast<double>(total);
  return report;
}

// synth_bop.json: how the dataset was made (options, camera, artefacts, the caller's provenance).
Json DatasetInfo(const BopSceneGenerator& generator, std::size_t images, int scenes, const Json& provenance) {
  const BopSynthOptions& options = generator.options();
  const CameraIntrinsics& c = options.camera;
  const DepthArtefactOptions& a = options.artefacts;
  return Json{{"generator", "c3po synth --format bop"},
              {"version", C3PO_VERSION},
              {"images", images},
              {"scenes", scenes},
              {"images_per_scene", options.images_per_scene},
              {"seed", options.seed},
              {"pose", ToString(options.pose.mode)},
              {"distance_range", {generator.distance_range().first, generator.distance_range().second}},
              {"camera", {{"fx", c.fx}, {"fy", c.fy}, {"cx", c.cx}, {"cy", c.cy},
                          {"width", c.width}, {"height", c.height}}},
              {"depth_scale", options.depth_scale},
              {"units_to_mm", options.units_to_mm},
              {"distractors", options.distractors},
              {"background", options.background},
              {"artefacts", {{"flying_fraction", a.flying_fraction}, {"discontinuity", a.discontinuity},
                             {"noise_a", a.noise_a}, {"noise_b", a.noise_b},
                             {"quantisation", a.quantisation}, {"dropout", a.dropout},
                             {"hole_blobs", a.hole_blobs}, {"hole_blob_radius", a.hole_blob_radius},
                             {"bleed", a.bleed}}},
              {"provenance", provenance}};
}

}  // namespace

BopSynthReport WriteBopDataset(const BopSceneGenerator& generator, const std::string& dir,
                               const std::string& provenance_json, const SynthProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  const BopSynthOptions& options = generator.options();
  Json provenance;
  try {
    provenance = Json::parse(provenance_json);
  } catch (const nlohmann::json::exception&) {
    throw std::invalid_argument("WriteBopDataset: provenance is not JSON");
  }
  StagedFolder folder(dir, "synth_bop.json", "c3po synth --format bop dataset");
  const std::size_t total = static_cast<std::size_t>(options.count);
  const int scenes = static_cast<int>((total + static_cast<std::size_t>(options.images_per_scene) - 1) /
                                      static_cast<std::size_t>(options.images_per_scene));
  MakeSceneFolders(folder, dir, scenes);
  const int workers = std::max(1, DefaultThreadCount());
  std::vector<std::unique_ptr<DepthRenderer>> renderers;
  for (int w = 0; w < workers; ++w) renderers.push_back(generator.MakeRenderer());
  std::vector<ImageRecord> records(total);
  const std::size_t batch = static_cast<std::size_t>(workers) * 8;
  for (std::size_t begin = 0; begin < total; begin += batch) {
    const std::size_t end = std::min(total, begin + batch);
    RunBatch(generator, begin, end, renderers, [&](std::size_t i, const SynthBopImage& image) {
      for (const auto& [name, bytes] : EncodeImage(image)) {
        WriteUnsynced(folder.path() + "/" + name, bytes);
      }
      records[i] = RecordOf(image, options);
    });
    ThrowIfInterrupted();
    if (progress) progress(end, total);
  }
  WriteSceneFiles(folder, scenes, records);
  BopSynthReport report = ReportOf(generator, scenes, records);
  WriteUnsynced(folder.path() + "/synth_bop.json", DatasetInfo(generator, total, scenes, provenance).dump(1) + "\n");
  folder.Commit();
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

BopSynthBenchmark BenchmarkBopSynth(const BopSceneGenerator& generator, double min_seconds) {
  const int workers = std::max(1, DefaultThreadCount());
  std::vector<std::unique_ptr<DepthRenderer>> renderers;
  for (int w = 0; w < workers; ++w) renderers.push_back(generator.MakeRenderer());
  const std::size_t batch = static_cast<std::size_t>(generator.options().count);
  std::vector<int> attempts(batch);
  std::vector<std::size_t> bytes(batch);
  BopSynthBenchmark result;
  result.threads = workers;
  double total_attempts = 0.0, total_bytes = 0.0;
  const auto start = std::chrono::steady_clock::now();
  std::size_t begin = 0;
  do {
    RunBatch(generator, begin, begin + batch, renderers, [&](std::size_t i, const SynthBopImage& image) {
      std::size_t size = 0;
      for (const auto& file : EncodeImage(image)) size += file.second.size();
      attempts[i - begin] = image.attempts;
      bytes[i - begin] = size;
    });
    ThrowIfInterrupted();
    for (std::size_t k = 0; k < batch; ++k) {
      total_attempts += attempts[k];
      total_bytes += static_cast<double>(bytes[k]);
    }
    begin += batch;
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  } while (result.seconds < min_seconds);
  result.images = begin;
  result.images_per_second = static_cast<double>(begin) / result.seconds;
  result.mean_attempts = total_attempts / static_cast<double>(begin);
  result.megabytes_per_image = total_bytes / static_cast<double>(begin) / 1e6;
  return result;
}

}  // namespace c3po
