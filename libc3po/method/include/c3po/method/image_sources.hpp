#pragma once
// Image inputs as CloudSources of the one batch path (certify_batch.hpp;
// issue 15, docs/camera_inputs.md): a depth frame + mask, BOP instances with
// their ids and ground truth, --shard by image, and the BOP results rows of a
// batch.
#include <memory>
#include <vector>

#include "c3po/io/bop.hpp"
#include "c3po/io/bop_dataset.hpp"
#include "c3po/io/segment.hpp"
#include "c3po/io/shard.hpp"
#include "c3po/method/certify_batch.hpp"

namespace c3po {

// One frame given by files:
// read and preprocessed now, so a bad depth, mask or camera is an InputError
// before any output; named by the mask path.
std::vector<CloudSource> FrameSources(const FrameInput& frame, const SegmentOptions& options);
// Every listed BOP instance (named SSSSSS/IIIIII_GGGGGG), read when certified,
// with its provenance and, from scene_gt.json, its ground truth.
std::vector<CloudSource> BopSources(const BopInstances& instances, const SegmentOptions& options);
// --shard K/N (shard.hpp): a BOP image's instances form one group, any other
// source is a group of its own; parts 1..N concatenated are `sources`.
std::vector<CloudSource> ShardSources(const std::vector<CloudSource>& sources, const Shard& shard);
// The same parts of a BOP instance list (eval --shard: instances become a
// dataset); instances keep pointing into their BopInstances' detections.
std::vector<BopInstance> ShardBopInstances(const std::vector<BopInstance>& instances, const Shard& shard);
// The depth frames of a dataset written from BOP instances (WriteDatasetFromBop,
// eval --bop): an entry's frame is its instance's depth image, camera and
// support plane, and its evidence when `options` gives it one of its own
// (the instance's segment under `options`, extracted when asked: the
// dataset's cloud is that segment's `cloud`); an entry no instance names has
// none.
// `listed` keeps the instances' detections alive.
DatasetFrames BopDatasetFrames(std::shared_ptr<const BopInstances> listed, const std::vector<BopInstance>& instances,
                               const SegmentOptions& options);
// BOP results rows (bop.hpp) from a batch: one per BOP source whose
// registration succeeded; score = CertificateScore with the batch's eps_oc;
// time = the seconds of all the object's sources of that image.
std::vector<BopResultRow> BopResultRows(const std::vector<CloudSource>& sources, const CertifyBatchResult& result);
// The same for the sources listed in `written` only (in that order; time
// still sums every source of the image): certify --poses writes one row per
// instance, its chosen hypothesis.
std::vector<BopResultRow> BopResultRows(const std::vector<CloudSource>& sources, const CertifyBatchResult& result,
                                        const std::vector<std::size_t>& written);

}  // namespace c3po
