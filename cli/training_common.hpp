#pragma once
// Helpers shared by `c3po train` and `c3po selftrain`: loading dataset clouds
// in parallel, the camera inputs (frames, BOP instances) with their
// augmentation, the per-epoch JSON-lines log written next to a model.
#include <string>
#include <vector>

#include "c3po/io/dataset.hpp"
#include "c3po/method/detector.hpp"
#include "c3po/method/selftrain_inputs.hpp"
#include "c3po/object/object_model.hpp"
#include "options.hpp"

namespace c3po::cli {

// Loads every cloud of the dataset on both cores (progress bar on a terminal).
std::vector<PointSet> LoadDatasetClouds(const Dataset& dataset, const std::string& label);

// The clouds of the camera inputs (empty when none is given): the frame's and
// the BOP instances' CloudSources (image_sources.hpp) read by LoadSourceCloud
// (LoadUnlabelledClouds), then Augment with flags->augment (noise parsed as a
// distance of `object`, seed = `seed`). Sources that cannot be read are
// skipped with their reason on stderr. InputError (naming `command`) for bad
// options, for --bop with no instance of --obj-id, and (with `need_truth`,
// before anything is read) for a source without a ground-truth pose.
UnlabelledClouds LoadCameraClouds(CameraCloudFlags* flags, const ObjectModel& object, std::uint64_t seed,
                                  const std::string& command, bool need_truth = false);

// MODEL.log.jsonl: rewritten atomically with every line so far after each epoch.
class EpochLogFile {
 public:
  explicit EpochLogFile(std::string model_path);
  const std::string& path() const { return path_; }
  // Records the line of `epoch` (a JSON object, no newline), dropping lines of
  // this or later epochs (left by an interrupted run), and rewrites the file.
  void Record(int epoch, const std::string& json_line);
  // Reads the lines of an existing log (for --resume); missing file = none.
  void LoadExisting();

 private:
  std::string path_;
  std::vector<std::pair<int, std::string>> lines_;
};

}  // namespace c3po::cli
