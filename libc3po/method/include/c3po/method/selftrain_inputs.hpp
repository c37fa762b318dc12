#pragma once
// What self-training learns from when its clouds come from cameras (issue 18
// part 3; docs/method.md "Self-training on camera frames"): the CloudSources of
// the one batch path (certify_batch.hpp, image_sources.hpp: --bop, --depth /
// --mask, datasets), read into memory with the image each came from, then the
// paper's augmentation (Section VIII-D): several copies of every real
// instance, each with 10 % of its points dropped and 1 mm Gaussian noise added.
// The image is the unit of the validation split (SelfTrain's `groups`), so no
// copy of a held-out image's instance is trained on.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/method/certify_batch.hpp"
#include "c3po/method/detector.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct AugmentOptions {
  int copies = 1;                // augmented copies per instance (0 = the instances as read, unchanged)
  double drop_fraction = 0.1;    // points dropped from each copy (the same count for every copy of a cloud)
  double noise_sigma = 0.001;    // Gaussian noise per coordinate, object units (1 mm for metre objects)
  std::uint64_t seed = 0;        // copy c of instance i draws from Rng::ForItem(seed, i * copies + c)
  void Check() const;            // throws std::invalid_argument
};

// Unlabelled clouds with their provenance. groups[i]: the validation unit of
// clouds[i] (one per image for BOP sources, keyed (scene_id, im_id); one per
// source otherwise). truth[i]: the source's ground truth (reporting only).
// labels[i]: the object the cloud shows when known ("obj_000005" for a BOP
// instance of obj_id 5, the name annotate gives models/obj_000005.ply; a
// manifest's "object"), "" otherwise; never used for training, only to
// report what a mixed dataset's clouds of each object taught. frames[i]: the
// depth frame clouds[i] came from (an invalid view for other sources; empty =
// none at all): self-training certifies with the free-space test where a
// frame is known, as `certify` does.
struct UnlabelledClouds {
  std::vector<PointSet> clouds;
  std::vector<DepthView> frames;
  std::vector<int> groups;
  std::vector<std::optional<Pose>> truth;
  std::vector<std::string> names;
  std::vector<std::string> labels;
  std::vector<std::string> skipped;   // sources that could not be read: the InputError text
  bool AllHaveTruth() const;          // non-empty and every cloud has a truth
};

// Reads every source with LoadSourceCloud (in parallel); a source that cannot
// be read (e.g. a segment with no valid depth) is skipped and its error kept.
UnlabelledClouds LoadUnlabelledClouds(const std::vector<CloudSource>& sources);

// `copies` augmented copies of every cloud (in order: instance 0's copies,
// then instance 1's, ...), each keeping its instance's group, truth and name
// (+ "#c") and frame. A copy keeps n - round(drop_fraction * n) points (at least 1, in
// their original order) and adds N(0, noise_sigma^2) to every coordinate.
// std::invalid_argument when the per-cloud vectors differ in length.
UnlabelledClouds Augment(const UnlabelledClouds& instances, const AugmentOptions& options);

// The validation split of self-training and of supervised training on camera
// frames: indices into `count` clouds, validation first. Without groups, a
// seeded shuffle whose first round(fraction * count) (at least 1, at most
// count - 1) are held out. With `groups` (one per cloud, e.g. the image of
// each instance and of its augmented copies): whole groups in a seeded order
// are held out until the validation part reaches that size; at least one
// group is held out and one trained on (InputError naming `command` with
// fewer than 2 groups). Requires count >= 2 (std::invalid_argument).
struct ValidationSplit {
  std::vector<int> validation;
  std::vector<int> train;
};
ValidationSplit SplitValidation(std::size_t count, const std::vector<int>* groups, double fraction,
                                std::uint64_t seed, const std::string& command);

// Supervised labels from ground truth (`c3po train --bop`): every cloud with
// the object's keypoints posed at its truth, truth[i] * object.keypoints(),
// in the cloud's frame (the camera's, for BOP instances). InputError naming
// `command` and the cloud when a cloud has no ground truth.
std::vector<TrainingSample> LabelWithTruth(const UnlabelledClouds& clouds, const ObjectModel& object,
                                           const std::string& command);

}  // namespace c3po
