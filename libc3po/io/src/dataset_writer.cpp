// DatasetWriter (dataset_writer.hpp): builds a dataset in a hidden sibling
// folder and renames it into place, so readers never see half a dataset.
#include "c3po/io/dataset_writer.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <stdexcept>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/paths.hpp"
#include "cloud_io_internal.hpp"

namespace c3po {
namespace fs = std::filesystem;
namespace {

bool IsDataset(const std::string& dir) {
  std::error_code ec;
  return fs::is_regular_file(fs::path(dir) / "manifest.jsonl", ec);
}

// Throws unless `dir` is absent, an empty folder or a dataset.
void CheckReplaceable(const std::string& dir) {
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (!fs::exists(status)) return;
  if (fs::is_directory(status) && (IsDataset(dir) || fs::is_empty(dir, ec))) return;
  throw InputError(dir, "exists and is not a c3po dataset (no manifest.jsonl); refusing to overwrite it");
}

// Flushes every file of the folder's file system to disk (one syncfs instead
// of an fsync per cloud) and records the folder entries.
void SyncFileSystemOf(const std::string& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::syncfs(fd);
  ::fsync(fd);
  ::close(fd);
}

// Removes ".<name>.partial.<pid>" siblings left by writers that were killed
// (their process no longer exists); live writers' folders are kept.
void RemoveStalePartials(const std::string& parent, const std::string& name) {
  const std::string prefix = "." + name + ".partial.";
  std::error_code ec;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string leaf = it->path().filename().string();
    if (leaf.rfind(prefix, 0) != 0) continue;
    const std::string pid_text = leaf.substr(prefix.size());
    if (pid_text.empty() || pid_text.find_first_not_of("0123456789") != std::string::npos || pid_text.size() > 9) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(pid_text));
    if (pid > 0 && ::kill(pid, 0) != 0 && errno == ESRCH) {
      std::error_code ignored;
      fs::remove_all(it->path(), ignored);
    }
  }
}

[[noreturn]] void FailWrite(const std::string& path, const std::error_code& ec) {
  throw InputError(path, "cannot write: " + ec.message());
}

}  // namespace

DatasetWriter::DatasetWriter(std::string dir) : dir_(StripTrailingSlashes(std::move(dir))) {
  const std::string name = LeafOf(dir_);
  if (dir_.empty() || name.empty() || name == "." || name == "..") {
    throw InputError(dir_, "cannot write: not a usable folder name");
  }
  CheckReplaceable(dir_);
  const std::string parent = ParentOf(dir_);
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) FailWrite(dir_, ec);
  RemoveStalePartials(parent, name);
  tmp_dir_ = parent + "/." + name + ".partial." + std::to_string(::getpid());
  fs::remove_all(tmp_dir_, ec);
  if (!fs::create_directory(tmp_dir_, ec) || ec) FailWrite(dir_, ec ? ec : std::make_error_code(std::errc::file_exists));
}

DatasetWriter::~DatasetWriter() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(tmp_dir_, ec);
}

void DatasetWriter::Add(std::size_t order, const DatasetEntry& entry, const PointSet& cloud) {
  std::string line = ManifestLine(entry);   // validates the entry first
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (committed_) throw std::logic_error("DatasetWriter::Add after Commit");
    if (!clouds_.insert(entry.cloud).second) {
      throw std::invalid_argument("DatasetWriter::Add: cloud '" + entry.cloud + "' added twice");
    }
  }
  const std::string path = tmp_dir_ + "/" + entry.cloud;
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
  if (lines_.empty()) throw InputError(dir_, "cannot write: no entries");
  std::stable_sort(lines_.begin(), lines_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::string manifest;
  for (const auto& [order, line] : lines_) manifest += line + "\n";
  WriteFileAtomically(tmp_dir_ + "/manifest.jsonl", manifest);
  SyncFileSystemOf(tmp_dir_);   // the clouds were written without fsync

  CheckReplaceable(dir_);
  std::error_code ec;
  if (IsDataset(dir_)) {
    // Swap: old dataset away, new one in, old one deleted.
    const std::string old_dir = ParentOf(dir_) + "/." + LeafOf(dir_) + ".old." + std::to_string(::getpid());
    fs::remove_all(old_dir, ec);
    fs::rename(dir_, old_dir, ec);
    if (ec) FailWrite(dir_, ec);
    fs::rename(tmp_dir_, dir_, ec);
    if (ec) {
      std::error_code restore;
      fs::rename(old_dir, dir_, restore);
      FailWrite(dir_, ec);
    }
    fs::remove_all(old_dir, ec);
  } else {
    fs::rename(tmp_dir_, dir_, ec);   // also replaces an empty folder
    if (ec) FailWrite(dir_, ec);
  }
  SyncFileSystemOf(ParentOf(dir_));   // make the renames durable
  committed_ = true;
}

}  // namespace c3po
