// Automatic indicator sets, step 2: greedy set cover over small keypoint
// subsets, scoring on separate views, and the whole run (render -> label ->
// learn -> score).
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>

#include "c3po/authoring/indicators.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/base/parallel.hpp"

namespace c3po {
namespace {

bool SeesAll(std::uint64_t seen, std::uint64_t set) { return (seen & set) == set; }

// Every subset of {0..n-1} with 1..max_size elements, smaller sizes first,
// lexicographic within a size.
std::vector<std::uint64_t> CandidateSubsets(int n, int max_size) {
  std::vector<std::uint64_t> out;
  std::vector<int> chosen;
  for (int size = 1; size <= std::min(max_size, n); ++size) {
    // Iterate combinations of `size` indices in lexicographic order.
    chosen.resize(size);
    for (int i = 0; i < size; ++i) chosen[i] = i;
    for (;;) {
      std::uint64_t mask = 0;
      for (int i : chosen) mask |= std::uint64_t{1} << i;
      out.push_back(mask);
      int k = size - 1;
      while (k >= 0 && chosen[k] == n - size + k) --k;
      if (k < 0) break;
      ++chosen[k];
      for (int j = k + 1; j < size; ++j) chosen[j] = chosen[j - 1] + 1;
    }
  }
  return out;
}

IndicatorSet MaskToSet(std::uint64_t mask) {
  IndicatorSet set;
  for (int i = 0; i < 64; ++i) {
    if (mask >> i & 1) set.push_back(i);
  }
  return set;
}

std::uint64_t SetToMask(const IndicatorSet& set) {
  std::uint64_t mask = 0;
  for (int i : set) {
    if (i < 0 || i >= 64) throw std::invalid_argument("indicator set index out of [0, 64)");
    mask |= std::uint64_t{1} << i;
  }
  return mask;
}

// Owns one renderer per concurrent user (ParallelFor gives no thread ids).
class RendererPool {
 public:
  explicit RendererPool(const CameraIntrinsics& camera) : camera_(camera) {}
  std::unique_ptr<DepthRenderer> Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (free_.empty()) return std::make_unique<DepthRenderer>(camera_);
    auto renderer = std::move(free_.back());
    free_.pop_back();
    return renderer;
  }
  void Give(std::unique_ptr<DepthRenderer> renderer) {
    std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(std::move(renderer));
  }

 private:
  CameraIntrinsics camera_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<DepthRenderer>> free_;
};

std::vector<LabelledView> UsableLabels(const std::vector<ViewDegeneracy>& views, double borderline_distance,
                                       int* unusable) {
  std::vector<LabelledView> labels;
  *unusable = 0;
  for (const ViewDegeneracy& view : views) {
    if (!view.usable) {
      ++*unusable;
      continue;
    }
    labels.push_back({view.seen_mask, view.degenerate,
                      !view.degenerate && view.worst_hausdorff > borderline_distance, view.near_mask});
  }
  return labels;
}

}  // namespace

void SetLearningOptions::Check() const {
  if (max_set_size < 1 || max_set_size > 6) throw InputError("--max-set-size", "must be in [1, 6]");
  if (min_support < 1) throw InputError("--min-support", "must be at least 1");
  if (max_sets < 1) throw InputError("--max-sets", "must be at least 1");
  if (!(borderline_factor > 0 && borderline_factor <= 1)) throw InputError("--borderline", "must be in (0, 1]");
}

void AutoIndicatorOptions::Check() const {
  training.Check();
  if (test_views == 0 || test_views < -1) throw InputError("--test-views", "must be positive");
  degeneracy.Check();
  learning.Check();
}

LearnedSets LearnIndicatorSets(const std::vector<LabelledView>& views, int num_keypoints,
                               const SetLearningOptions& options) {
  options.Check();
  if (num_keypoints < 1 || num_keypoints > 64) throw std::invalid_argument("LearnIndicatorSets: 1..64 keypoints");
  LearnedSets learned;
  std::vector<std::uint64_t> degenerate_seen;
  std::vector<std::uint64_t> uncovered;   // seen masks of non-degenerate views not yet accepted
  bool any_degenerate = false;
  for (const LabelledView& view : views) {
    any_degenerate = any_degenerate || view.degenerate;
    if (view.degenerate || view.borderline) {
      degenerate_seen.push_back(view.seen_mask | view.near_mask);   // blocks what it nearly sees too
    } else {
      uncovered.push_back(view.seen_mask);
    }
  }
  if (!any_degenerate) {
    learned.accept_all = true;   // every training view pins the pose down: nd = 1 always
    return learned;
  }
  // Admissible: no degenerate training view sees the whole candidate.
  std::vector<std::uint64_t> admissible;
  const std::vector<std::uint64_t> candidates = CandidateSubsets(num_keypoints, options.max_set_size);
  learned.candidates = static_cast<int>(candidates.size());
  for (std::uint64_t candidate : candidates) {
    bool ok = true;
    for (std::uint64_t seen : degenerate_seen) {
      if (SeesAll(seen, candidate)) {
        ok = false;
        break;
      }
    }
    if (ok) admissible.push_back(candidate);
  }
  learned.admissible = static_cast<int>(admissible.size());
  // Greedy cover; candidates are ordered by size, so the first maximum is the
  // smallest set (a superset never accepts more than its subsets).
  while (static_cast<int>(learned.sets.size()) < options.max_sets && !uncovered.empty()) {
    int best_count = 0;
    std::uint64_t best = 0;
    for (std::uint64_t candidate : admissible) {
      int count = 0;
      for (std::uint64_t seen : uncovered) count += SeesAll(seen, candidate);
      if (count > best_count) {
        best_count = count;
        best = candidate;
      }
    }
    if (best_count < options.min_support) break;
    learned.sets.push_back(MaskToSet(best));
    learned.accepted_per_set.push_back(best_count);
    std::vector<std::uint64_t> rest;
    for (std::uint64_t seen : uncovered) {
      if (!SeesAll(seen, best)) rest.push_back(seen);
    }
    uncovered.swap(rest);
  }
  return learned;
}

SetScore ScoreIndicatorSets(const std::vector<IndicatorSet>& sets,
                            const std::vector<LabelledView>& views) {
  std::vector<std::uint64_t> masks;
  for (const IndicatorSet& set : sets) masks.push_back(SetToMask(set));
  SetScore score;
  int non_degenerate = 0;
  for (const LabelledView& view : views) {
    ++score.views;
    score.degenerate += view.degenerate;
    non_degenerate += !view.degenerate;
    bool accepted = masks.empty();   // no sets: nd = 1 always (CheckNonDegeneracy)
    for (std::uint64_t mask : masks) accepted = accepted || SeesAll(view.seen_mask, mask);
    if (!accepted) continue;
    ++score.accepted;
    (view.degenerate ? score.false_accepts : score.true_accepts) += 1;
  }
  if (score.accepted > 0) score.precision = static_cast<double>(score.true_accepts) / score.accepted;
  if (non_degenerate > 0) score.recall = static_cast<double>(score.true_accepts) / non_degenerate;
  return score;
}

std::string AutoIndicatorResult::EvidenceJson() const {
  nlohmann::json doc;
  doc["method"] = "c3po indicators --auto: ICP search for far fitting poses on rendered views, greedy set cover";
  doc["precision"] = test_score.precision;
  doc["recall"] = test_score.recall;
  doc["false_accepts"] = test_score.false_accepts;
  doc["test_views"] = test_score.views;
  doc["test_degenerate"] = test_score.degenerate;
  doc["training_precision"] = training_score.precision;
  doc["training_recall"] = training_score.recall;
  doc["views"] = training_score.views;
  doc["training_degenerate"] = training_score.degenerate;
  doc["seed"] = training_seed;
  doc["test_seed"] = test_seed;
  doc["eps_oc"] = eps_oc;
  doc["delta_nd"] = delta_nd;
  doc["noise_sigma"] = noise_sigma;
  doc["accept_all"] = learned.accept_all;
  doc["previous_sets_precision"] = current_test_score.precision;
  doc["previous_sets_recall"] = current_test_score.recall;
  // The deliberate views (face-on, edge-on, corner, partial) and how the sets treat them.
  nlohmann::json kinds = nlohmann::json::object();
  for (std::size_t i = 0; i < deliberate_views.size() && i < deliberate_labels.size(); ++i) {
    auto& k = kinds[ToString(deliberate_views[i].kind)];
    if (k.is_null()) k = {{"views", 0}, {"degenerate", 0}};
    k["views"] = k["views"].get<int>() + 1;
    k["degenerate"] = k["degenerate"].get<int>() + (deliberate_labels[i].usable && deliberate_labels[i].degenerate);
  }
  doc["deliberate_trained"] = deliberate_trained;
  doc["deliberate_views"] = kinds;
  doc["deliberate_false_accepts"] = deliberate_score.false_accepts;
  doc["deliberate_degenerate"] = deliberate_score.degenerate;
  return doc.dump();
}

namespace {

// Renders and labels every view (the deliberate ones, the random training and test views) on both
// cores into result->deliberate_labels, training_views and test_views.
void LabelViews(const ObjectModel& object, const ViewSamplingOptions& training, const ViewSamplingOptions& test,
                const DegeneracyOptions& degeneracy, const IndicatorProgress& progress, AutoIndicatorResult* result) {
  const std::vector<Pose> motions = DegeneracySearchMotions(object);
  const int random_start = static_cast<int>(result->deliberate_views.size());
  const int test_start = random_start + training.views;
  const int total = test_start + test.views;
  result->deliberate_labels.resize(random_start);
  result->training_views.resize(training.views);
  result->test_views.resize(test.views);
  RendererPool pool(training.camera);
  std::atomic<std::size_t> done{0};
  ParallelFor(0, total, [&](int item) {
    ThrowIfInterrupted();
    auto renderer = pool.Take();
    RenderedView view;
    ViewDegeneracy* label = nullptr;
    if (item < random_start) {
      view = RenderDeliberateView(object, training, result->noise_sigma, result->deliberate_views[item], item,
                                  renderer.get());
      label = &result->deliberate_labels[item];
    } else if (item < test_start) {
      view = RenderView(object, training, result->noise_sigma, item - random_start, renderer.get());
      label = &result->training_views[item - random_start];
    } else {
      view = RenderView(object, test, result->noise_sigma, item - test_start, renderer.get());
      label = &result->test_views[item - test_start];
    }
    pool.Give(std::move(renderer));
    *label = AnalyzeViewDegeneracy(object, view.cloud, view.camera_from_model, motions, degeneracy);
    const std::size_t finished = ++done;
    if (progress) progress(finished, static_cast<std::size_t>(total));
  });
}

// Learns the sets from the usable training labels (with the deliberate views when options.deliberate)
// and scores them, and the object's current sets, on the test and deliberate views.
void LearnAndScore(const ObjectModel& object, const AutoIndicatorOptions& options, double borderline,
                   AutoIndicatorResult* result) {
  std::vector<LabelledView> training_labels =
      UsableLabels(result->training_views, borderline, &result->unusable_training_views);
  const std::vector<LabelledView> test_labels =
      UsableLabels(result->test_views, borderline, &result->unusable_test_views);
  const std::vector<LabelledView> deliberate_labels =
      UsableLabels(result->deliberate_labels, borderline, &result->unusable_deliberate_views);
  if (options.deliberate) {
    training_labels.insert(training_labels.begin(), deliberate_labels.begin(), deliberate_labels.end());
  }
  result->learned = LearnIndicatorSets(training_labels, object.num_keypoints(), options.learning);
  result->training_score = ScoreIndicatorSets(result->learned.sets, training_labels);
  result->test_score = ScoreIndicatorSets(result->learned.sets, test_labels);
  result->current_test_score = ScoreIndicatorSets(object.spec().indicator_sets, test_labels);
  result->deliberate_score = ScoreIndicatorSets(result->learned.sets, deliberate_labels);
  result->current_deliberate_score = ScoreIndicatorSets(object.spec().indicator_sets, deliberate_labels);
  result->deliberate_trained = options.deliberate;
}

}  // namespace

AutoIndicatorResult LearnIndicatorSetsFromViews(const ObjectModel& object,
                                                const AutoIndicatorOptions& options,
                                                const IndicatorProgress& progress) {
  options.Check();
  const auto start_time = std::chrono::steady_clock::now();
  AutoIndicatorResult result;
  DegeneracyOptions degeneracy = options.degeneracy;
  if (degeneracy.eps_oc <= 0) degeneracy.eps_oc = object.spec().eps_oc;
  if (degeneracy.delta_nd <= 0) degeneracy.delta_nd = object.spec().delta_nd;
  result.eps_oc = degeneracy.eps_oc;
  result.delta_nd = degeneracy.delta_nd;
  result.noise_sigma = options.training.noise_sigma >= 0 ? options.training.noise_sigma : degeneracy.eps_oc / 8.0;
  const ViewSamplingOptions& training = options.training;
  ViewSamplingOptions test = options.training;
  test.seed = options.test_seed != 0 ? options.test_seed : training.seed + 1000003;
  if (options.test_views > 0) test.views = options.test_views;
  result.training_seed = training.seed;
  result.test_seed = test.seed;

  // The deliberate (face-on, edge-on, corner, partial) views are always
  // labelled and scored; with options.deliberate they are training views too.
  // Test views are random only.
  result.deliberate_views = DeliberateViews(object, options.deliberate_views);
  LabelViews(object, training, test, degeneracy, progress, &result);
  const double borderline = options.learning.borderline_factor * degeneracy.tolerance_factor * degeneracy.eps_oc;
  LearnAndScore(object, options, borderline, &result);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

}  // namespace c3po
