#pragma once
// Helpers shared by `c3po train` and `c3po selftrain`: loading dataset clouds
// in parallel, the per-epoch JSON-lines log written next to a model.
#include <string>
#include <vector>

#include "c3po/io/dataset.hpp"
#include "c3po/method/detector.hpp"

namespace c3po::cli {

// Loads every cloud of the dataset on both cores (progress bar on a terminal).
std::vector<PointSet> LoadDatasetClouds(const Dataset& dataset, const std::string& label);

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
