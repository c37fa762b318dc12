#pragma once
// Poses from any estimator, for `c3po certify --poses FILE` (docs/method.md
// "Certifying poses from any estimator"). Two formats, told apart by the first non-blank
// character ('{' = JSON lines, anything else = BOP CSV):
//   BOP results CSV (BOP toolkit): header `scene_id,im_id,obj_id,score,R,t,time`,
//     R = 9 numbers row-major separated by spaces, t = 3 numbers in mm,
//     time in seconds (-1 = unknown); t is converted to metres (object units).
//   JSON lines: {"cloud": NAME, "R": [[...]x3], "t": [x, y, z]} with t in
//     object units, optional "score", "scene_id", "im_id", "obj_id".
// R must be a rotation within 1e-4 (max |R^T R - I|; estimators print few
// digits) with det +1; it is projected onto SO(3). Several lines may name the
// same instance (hypotheses): they are kept in file order.
#include <optional>
#include <string>
#include <vector>

#include "c3po/base/types.hpp"

namespace c3po {

struct PoseHypothesis {
  int line = 0;                         // 1-based line of the file
  std::string cloud;                    // JSON lines: the "cloud" it names ("" in CSV)
  std::optional<int> scene_id, im_id, obj_id;
  double score = 0.0;                   // default 0 when absent
  double time = -1.0;                   // seconds; -1 = unknown (CSV)
  Pose scene_from_model;                // object units (metres)
};

// Throws InputError("path: line N: field: problem") on malformed content,
// "path: empty pose file" when there is no pose line, and
// "path: cannot open" when it cannot be read.
std::vector<PoseHypothesis> ReadPoseList(const std::string& path);
// The same on text in memory (`where` names it in errors).
std::vector<PoseHypothesis> ParsePoseList(const std::string& text, const std::string& where);

}  // namespace c3po
