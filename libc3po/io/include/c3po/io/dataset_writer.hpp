#pragma once
// Writing a dataset folder (manifest.jsonl + binary PLY clouds) atomically.
#include <cstddef>
#include <mutex>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "c3po/base/atomic_file.hpp"
#include "c3po/io/dataset.hpp"

namespace c3po {

// Writes a dataset into a hidden temporary sibling folder (a StagedFolder whose
// marker is manifest.jsonl); Commit() renames it to `dir` (replacing an
// existing dataset). Destroying an uncommitted writer removes the temporary
// folder, so an interrupted run leaves no dataset.
class DatasetWriter {
 public:
  explicit DatasetWriter(std::string dir);
  ~DatasetWriter();
  DatasetWriter(const DatasetWriter&) = delete;
  DatasetWriter& operator=(const DatasetWriter&) = delete;

  // Writes the cloud as binary PLY under entry.cloud and records the entry.
  // Thread-safe: parallel producers may call Add concurrently.
  // Entries are written to the manifest in the order of their `order` keys
  // (so parallel producers can add out of order). Thread-safe. Throws
  // InputError("dir: ...") for an unsafe cloud path or a write failure.
  void Add(std::size_t order, const DatasetEntry& entry, const PointSet& cloud);
  // Writes manifest.jsonl and renames the folder to `dir`. An existing dataset
  // (a folder with manifest.jsonl) or an empty folder is replaced; any other
  // existing file or folder is refused with InputError (also checked by the
  // constructor, so a long run fails before it starts).
  void Commit();
  const std::string& temporary_dir() const { return folder_.path(); }

 private:
  StagedFolder folder_;
  std::mutex mutex_;   // guards lines_, clouds_, committed_
  std::vector<std::pair<std::size_t, std::string>> lines_;
  std::set<std::string> clouds_;
  bool committed_ = false;
};

// Joins dataset folders (e.g. the parts of `synth --shard K/N`, in order) into
// `dir` through DatasetWriter: manifest lines in part order, clouds rewritten
// as binary PLY under their names. Returns the number of clouds. Throws
// InputError for unreadable parts or a cloud name in two parts.
// `prefix_parts`: every cloud goes under a subfolder named after its part's
// folder ("drill_depth/000000.ply"), so datasets with the same cloud names (e.g.
// several objects' synth outputs: a mixed dataset, whose lines keep their
// "object" labels) can be joined; two parts with the same folder name are
// then refused.
std::size_t MergeDatasets(const std::vector<std::string>& parts, const std::string& dir, bool prefix_parts = false);

}  // namespace c3po
