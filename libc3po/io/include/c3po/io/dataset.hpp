#pragma once
// Dataset directory: manifest.jsonl + one cloud file per line (design.md).
// Line: {"cloud": "000000.ply"} plus optional ground truth "R" (3x3 rows),
// "t", "keypoints" (posed, N x 3), "detected_keypoints" (N x 3) and
// "visible" (N booleans, for rendered depth clouds).
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/types.hpp"

namespace c3po {

struct DatasetEntry {
  std::string cloud;                          // path relative to the dataset folder
  std::optional<Pose> pose;                   // ground truth scene_from_model
  std::optional<PointSet> keypoints;          // ground-truth posed keypoints, 3 x N
  std::optional<PointSet> detected_keypoints; // 3 x N, from an outside detector
  std::optional<std::vector<bool>> visible;   // per keypoint
};

struct Dataset {
  std::string dir;
  std::vector<DatasetEntry> entries;

  std::string CloudPath(std::size_t i) const;   // dir / entries[i].cloud
  PointSet LoadCloud(std::size_t i) const;      // ReadCloud(CloudPath(i))
  bool HasGroundTruth() const;                  // every entry has pose + keypoints
};

// Throws InputError("dir/manifest.jsonl: line 3: field: problem") for
// malformed lines, inconsistent keypoint counts, missing cloud files or clouds
// escaping the folder; "dir: no manifest.jsonl (not a c3po dataset)" when the
// manifest is missing. "R" must be a rotation (orthonormal within
// kRotationTolerance = 1e-4, det +1, rotation.hpp); float errors are projected
// onto SO(3). `ground_truth = false` skips (does not parse or check) "R", "t",
// "keypoints" and "visible": for commands that do not use ground truth
// (certify), which must not refuse a dataset for it.
Dataset ReadDataset(const std::string& dir, bool ground_truth = true);
DatasetEntry ParseManifestLine(const std::string& line, const std::string& where, bool ground_truth = true);
// One JSON object, no newline; doubles printed so they read back exactly.
// Throws std::invalid_argument for non-finite values or mismatched sizes.
std::string ManifestLine(const DatasetEntry& entry);

// Joins dataset folders (e.g. the parts of `synth --shard K/N`, in order) into
// `dir` through DatasetWriter: manifest lines in part order, clouds rewritten
// as binary PLY under their names. Returns the number of clouds. Throws
// InputError for unreadable parts or a cloud name in two parts.
std::size_t MergeDatasets(const std::vector<std::string>& parts, const std::string& dir);

// Writes a dataset into a hidden temporary sibling folder; Commit() renames it
// to `dir` (replacing an existing dataset). Destroying an uncommitted writer
// removes the temporary folder, so an interrupted run leaves no dataset.
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

}  // namespace c3po
