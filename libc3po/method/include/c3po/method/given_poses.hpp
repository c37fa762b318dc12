#pragma once
// Certificates for poses from any estimator (`c3po certify --poses FILE`,
// docs/method.md "Certifying poses from any estimator"). The certificates need only the
// cloud and a pose (paper Theorems 7, 12), so a given pose T enters the one
// batch path (certify_batch.hpp) as given keypoints ỹ = T·b: without
// correction the registration of T·b onto b is T itself (eq. 8 is exact on
// noise-free correspondences), with correction T·b is the corrector's start.
//
// Matching rule (a hypothesis to cloud sources):
//  - a hypothesis naming a "cloud" matches the source whose name is exactly
//    that text (one source);
//  - a hypothesis without "cloud" (every BOP CSV row) but with scene_id and
//    im_id is a hypothesis for EVERY source with BOP provenance of that
//    scene_id and im_id (and of its obj_id, when the line has one). A BOP
//    results row carries no gt_id, so with several instances of one object
//    in an image the row cannot be tied to one of them by ids: it is tried
//    on each, and each instance keeps its best certified hypothesis
//    (ChooseCertified). The BOP toolkit likewise assigns estimates to
//    instances by pose error, not by id. A row posed on another instance
//    fails oc on this one unless its posed model explains every point of
//    this instance's cloud (then the pose is right for this cloud too).
// A hypothesis without "cloud" whose obj_id differs from that of every BOP
// source is for another object (a results file of a multi-object
// estimator): listed in `other_object`. Everything else that matches nothing
// is listed in `unmatched`; nothing is dropped silently. Several hypotheses
// may match one source (the instance's hypotheses).
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "c3po/io/pose_list.hpp"
#include "c3po/method/certify_batch.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct GivenPoseSources {
  std::vector<CloudSource> sources;        // one per (hypothesis, source it matches), in file order
  std::vector<std::size_t> hypothesis;     // per source: index into the poses
  std::vector<std::size_t> instance;       // per source: index into the cloud sources
  std::vector<std::size_t> unmatched;      // indices into the poses
  std::vector<std::size_t> other_object;   // indices into the poses: an obj_id no BOP source has
};

// The key a hypothesis is matched by (see the rule above): its "cloud", or
// "scene_id/im_id" (decimal, no padding) for BOP rows.
std::string PoseMatchKey(const PoseHypothesis& pose);

GivenPoseSources MatchGivenPoses(const ObjectModel& object, const std::vector<CloudSource>& clouds,
                                 const std::vector<PoseHypothesis>& poses);

// The change the correction made to a given pose.
struct PoseChange {
  double rotation_degrees = 0.0;   // angle of R_given^T R_estimate
  double translation = 0.0;        // |t_estimate - t_given|, object units
};
PoseChange ChangeBetween(const Pose& given, const Pose& estimate);

// Per instance (cloud source) with at least one hypothesis: the certified
// hypothesis with the best fit (smallest oc distance, then the higher score,
// then the earlier line), or none; and the instance's row of a BOP results
// CSV: the chosen hypothesis, else the best fit among those the corrector
// returned a pose for (same order), or none.
struct InstanceVerdict {
  std::size_t instance = 0;                // index into the cloud sources
  std::vector<std::size_t> sources;        // its hypotheses' indices into GivenPoseSources::sources
  std::optional<std::size_t> chosen;       // index into GivenPoseSources::sources
  std::optional<std::size_t> best_fit;     // the same; == chosen when there is one
};
std::vector<InstanceVerdict> ChooseCertified(const GivenPoseSources& matched,
                                             const std::vector<PoseHypothesis>& poses,
                                             const CertifyBatchResult& result);

}  // namespace c3po
