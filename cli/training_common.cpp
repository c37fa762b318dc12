#include "training_common.hpp"

#include <atomic>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/method/image_sources.hpp"
#include "c3po/object/object_io.hpp"
#include "progress_bar.hpp"

namespace c3po::cli {

std::vector<PointSet> LoadDatasetClouds(const Dataset& dataset, const std::string& label) {
  std::vector<PointSet> clouds(dataset.entries.size());
  ProgressBar progress(label, clouds.size());
  std::atomic<std::size_t> done{0};
  ParallelFor(0, static_cast<int>(clouds.size()), [&](int i) {
    clouds[i] = dataset.LoadCloud(i);
    progress.Update(++done);
  });
  progress.Finish();
  return clouds;
}

UnlabelledClouds LoadCameraClouds(CameraCloudFlags* flags, const ObjectModel& object, std::uint64_t seed,
                                  const std::string& command, bool need_truth) {
  flags->augment.noise_sigma = ParseThreshold(flags->noise, object.diameter(), flags->noise_flag);
  flags->augment.seed = seed;
  try {
    flags->augment.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  CheckSegmentOptions(flags->segment, command);
  std::vector<CloudSource> sources;
  if (flags->frame.given()) {
    for (auto& s : FrameSources(ResolveFrame(flags->frame, command), flags->segment)) sources.push_back(s);
  }
  if (!flags->bop.dir.empty()) {
    const BopInstances listed = ListBopInstancesWarning(flags->bop.dir, flags->bop.options, command);
    if (listed.instances.empty()) {
      throw InputError(flags->bop.dir, "no instances of obj_id " + std::to_string(flags->bop.options.obj_id) +
                                           (flags->bop.options.targets_path.empty() ? "" : " among the targets"));
    }
    for (auto& s : BopSources(listed, flags->segment)) sources.push_back(s);
    for (const int other : flags->other_obj_ids) {
      if (other == flags->bop.options.obj_id) {
        throw InputError("--add-obj-id " + std::to_string(other) + ": that is --obj-id, the object itself");
      }
      BopOptions options = flags->bop.options;
      options.obj_id = other;
      const BopInstances others = ListBopInstancesWarning(flags->bop.dir, options, command);
      if (others.instances.empty()) {
        throw InputError(flags->bop.dir, "no instances of obj_id " + std::to_string(other) + " (--add-obj-id)");
      }
      for (auto& s : BopSources(others, flags->segment)) sources.push_back(s);
    }
  } else if (!flags->other_obj_ids.empty()) {
    throw InputError("--add-obj-id needs --bop DIR");
  }
  if (sources.empty()) return {};
  if (need_truth) {
    for (const CloudSource& source : sources) {
      if (!source.scene_from_model_truth) {
        throw InputError(source.name, "no ground-truth pose to label it with (" + command +
                                          " needs a BOP scene with scene_gt.json)");
      }
    }
  }
  UnlabelledClouds camera = LoadUnlabelledClouds(sources);
  for (const std::string& skipped : camera.skipped) {
    std::fprintf(stderr, "%s: skipped %s\n", command.c_str(), skipped.c_str());
  }
  const std::size_t instances = camera.clouds.size();
  camera = Augment(camera, flags->augment);
  std::fprintf(stderr, "%s: %zu real instances (%zu skipped) -> %zu augmented clouds (%d copies, dropout %.3g, "
               "noise %.4g)\n", command.c_str(), instances, camera.skipped.size(), camera.clouds.size(),
               flags->augment.copies, flags->augment.drop_fraction, flags->augment.noise_sigma);
  return camera;
}

EpochLogFile::EpochLogFile(std::string model_path) : path_(std::move(model_path) + ".log.jsonl") {}

void EpochLogFile::Record(int epoch, const std::string& json_line) {
  while (!lines_.empty() && lines_.back().first >= epoch) lines_.pop_back();
  lines_.emplace_back(epoch, json_line);
  std::string text;
  for (const auto& line : lines_) text += line.second + "\n";
  WriteFileAtomically(path_, text);
}

void EpochLogFile::LoadExisting() {
  lines_.clear();
  if (!std::filesystem::exists(path_)) return;
  std::istringstream in(ReadFileToString(path_));
  for (std::string line; std::getline(in, line);) {
    const auto parsed = nlohmann::json::parse(line, nullptr, false);
    if (parsed.is_object() && parsed.contains("epoch") && parsed["epoch"].is_number_integer()) {
      lines_.emplace_back(parsed["epoch"].get<int>(), line);
    }
  }
}

}  // namespace c3po::cli
