#include "training_common.hpp"

#include <atomic>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/parallel.hpp"
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
