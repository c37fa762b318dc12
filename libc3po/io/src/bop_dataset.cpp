// BOP instances -> c3po dataset folder (bop_dataset.hpp).
#include "c3po/io/bop_dataset.hpp"
#include "c3po/io/dataset_writer.hpp"

#include <algorithm>
#include <cstdio>
#include <mutex>

#include "c3po/io/dataset.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/base/parallel.hpp"

namespace c3po {

std::string BopDatasetCloudName(const BopInstance& instance) {
  char name[64];
  std::snprintf(name, sizeof name, "%06d_%06d_%06d.ply", instance.scene_id, instance.im_id, instance.gt_id);
  return name;
}

BopDatasetSummary WriteDatasetFromBop(const std::vector<BopInstance>& instances, const PointSet& model_keypoints,
                                  const SegmentOptions& options, const std::string& dir) {
  const bool any_truth = std::any_of(instances.begin(), instances.end(),
                                     [](const BopInstance& instance) { return instance.ground_truth.has_value(); });
  if (!any_truth) throw InputError(dir, "BOP instances without ground truth (detections) cannot make a dataset");
  DatasetWriter writer(dir);
  std::vector<std::string> skipped(instances.size());
  ParallelFor(0, static_cast<int>(instances.size()), [&](int i) {
    ThrowIfInterrupted();
    const BopInstance& instance = instances[static_cast<std::size_t>(i)];
    const std::string name = BopDatasetCloudName(instance);
    try {
      if (!instance.ground_truth) {
        throw InputError(name.substr(0, name.size() - 4), "no usable ground truth (" + instance.ground_truth_problem + ")");
      }
      const SegmentCloud segment = LoadBopInstance(instance, options);
      RequireUsableSegment(segment, name.substr(0, name.size() - 4));
      DatasetEntry entry;
      entry.cloud = name;
      entry.pose = *instance.ground_truth;
      entry.keypoints = *instance.ground_truth * model_keypoints;
      writer.Add(static_cast<std::size_t>(i), entry, segment.cloud);
    } catch (const InputError& e) {
      skipped[static_cast<std::size_t>(i)] = e.what();
    }
  });
  BopDatasetSummary summary;
  for (const std::string& reason : skipped) {
    if (reason.empty()) ++summary.written; else summary.skipped.push_back(reason);
  }
  if (summary.written == 0) throw InputError(dir, "no BOP instance had a usable segment");
  writer.Commit();
  return summary;
}

}  // namespace c3po
