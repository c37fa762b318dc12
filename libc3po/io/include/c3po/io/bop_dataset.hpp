#pragma once
// A BOP folder as a c3po dataset (issue 15): every instance with ground truth
// becomes one cloud (its preprocessed segment, camera frame, metres) and one
// manifest line with the ground-truth pose and posed keypoints, so that
// `c3po eval --bop` (and anything that reads datasets) runs on BOP data.
#include <string>
#include <vector>

#include "c3po/io/bop.hpp"
#include "c3po/io/segment.hpp"

namespace c3po {

struct BopDatasetSummary {
  std::size_t written = 0;
  std::vector<std::string> skipped;   // "SSSSSS/IIIIII_GGGGGG: reason" (no usable segment)
};

// The manifest's cloud name of an instance: SSSSSS_IIIIII_GGGGGG.ply.
std::string BopDatasetCloudName(const BopInstance& instance);

// Writes `dir` (DatasetWriter: atomic, replaces an existing dataset). Clouds
// are named by BopDatasetCloudName. Instances that all lack ground truth (from
// detections) are an InputError("dir", ...); an instance whose scene_gt.json
// pose is unusable (BopInstance::ground_truth_problem) or whose segment is
// unusable (RequireUsableSegment) is skipped and listed.
BopDatasetSummary WriteDatasetFromBop(const std::vector<BopInstance>& instances, const PointSet& model_keypoints,
                                  const SegmentOptions& options, const std::string& dir);

}  // namespace c3po
