// Batch certification (certify_batch.hpp): the loop behind certify, eval and
// self-training, and the one `--eps-oc auto` decision.
#include "c3po/method/certify_batch.hpp"

#include <atomic>
#include <chrono>
#include <exception>
#include <stdexcept>

#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/io/cloud_io.hpp"

namespace c3po {
namespace {

// --eps-oc auto (docs/method.md "Automatic ε_oc"): eps_oc from the clouds
// that were processed and the oc distances of their estimates, then both
// certificates are decided again with it. With a budget m the distance used is
// each cloud's (m+1)-th largest point distance (budget_distance: the m
// farthest points never set eps_oc), and nd is decided again too: nd_m and the
// local test count only the points accepted under the new eps_oc.
AutoEpsOcResult DecideAutoEpsOc(const ObjectModel& object, const std::vector<PointSet>& clouds,
                                const CertifyBatchOptions& options, CertifyBatchResult* result) {
  std::vector<PointSet> usable;
  std::vector<double> oc_distances;
  for (std::size_t i = 0; i < result->outcomes.size(); ++i) {
    const CloudOutcome& outcome = result->outcomes[i];
    if (!outcome.processed()) continue;
    usable.push_back(clouds[i]);
    if (outcome.estimate.ok()) oc_distances.push_back(outcome.estimate.certificate.oc.budget_distance);
  }
  const AutoEpsOcResult chosen = EstimateEpsOc(object, usable, options.auto_eps_oc_options, &oc_distances);
  CertificateOptions decided = options.pipeline.certificate;
  decided.eps_oc = chosen.eps_oc;
  // Only estimates that have a pose have oc evidence: a failed registration
  // keeps oc = 0 (its distances were never computed) and records eps_oc.
  PipelineOptions pipeline = options.pipeline;
  pipeline.certificate = decided;
  const auto decide = [&](const PointSet& cloud, PoseEstimate* estimate) {
    if (estimate->ok()) {
      // The free-space evidence does not depend on eps_oc beyond its tolerance
      // (decided with the options' eps_oc) and the frame is released: kept.
      // Rivals are searched again without the free-space filter (stricter).
      const FreeSpace free_space = estimate->certificate.free_space;
      estimate->certificate = Certify(object, cloud, estimate->scene_from_model, estimate->keypoints, decided);
      estimate->certificate.free_space = free_space;
      CompleteCertificate(object, cloud, pipeline, nullptr, estimate);
    } else {
      estimate->certificate.oc.eps_oc = chosen.eps_oc;
    }
  };
  for (std::size_t i = 0; i < result->outcomes.size(); ++i) {
    CloudOutcome& outcome = result->outcomes[i];
    if (!outcome.processed()) continue;
    decide(clouds[i], &outcome.estimate);
    if (outcome.uncorrected) decide(clouds[i], &outcome.uncorrected.value());
  }
  return chosen;
}

std::string WhereOf(const CloudSource& source) { return source.path.empty() ? source.name : source.path; }

}  // namespace

std::vector<CloudSource> CloudFileSources(const std::vector<std::string>& paths) {
  std::vector<CloudSource> sources;
  sources.reserve(paths.size());
  for (const std::string& path : paths) {
    CloudSource source;
    source.name = path;
    source.path = path;
    source.load = [path]() { return ReadCloud(path); };
    sources.push_back(std::move(source));
  }
  return sources;
}

std::vector<CloudSource> DatasetSources(const Dataset& dataset, const DatasetFrames& frames) {
  std::vector<CloudSource> sources;
  sources.reserve(dataset.entries.size());
  for (std::size_t i = 0; i < dataset.entries.size(); ++i) {
    const DatasetEntry& entry = dataset.entries[i];
    CloudSource source;
    source.name = entry.cloud;
    source.path = dataset.CloudPath(i);
    source.dataset_index = i;
    const std::string path = source.path;
    source.load = [path]() { return ReadCloud(path); };
    source.given_keypoints = entry.detected_keypoints;
    source.scene_from_model_truth = entry.pose;
    if (frames) source.load_frame = [frames, entry]() { return frames(entry); };
    sources.push_back(std::move(source));
  }
  return sources;
}

std::vector<CloudSource> InMemorySources(const std::vector<PointSet>& clouds,
                                         const std::vector<PointSet>& keypoints,
                                         const std::vector<DepthView>* frames) {
  if (!keypoints.empty() && keypoints.size() != clouds.size()) {
    throw std::invalid_argument("InMemorySources: keypoints.size() != clouds.size()");
  }
  if (frames != nullptr && frames->size() != clouds.size()) {
    throw std::invalid_argument("InMemorySources: frames->size() != clouds.size()");
  }
  std::vector<CloudSource> sources;
  sources.reserve(clouds.size());
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    CloudSource source;
    source.name = "#" + std::to_string(i);
    source.dataset_index = i;
    const PointSet* cloud = &clouds[i];
    source.load = [cloud]() { return *cloud; };
    if (!keypoints.empty()) source.given_keypoints = keypoints[i];
    if (frames != nullptr) {
      const DepthView view = (*frames)[i];
      source.load_frame = [view]() { return view; };
    }
    sources.push_back(std::move(source));
  }
  return sources;
}

PointSet LoadSourceCloud(const CloudSource& source, std::optional<SegmentCloud>* segment_counts, DepthView* frame,
                         std::optional<PointSet>* evidence) {
  if (!source.load_segment) {
    PointSet cloud = source.load();
    DepthView view;
    if ((frame != nullptr || evidence != nullptr) && source.load_frame) view = source.load_frame();
    if (evidence != nullptr && view.evidence) *evidence = *view.evidence;
    view.evidence.reset();
    if (frame != nullptr) *frame = std::move(view);
    return cloud;
  }
  SegmentCloud segment = source.load_segment();
  PointSet cloud = std::move(segment.cloud);
  segment.cloud.resize(3, 0);   // the counts stay for the output
  if (!segment.evidence) segment.evidence_points = static_cast<std::size_t>(cloud.cols());
  if (evidence != nullptr) *evidence = std::move(segment.evidence);
  segment.evidence.reset();
  if (frame != nullptr) {
    frame->depth = segment.depth;
    frame->mask = segment.mask;
    frame->camera = segment.camera;
    frame->support = segment.support_plane;
    frame->support_distance = segment.support_plane_distance;
  }
  segment.depth.reset();        // the counts never keep the image alive (~1 MB per instance)
  segment.mask.reset();
  if (segment_counts != nullptr) *segment_counts = segment;
  segment.cloud = std::move(cloud);
  RequireUsableSegment(segment, source.name);   // throws the reason (the counts are already out)
  return std::move(segment.cloud);
}

void CertifyBatchOptions::Check() const {
  pipeline.Check();
  if (auto_eps_oc) auto_eps_oc_options.Check();
  for (const KnownObject& other : other_objects) other.Check();
  if (auto_eps_oc && !other_objects.empty()) {
    throw std::invalid_argument("CertifyBatchOptions: other_objects need an eps_oc given, not auto");
  }
}

namespace {

void RequireDetectorOrKeypoints(const std::vector<CloudSource>& sources, const Detector* detector) {
  if (detector) return;
  for (const CloudSource& source : sources) {
    if (!source.given_keypoints) {
      throw InputError(WhereOf(source),
                       "no detector, and no given keypoints (a manifest line's \"detected_keypoints\")");
    }
  }
}

// Runs `step`; any error but an interruption becomes the outcome's failure (kind and message).
template <typename Step>
void RecordFailure(CloudOutcome* outcome, CloudOutcome::Failure kind, const Step& step) {
  try {
    step();
  } catch (const Interrupted&) {
    throw;
  } catch (const std::exception& e) {
    outcome->failure = kind;
    outcome->error = e.what();
  }
}

void DetectKeypoints(const CloudSource& source, const PointSet& cloud, const Detector* detector, int num_keypoints,
                     CloudOutcome* outcome) {
  outcome->detected_keypoints = detector ? detector->Detect(cloud) : *source.given_keypoints;
  if (outcome->detected_keypoints.cols() != num_keypoints) {
    throw InputError(WhereOf(source), "detected " + std::to_string(outcome->detected_keypoints.cols()) +
                                          " keypoints, object has " + std::to_string(num_keypoints));
  }
}

// Counts of the processed outcomes: errors, certified, oc and nd passed.
void CountOutcomes(CertifyBatchResult* result) {
  for (const CloudOutcome& outcome : result->outcomes) {
    if (!outcome.processed()) {
      ++result->errors;
      continue;
    }
    result->certified += outcome.estimate.certified();
    result->oc += outcome.estimate.certificate.oc.passed;
    result->nd += outcome.estimate.certificate.nd.passed;
  }
}

}  // namespace

CertifyBatchResult CertifyBatch(const ObjectModel& object, const std::vector<CloudSource>& sources,
                                const Detector* detector, const CertifyBatchOptions& options,
                                const ProgressCallback& progress, const CloudVisitor& visit) {
  options.Check();
  RequireDetectorOrKeypoints(sources, detector);
  CertifyBatchResult result;
  result.outcomes.resize(sources.size());
  result.certificate = options.pipeline.certificate;
  std::vector<PointSet> clouds(options.auto_eps_oc ? sources.size() : 0);   // kept for auto eps_oc
  PipelineOptions uncorrected = options.pipeline;
  uncorrected.correct = false;
  std::atomic<std::size_t> done{0};
  // One source: load, detect, estimate and certify (the free-space test from its frame), judge
  // against its truth, hand to the visitor; failures are recorded in its outcome.
  const auto certify_source = [&](std::size_t i, std::chrono::steady_clock::time_point start) {
    const CloudSource& source = sources[i];
    CloudOutcome& outcome = result.outcomes[i];
    PointSet cloud;                    // the estimate's cloud
    std::optional<PointSet> evidence;  // the certificate's, when it is another (image inputs)
    DepthView view;                    // image inputs: the frame, for the free-space test
    RecordFailure(&outcome, CloudOutcome::Failure::kLoad,
                  [&] { cloud = LoadSourceCloud(source, &outcome.segment, &view, &evidence); });
    if (!outcome.processed()) return;
    const double load_ms = MillisecondsSince(start);
    const auto detect_start = std::chrono::steady_clock::now();
    RecordFailure(&outcome, CloudOutcome::Failure::kDetect,
                  [&] { DetectKeypoints(source, cloud, detector, object.num_keypoints(), &outcome); });
    if (!outcome.processed()) return;
    const double detect_ms = MillisecondsSince(detect_start);
    const std::optional<FreeSpaceTest> free_space = MakeFreeSpaceTest(
        object, view, options.pipeline.certificate.free_space, options.pipeline.certificate.eps_oc);
    const FreeSpaceTest* free_space_test = free_space ? &*free_space : nullptr;
    const PointSet* judged = evidence ? &*evidence : nullptr;
    if (options.also_uncorrected) {
      outcome.uncorrected =
          EstimateAndCertify(object, cloud, outcome.detected_keypoints, uncorrected, free_space_test, judged);
    }
    outcome.estimate =
        EstimateAndCertify(object, cloud, outcome.detected_keypoints, options.pipeline, free_space_test, judged);
    if (!options.other_objects.empty() && outcome.estimate.certified()) {   // part of the certificate's time
      const auto identity_start = std::chrono::steady_clock::now();
      outcome.estimate.certificate.identity = CheckIdentity(options.other_objects, cloud, view, judged);
      outcome.estimate.ms_stages.identity = MillisecondsSince(identity_start);
      outcome.estimate.milliseconds += outcome.estimate.ms_stages.identity;
    }
    outcome.estimate.ms_stages.load = load_ms;
    outcome.estimate.ms_stages.detect = detect_ms;
    if (source.scene_from_model_truth && outcome.estimate.ok()) {
      outcome.truth_hausdorff = PosedModelHausdorff(object, StridedColumns(object.sample(), 2000),
                                                    *source.scene_from_model_truth, outcome.estimate.scene_from_model);
    }
    outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (visit) visit(i, evidence ? *evidence : cloud, free_space_test, &outcome);
    if (options.auto_eps_oc) clouds[i] = evidence ? std::move(*evidence) : std::move(cloud);
  };
  ParallelFor(0, static_cast<int>(sources.size()), [&](int i) {
    ThrowIfInterrupted();
    const auto start = std::chrono::steady_clock::now();
    certify_source(static_cast<std::size_t>(i), start);
    CloudOutcome& outcome = result.outcomes[static_cast<std::size_t>(i)];
    if (outcome.seconds == 0.0) {   // failed before the estimate
      outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    if (progress) progress(++done, sources.size());
  });
  if (options.auto_eps_oc) {
    result.auto_eps_oc = DecideAutoEpsOc(object, clouds, options, &result);
    result.certificate.eps_oc = result.auto_eps_oc->eps_oc;
  }
  CountOutcomes(&result);
  return result;
}

}  // namespace c3po
