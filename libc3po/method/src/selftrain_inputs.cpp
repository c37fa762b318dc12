// Self-training inputs from cameras: loading CloudSources, the paper's
// augmentation (selftrain_inputs.hpp).
#include "c3po/method/selftrain_inputs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "c3po/base/error.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/base/random.hpp"

namespace c3po {

void AugmentOptions::Check() const {
  if (copies < 0 || copies > 1000) throw std::invalid_argument("copies must be in [0, 1000]");
  if (!(drop_fraction >= 0 && drop_fraction < 1)) throw std::invalid_argument("drop fraction must be in [0, 1)");
  if (!(noise_sigma >= 0 && std::isfinite(noise_sigma))) throw std::invalid_argument("noise sigma must be >= 0");
}

bool UnlabelledClouds::AllHaveTruth() const {
  return !clouds.empty() &&
         std::all_of(truth.begin(), truth.end(), [](const std::optional<Pose>& t) { return t.has_value(); });
}

UnlabelledClouds LoadUnlabelledClouds(const std::vector<CloudSource>& sources) {
  std::vector<PointSet> clouds(sources.size());
  std::vector<DepthView> frames(sources.size());
  std::vector<std::string> errors(sources.size());
  ParallelFor(0, static_cast<int>(sources.size()), [&](int i) {
    try {
      clouds[i] = LoadSourceCloud(sources[i], nullptr, &frames[i]);
    } catch (const std::exception& e) {
      errors[i] = e.what();
      if (errors[i].empty()) errors[i] = sources[i].name + ": unreadable";
    }
  });
  UnlabelledClouds result;
  std::map<std::pair<int, int>, int> image_groups;
  int next_group = 0;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    // The group is decided before skipping, so it never depends on which
    // sources failed.
    int group = 0;
    if (sources[i].provenance) {
      const auto key = std::make_pair(sources[i].provenance->scene_id, sources[i].provenance->im_id);
      const auto found = image_groups.find(key);
      group = found != image_groups.end() ? found->second : (image_groups[key] = next_group++);
    } else {
      group = next_group++;
    }
    if (!errors[i].empty()) {
      result.skipped.push_back(errors[i]);
      continue;
    }
    result.clouds.push_back(std::move(clouds[i]));
    result.frames.push_back(std::move(frames[i]));
    result.groups.push_back(group);
    result.truth.push_back(sources[i].scene_from_model_truth);
    result.names.push_back(sources[i].name);
    char label[32] = "";
    if (sources[i].provenance) std::snprintf(label, sizeof label, "obj_%06d", sources[i].provenance->obj_id);
    result.labels.push_back(label);
  }
  return result;
}

UnlabelledClouds Augment(const UnlabelledClouds& instances, const AugmentOptions& options) {
  options.Check();
  const std::size_t count = instances.clouds.size();
  if (instances.groups.size() != count || instances.truth.size() != count || instances.names.size() != count ||
      instances.labels.size() != count || (!instances.frames.empty() && instances.frames.size() != count)) {
    throw std::invalid_argument("Augment: groups, truth, names, labels (and frames) must have one entry per cloud");
  }
  if (options.copies == 0) return instances;
  const std::size_t copies = static_cast<std::size_t>(options.copies);
  const std::size_t total = instances.clouds.size() * copies;
  UnlabelledClouds result;
  result.skipped = instances.skipped;
  result.clouds.resize(total);
  ParallelFor(0, static_cast<int>(total), [&](int k) {
    const std::size_t i = static_cast<std::size_t>(k) / copies;
    const PointSet& cloud = instances.clouds[i];
    Rng rng = Rng::ForItem(options.seed, static_cast<std::uint64_t>(k));
    const Eigen::Index n = cloud.cols();
    const Eigen::Index dropped =
        std::min<Eigen::Index>(n - 1, static_cast<Eigen::Index>(std::lround(options.drop_fraction * n)));
    // A seeded partial Fisher-Yates picks the dropped points.
    std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
    std::iota(order.begin(), order.end(), 0);
    for (Eigen::Index j = 0; j < dropped; ++j) {
      std::swap(order[j], order[j + rng.UniformInt(static_cast<int>(n - j))]);
    }
    std::vector<Eigen::Index> kept(order.begin() + dropped, order.end());
    std::sort(kept.begin(), kept.end());
    PointSet copy(3, static_cast<Eigen::Index>(kept.size()));
    for (std::size_t j = 0; j < kept.size(); ++j) {
      copy.col(static_cast<Eigen::Index>(j)) = cloud.col(kept[j]);
      if (options.noise_sigma > 0) {
        for (int r = 0; r < 3; ++r) copy(r, static_cast<Eigen::Index>(j)) += options.noise_sigma * rng.Normal();
      }
    }
    result.clouds[k] = std::move(copy);
  });
  for (std::size_t k = 0; k < total; ++k) {
    const std::size_t i = k / copies;
    result.groups.push_back(instances.groups[i]);
    result.truth.push_back(instances.truth[i]);
    result.names.push_back(instances.names[i] + "#" + std::to_string(k % copies));
    result.labels.push_back(instances.labels[i]);
    if (!instances.frames.empty()) result.frames.push_back(instances.frames[i]);
  }
  return result;
}

namespace {
std::vector<int> Shuffled(std::vector<int> indices, Rng rng) {
  for (int i = static_cast<int>(indices.size()) - 1; i > 0; --i) {
    std::swap(indices[i], indices[rng.UniformInt(i + 1)]);
  }
  return indices;
}
}  // namespace

ValidationSplit SplitValidation(std::size_t count, const std::vector<int>* groups, double fraction,
                                std::uint64_t seed, const std::string& command) {
  if (count < 2) throw std::invalid_argument("SplitValidation: need at least 2 clouds");
  if (groups != nullptr && groups->size() != count) {
    throw std::invalid_argument("SplitValidation: groups must match the clouds");
  }
  // Deterministic split: a seeded shuffle, the first part held out.
  std::vector<int> all(count);
  std::iota(all.begin(), all.end(), 0);
  all = Shuffled(all, Rng::ForItem(seed, 0xC3B0));
  std::size_t validation_count =
      std::clamp<std::size_t>(static_cast<std::size_t>(std::lround(fraction * count)), 1, count - 1);
  if (groups != nullptr) {
    // Split by group (e.g. by image: the augmented copies of one real
    // instance, and the instances of one image, are never on both sides).
    std::vector<int> distinct(groups->begin(), groups->end());
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    if (distinct.size() < 2) {
      throw InputError(command, "the clouds come from one image: need at least 2 to split into training and "
                                "validation");
    }
    distinct = Shuffled(distinct, Rng::ForItem(seed, 0xC3B0));
    std::vector<std::vector<int>> members(distinct.size());
    std::map<int, std::size_t> rank_of;
    for (std::size_t r = 0; r < distinct.size(); ++r) rank_of[distinct[r]] = r;
    for (int i : all) members[rank_of.at((*groups)[i])].push_back(i);
    const std::size_t target = validation_count;
    all.clear();
    validation_count = 0;
    for (std::size_t r = 0; r < members.size(); ++r) {
      const bool held_out = r == 0 || (validation_count < target && r + 1 < members.size());
      if (held_out) validation_count += members[r].size();
      all.insert(all.end(), members[r].begin(), members[r].end());
    }
  }
  ValidationSplit split;
  split.validation.assign(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(validation_count));
  split.train.assign(all.begin() + static_cast<std::ptrdiff_t>(validation_count), all.end());
  return split;
}

std::vector<TrainingSample> LabelWithTruth(const UnlabelledClouds& clouds, const ObjectModel& object,
                                           const std::string& command) {
  if (clouds.truth.size() != clouds.clouds.size() || clouds.names.size() != clouds.clouds.size()) {
    throw std::invalid_argument("LabelWithTruth: truth and names must have one entry per cloud");
  }
  std::vector<TrainingSample> samples;
  samples.reserve(clouds.clouds.size());
  for (std::size_t i = 0; i < clouds.clouds.size(); ++i) {
    if (!clouds.truth[i]) {
      throw InputError(command, clouds.names[i] + ": no ground-truth pose to label it with (train needs "
                                                  "scene_gt.json, or a manifest with keypoints)");
    }
    // Label = the keypoints posed at the truth: scene_from_model * keypoints.
    samples.push_back({clouds.clouds[i], *clouds.truth[i] * object.keypoints(), {}});
  }
  return samples;
}

}  // namespace c3po
