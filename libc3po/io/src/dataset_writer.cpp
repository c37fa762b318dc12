// DatasetWriter (dataset_writer.hpp): builds a dataset in a hidden sibling
// folder (StagedFolder) and renames it into place, so readers never see half
// a dataset.
#include "c3po/io/dataset_writer.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "c3po/base/error.hpp"
#include "c3po/base/paths.hpp"
#include "cloud_io_internal.hpp"

namespace c3po {
namespace fs = std::filesystem;
namespace {

[[noreturn]] void FailWrite(const std::string& path, const std::error_code& ec) {
  throw InputError(path, "cannot write: " + ec.message());
}

}  // namespace

DatasetWriter::DatasetWriter(std::string dir)
    : folder_(std::move(dir), "manifest.jsonl", "c3po dataset") {}

DatasetWriter::~DatasetWriter() = default;

void DatasetWriter::Add(std::size_t order, const DatasetEntry& entry, const PointSet& cloud) {
  std::string line = ManifestLine(entry);   // validates the entry first
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (committed_) throw std::logic_error("DatasetWriter::Add after Commit");
    if (!clouds_.insert(entry.cloud).second) {
      throw std::invalid_argument("DatasetWriter::Add: cloud '" + entry.cloud + "' added twice");
    }
  }
  const std::string path = folder_.path() + "/" + entry.cloud;
  if (entry.cloud.find('/') != std::string::npos) {
    std::error_code ec;
    fs::create_directories(ParentOf(path), ec);
    if (ec) FailWrite(path, ec);
  }
  cloud_detail::WritePlyBinary(path, cloud, false);   // synced once by Commit
  const std::lock_guard<std::mutex> lock(mutex_);
  lines_.emplace_back(order, std::move(line));
}

void DatasetWriter::Commit() {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (committed_) throw std::logic_error("DatasetWriter::Commit called twice");
  if (lines_.empty()) throw InputError(folder_.dir(), "cannot write: no entries");
  std::stable_sort(lines_.begin(), lines_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::string manifest;
  for (const auto& [order, line] : lines_) manifest += line + "\n";
  WriteFileAtomically(folder_.path() + "/manifest.jsonl", manifest);
  folder_.Commit();   // syncs the clouds, written without fsync, once
  committed_ = true;
}

std::size_t MergeDatasets(const std::vector<std::string>& parts, const std::string& dir, bool prefix_parts) {
  DatasetWriter writer(dir);
  std::set<std::string> names;
  std::size_t order = 0;
  for (const std::string& part : parts) {
    const Dataset dataset = ReadDataset(part);
    const std::string prefix = prefix_parts ? fs::path(dataset.dir).filename().string() + "/" : std::string();
    for (std::size_t i = 0; i < dataset.entries.size(); ++i) {
      DatasetEntry entry = dataset.entries[i];
      entry.cloud = prefix + entry.cloud;
      if (!names.insert(entry.cloud).second) {
        throw InputError(part, "cloud " + entry.cloud + " is also in an earlier part" +
                                   (prefix_parts ? " (two parts with the same folder name)" : ""));
      }
      writer.Add(order++, entry, dataset.LoadCloud(i));
    }
  }
  writer.Commit();
  return order;
}

}  // namespace c3po
