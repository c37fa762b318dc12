#include "c3po/method/given_poses.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <utility>
#include <unordered_map>

namespace c3po {

std::string PoseMatchKey(const PoseHypothesis& pose) {
  if (!pose.cloud.empty()) return pose.cloud;
  if (pose.scene_id && pose.im_id) return std::to_string(*pose.scene_id) + "/" + std::to_string(*pose.im_id);
  return "";
}

GivenPoseSources MatchGivenPoses(const ObjectModel& object, const std::vector<CloudSource>& clouds,
                                 const std::vector<PoseHypothesis>& poses) {
  std::unordered_map<std::string, std::size_t> by_name;
  std::map<std::pair<int, int>, std::vector<std::size_t>> by_image;   // BOP sources of (scene_id, im_id)
  std::set<int> obj_ids;                                              // of the BOP sources
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    by_name.emplace(clouds[i].name, i);   // first wins
    if (const auto& p = clouds[i].provenance) {
      by_image[{p->scene_id, p->im_id}].push_back(i);
      obj_ids.insert(p->obj_id);
    }
  }
  GivenPoseSources matched;
  const auto add = [&](std::size_t h, std::size_t i) {
    CloudSource source = clouds[i];
    source.name += " (line " + std::to_string(poses[h].line) + ")";
    source.given_keypoints = poses[h].scene_from_model * object.keypoints();
    matched.sources.push_back(std::move(source));
    matched.hypothesis.push_back(h);
    matched.instance.push_back(i);
  };
  for (std::size_t h = 0; h < poses.size(); ++h) {
    const PoseHypothesis& pose = poses[h];
    if (!pose.cloud.empty()) {
      const auto it = by_name.find(pose.cloud);
      if (it == by_name.end()) {
        matched.unmatched.push_back(h);
      } else {
        add(h, it->second);
      }
      continue;
    }
    if (pose.obj_id && !obj_ids.empty() && obj_ids.count(*pose.obj_id) == 0) {
      matched.other_object.push_back(h);
      continue;
    }
    bool any = false;
    if (pose.scene_id && pose.im_id) {
      const auto it = by_image.find({*pose.scene_id, *pose.im_id});
      if (it != by_image.end()) {
        for (std::size_t i : it->second) {
          if (pose.obj_id && clouds[i].provenance->obj_id != *pose.obj_id) continue;
          add(h, i);
          any = true;
        }
      }
    }
    if (!any) matched.unmatched.push_back(h);
  }
  return matched;
}

PoseChange ChangeBetween(const Pose& given, const Pose& estimate) {
  PoseChange change;
  const double cosine = std::clamp(((given.R.transpose() * estimate.R).trace() - 1.0) / 2.0, -1.0, 1.0);
  change.rotation_degrees = std::acos(cosine) * 180.0 / M_PI;
  change.translation = (estimate.t - given.t).norm();
  return change;
}

std::vector<InstanceVerdict> ChooseCertified(const GivenPoseSources& matched,
                                             const std::vector<PoseHypothesis>& poses,
                                             const CertifyBatchResult& result) {
  // s fits better than t: smaller oc distance (not finite = worst), then the
  // higher score (file order keeps the earlier line on a full tie).
  auto fit_of = [&](std::size_t s) {
    const double d = result.outcomes[s].estimate.certificate.oc.max_point_distance;
    return std::isfinite(d) ? d : std::numeric_limits<double>::infinity();
  };
  auto better = [&](std::size_t s, std::size_t t) {
    const double fit = fit_of(s);
    const double other_fit = fit_of(t);
    return fit < other_fit ||
           (fit == other_fit && poses[matched.hypothesis[s]].score > poses[matched.hypothesis[t]].score);
  };
  std::map<std::size_t, InstanceVerdict> verdicts;
  for (std::size_t s = 0; s < matched.sources.size(); ++s) {
    InstanceVerdict& verdict = verdicts[matched.instance[s]];
    verdict.instance = matched.instance[s];
    verdict.sources.push_back(s);
    const CloudOutcome& outcome = result.outcomes[s];
    if (outcome.certified()) {
      if (!verdict.chosen || better(s, *verdict.chosen)) verdict.chosen = s;
    } else if (outcome.processed() && outcome.estimate.ok()) {
      if (!verdict.best_fit || better(s, *verdict.best_fit)) verdict.best_fit = s;   // best uncertified so far
    }
  }
  std::vector<InstanceVerdict> out;
  for (auto& [instance, verdict] : verdicts) {
    if (verdict.chosen) verdict.best_fit = verdict.chosen;
    out.push_back(std::move(verdict));
  }
  return out;
}

}  // namespace c3po
