#pragma once
// Dataset directory: manifest.jsonl + one cloud file per line (reading, and
// the manifest line schema below; writing is dataset_writer.hpp).
// Line: {"cloud": "000000.ply"} plus optional ground truth "R" (3x3 rows),
// "t", "keypoints" (posed, N x 3), "detected_keypoints" (N x 3) and
// "visible" (N booleans, for rendered depth clouds), and "object" (the name
// of the object the cloud shows: a label for mixed datasets, e.g. several
// objects' clouds joined by `c3po merge --prefix-parts`; ground truth and
// keypoints are that object's, and the keypoint count must agree only among
// lines of the same object).
#include <optional>
#include <string>
#include <vector>

#include "c3po/base/types.hpp"

namespace c3po {

struct DatasetEntry {
  std::string cloud;                          // path relative to the dataset folder
  std::optional<Pose> pose;                   // ground truth scene_from_model
  std::optional<PointSet> keypoints;          // ground-truth posed keypoints, 3 x N
  std::optional<PointSet> detected_keypoints; // 3 x N, from an outside detector
  std::optional<std::vector<bool>> visible;   // per keypoint
  std::optional<std::string> object;          // label: the object's name (1-256 printable characters)
};

struct Dataset {
  std::string dir;
  std::vector<DatasetEntry> entries;

  std::string CloudPath(std::size_t i) const;   // dir / entries[i].cloud
  PointSet LoadCloud(std::size_t i) const;      // ReadCloud(CloudPath(i))
  bool HasGroundTruth() const;                  // every entry has pose + keypoints
  // True when entry i shows `object_name`: its label is that name, or it has
  // no label (a single-object dataset).
  bool Shows(std::size_t i, const std::string& object_name) const;
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

}  // namespace c3po
