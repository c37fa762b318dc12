// Image inputs as CloudSources (image_sources.hpp).
#include "c3po/method/image_sources.hpp"

#include <cstdio>
#include <map>
#include <string>
#include <memory>
#include <utility>


namespace c3po {

std::vector<CloudSource> FrameSources(const FrameInput& frame, const SegmentOptions& options) {
  // Read now: a bad depth, mask or camera stops the run before any output.
  auto segment = std::make_shared<const SegmentCloud>(LoadFrameSegment(frame, options));
  CloudSource source;
  source.name = frame.mask_path;
  source.path = frame.mask_path;
  source.load_segment = [segment]() { return *segment; };
  return {std::move(source)};
}

std::vector<CloudSource> BopSources(const BopInstances& instances, const SegmentOptions& options) {
  // The instances point into their detections: the sources share one copy.
  auto shared = std::make_shared<const BopInstances>(instances);
  std::vector<CloudSource> sources;
  sources.reserve(shared->instances.size());
  for (const BopInstance& instance : shared->instances) {
    char name[96];
    std::snprintf(name, sizeof name, "%06d/%06d_%06d", instance.scene_id, instance.im_id, instance.gt_id);
    CloudSource source;
    source.name = name;
    source.path = name;
    const BopInstance* pointer = &instance;
    source.load_segment = [shared, pointer, options]() { return LoadBopInstance(*pointer, options); };
    CloudProvenance provenance;
    provenance.scene_id = instance.scene_id;
    provenance.im_id = instance.im_id;
    provenance.gt_id = instance.gt_id;
    provenance.obj_id = instance.obj_id;
    if (instance.detection) provenance.detection_score = instance.score;
    source.provenance = provenance;
    source.scene_from_model_truth = instance.ground_truth;
    sources.push_back(std::move(source));
  }
  return sources;
}

std::vector<CloudSource> ShardSources(const std::vector<CloudSource>& sources, const Shard& shard) {
  std::vector<std::int64_t> keys;
  keys.reserve(sources.size());
  std::int64_t next_single = -1;   // negative keys: sources that are groups of their own
  for (const CloudSource& source : sources) {
    if (source.provenance) {
      keys.push_back(ImageGroupKey(source.provenance->scene_id, source.provenance->im_id));
    } else {
      keys.push_back(next_single--);
    }
  }
  std::vector<CloudSource> part;
  for (std::size_t i : ShardJobs(keys, shard)) part.push_back(sources[i]);
  return part;
}

std::vector<BopInstance> ShardBopInstances(const std::vector<BopInstance>& instances, const Shard& shard) {
  std::vector<std::int64_t> keys;
  keys.reserve(instances.size());
  for (const BopInstance& instance : instances) keys.push_back(ImageGroupKey(instance.scene_id, instance.im_id));
  std::vector<BopInstance> part;
  for (std::size_t i : ShardJobs(keys, shard)) part.push_back(instances[i]);
  return part;
}

DatasetFrames BopDatasetFrames(std::shared_ptr<const BopInstances> listed, const std::vector<BopInstance>& instances,
                               const SegmentOptions& options) {
  auto by_cloud = std::make_shared<std::map<std::string, BopInstance>>();
  for (const BopInstance& instance : instances) (*by_cloud)[BopDatasetCloudName(instance)] = instance;
  return [listed, by_cloud, options](const DatasetEntry& entry) {
    const auto it = by_cloud->find(entry.cloud);
    if (it == by_cloud->end()) return DepthView{};
    // The segment is the dataset's cloud already; the frame and its support
    // plane come from the same extraction certify --bop makes.
    SegmentCloud segment = LoadBopInstance(it->second, options);
    DepthView view{segment.depth, segment.camera, segment.support_plane, segment.support_plane_distance, nullptr,
                   segment.mask};
    if (segment.evidence) view.evidence = std::make_shared<const PointSet>(std::move(*segment.evidence));
    return view;
  };
}

std::vector<BopResultRow> BopResultRows(const std::vector<CloudSource>& sources, const CertifyBatchResult& result) {
  std::vector<std::size_t> all(sources.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  return BopResultRows(sources, result, all);
}

std::vector<BopResultRow> BopResultRows(const std::vector<CloudSource>& sources, const CertifyBatchResult& result,
                                        const std::vector<std::size_t>& written) {
  std::map<std::pair<int, int>, double> image_seconds;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    if (sources[i].provenance) {
      image_seconds[{sources[i].provenance->scene_id, sources[i].provenance->im_id}] += result.outcomes[i].seconds;
    }
  }
  std::vector<BopResultRow> rows;
  for (std::size_t i : written) {
    const CloudOutcome& outcome = result.outcomes[i];
    if (!sources[i].provenance || !outcome.processed() || !outcome.estimate.ok()) continue;
    const CloudProvenance& p = *sources[i].provenance;
    const PoseEstimate& e = outcome.estimate;
    BopResultRow row;
    row.scene_id = p.scene_id;
    row.im_id = p.im_id;
    row.obj_id = p.obj_id;
    row.score = CertificateScore(e.certified(), e.certificate.oc.max_point_distance, result.certificate.eps_oc);
    row.camera_from_model = e.scene_from_model;
    row.time = image_seconds[{p.scene_id, p.im_id}];
    rows.push_back(row);
  }
  return rows;
}

}  // namespace c3po
