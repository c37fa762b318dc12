#pragma once
// Per-sample rows of an evaluation, so that `c3po eval --shard K/N` parts
// join into exactly the unsharded table (issue 15; docs/camera_inputs.md).
//
// `eval --samples FILE.jsonl` writes JSON lines: a header line
//   {"c3po_eval_samples": 1, "shard": "K/N", "object", "dataset", "clouds",
//    "diameter", "settings": {...every option the table and JSON show...},
//    "rows": [{"label", "detector", "method"}, ...]}   (the rows on all clouds)
// then one line per sample of each of those rows, in row then dataset order:
//   {"row": r, "index": i, "cloud", ["error"], "adds", "rotation_error" (rad),
//    "translation_error", "oc", "nd", "oc_distance", "ms", ["R", "t"]}
// Numbers are written so that they read back bit for bit (shortest
// round-trip form; non-finite as the strings "inf", "-inf", "nan"), `index`
// is the sample's entry in that part's dataset.
//
// MergeEvaluationSamples joins parts 1..N (in that order): the header of
// every part must agree except for "shard" and "clouds"; sample indices are
// offset by the clouds of the parts before; the subset rows of self-trained
// detectors ("(oc = 1)", "(oc = nd = 1)") are filtered again and every
// summary is recomputed (Summarize). Since parts are contiguous blocks of the
// unsharded job list and each cloud's result does not depend on the others,
// the merged evaluation equals the unsharded one (timings aside).
#include <string>
#include <utility>
#include <vector>

#include "c3po/eval/evaluation.hpp"

namespace c3po {

// The samples file of `evaluation` (its rows on all clouds); `shard` "K/N".
std::string EvaluationSamplesJsonl(const Evaluation& evaluation, const std::string& shard);

// Joins parts (name, contents) given in shard order. Throws InputError("name:
// line L: problem") for a malformed file, a header that differs from part
// 1's, a part that is not shard k/N of N parts, a sample of an unknown row or
// out of order.
Evaluation MergeEvaluationSamples(const std::vector<std::pair<std::string, std::string>>& parts);

// True when `text` starts with a samples header line (merge tells the kinds apart).
bool IsEvaluationSamples(const std::string& text);

}  // namespace c3po
