// Simulated and rendered depth samples (synth.hpp).
#include "c3po/synth/synth.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "c3po/base/error.hpp"

namespace c3po {
namespace {

// Two independent standard normals (Marsaglia's polar method: one log and
// one sqrt per pair, no trigonometry).
Eigen::Vector2d NormalPair(Rng& rng) {
  for (;;) {
    const double u = 2.0 * rng.Uniform() - 1.0;
    const double v = 2.0 * rng.Uniform() - 1.0;
    const double s = u * u + v * v;
    if (s > 0.0 && s < 1.0) {
      const double factor = std::sqrt(-2.0 * std::log(s) / s);
      return {u * factor, v * factor};
    }
  }
}

}  // namespace

void SynthOptions::Check() const {
  if (count < 1) throw InputError("--count: must be at least 1");
  if (shard.count < 1 || shard.index < 1 || shard.index > shard.count) throw InputError("--shard: need 1 <= K <= N");
  if (shard.count > count) throw InputError("--shard: more parts than clouds (--count)");
  if (points < 1 || points > 10000000) throw InputError("--points: must be in [1, 10000000]");
  if (!(noise >= 0.0) || !std::isfinite(noise)) throw InputError("--noise: must be a distance >= 0");
  if (!(dropout >= 0.0 && dropout < 1.0)) throw InputError("--dropout: must be in [0, 1)");
  if (min_points < -1) throw InputError("--min-points: must be >= 0");
  if (ResolvedMinPoints() > points) throw InputError("--min-points: must not exceed --points");
  if (!(perturb_sigma >= 0.0) || !std::isfinite(perturb_sigma)) {
    throw InputError("--perturb-sigma: must be >= 0");
  }
  if (!(perturb_fraction >= 0.0 && perturb_fraction <= 1.0)) {
    throw InputError("--perturb-fraction: must be in [0, 1]");
  }
  if (!(visibility_tolerance == -1.0 || (visibility_tolerance >= 0.0 &&
                                         std::isfinite(visibility_tolerance)))) {
    throw InputError("visibility tolerance: must be >= 0");
  }
  if (max_attempts < 1) throw InputError("max attempts: must be at least 1");
  camera.Check();
  pose.Check();
}

SynthGenerator::SynthGenerator(const Mesh& mesh, PointSet keypoints, const SynthOptions& options,
                               std::string where)
    : mesh_(mesh), keypoints_(std::move(keypoints)), options_(options), where_(std::move(where)) {
  options_.Check();
  if (mesh_.empty()) throw InputError(where_ + ": the mesh has no triangles");
  try {
    mesh_.Validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(where_ + ": " + e.what());
  }
  if (!keypoints_.allFinite()) throw InputError(where_ + ": keypoints: non-finite coordinates");
  const Eigen::AlignedBox3d box = mesh_.BoundingBox();
  centre_ = box.center();
  diameter_ = box.diagonal().norm();
  if (!(diameter_ > 0.0)) throw InputError(where_ + ": the mesh has zero extent");
  const auto& pose = options_.pose;
  distance_ = (pose.distance_min == 0.0 && pose.distance_max == 0.0)
                  ? DefaultDistanceRange(diameter_, options_.camera)
                  : std::make_pair(pose.distance_min, pose.distance_max);
  cumulative_area_.reserve(static_cast<std::size_t>(mesh_.triangles.cols()));
  double total = 0.0;
  for (Eigen::Index t = 0; t < mesh_.triangles.cols(); ++t) {
    const Eigen::Vector3d a = mesh_.vertices.col(mesh_.triangles(0, t));
    const Eigen::Vector3d b = mesh_.vertices.col(mesh_.triangles(1, t));
    const Eigen::Vector3d c = mesh_.vertices.col(mesh_.triangles(2, t));
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative_area_.push_back(total);
  }
  if (!(total > 0.0)) throw InputError(where_ + ": the mesh has zero surface area");
  BuildAliasTable();
  cull_back_faces_ = IsClosedOutward(mesh_);
}

void SynthGenerator::BuildAliasTable() {
  // Vose's alias method: triangle t is drawn with probability area_t / total
  // in O(1) (a uniform column, then a biased coin between it and its alias).
  const std::size_t n = cumulative_area_.size();
  const double total = cumulative_area_.back();
  std::vector<double> scaled(n);
  for (std::size_t t = 0; t < n; ++t) {
    const double area = cumulative_area_[t] - (t > 0 ? cumulative_area_[t - 1] : 0.0);
    scaled[t] = area / total * static_cast<double>(n);
  }
  alias_probability_.assign(n, 1.0);
  alias_.resize(n);
  std::vector<int> small, large;
  for (std::size_t t = 0; t < n; ++t) {
    alias_[t] = static_cast<int>(t);
    (scaled[t] < 1.0 ? small : large).push_back(static_cast<int>(t));
  }
  while (!small.empty() && !large.empty()) {
    const int s = small.back(), l = large.back();
    small.pop_back();
    alias_probability_[static_cast<std::size_t>(s)] = scaled[static_cast<std::size_t>(s)];
    alias_[static_cast<std::size_t>(s)] = l;
    scaled[static_cast<std::size_t>(l)] -= 1.0 - scaled[static_cast<std::size_t>(s)];
    if (scaled[static_cast<std::size_t>(l)] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  // Leftovers (round-off) keep probability 1.
}

std::unique_ptr<DepthRenderer> SynthGenerator::MakeRenderer() const {
  return std::make_unique<DepthRenderer>(options_.camera);
}

PointSet SynthGenerator::SampleSurfacePoints(int count, Rng& rng) const {
  PointSet points(3, count);
  const int triangles = static_cast<int>(alias_.size());
  for (int i = 0; i < count; ++i) {
    const auto column = static_cast<std::size_t>(rng.UniformInt(triangles));
    const Eigen::Index t =
        rng.Uniform() < alias_probability_[column] ? static_cast<Eigen::Index>(column)
                                                   : alias_[column];
    // Uniform point in a triangle: sqrt(r1) warps the density to be area-uniform.
    const double s = std::sqrt(rng.Uniform());
    const double r = rng.Uniform();
    points.col(i) = (1.0 - s) * mesh_.vertices.col(mesh_.triangles(0, t)) +
                    s * (1.0 - r) * mesh_.vertices.col(mesh_.triangles(1, t)) +
                    s * r * mesh_.vertices.col(mesh_.triangles(2, t));
  }
  return points;
}

SynthSample SynthGenerator::GenerateSim(Rng& rng) const {
  SynthSample sample;
  sample.scene_from_model = SamplePose(options_.pose, options_.camera, distance_, centre_,
                                       diameter_, CloudKind::kSim, rng);
  const PointSet model_points = SampleSurfacePoints(options_.points, rng);
  PointSet cloud(3, options_.points);
  Eigen::Index kept = 0;
  for (Eigen::Index i = 0; i < model_points.cols(); ++i) {
    if (options_.dropout > 0.0 && rng.Uniform() < options_.dropout) continue;
    Eigen::Vector3d p = sample.scene_from_model * Eigen::Vector3d(model_points.col(i));
    if (options_.noise > 0.0) {
      const Eigen::Vector2d n1 = NormalPair(rng), n2 = NormalPair(rng);
      p += options_.noise * Eigen::Vector3d(n1.x(), n1.y(), n2.x());
    }
    cloud.col(kept++) = p;
  }
  if (kept == 0) {   // a cloud is never empty: keep the first point
    cloud.col(kept++) = sample.scene_from_model * Eigen::Vector3d(model_points.col(0));
  }
  cloud.conservativeResize(3, kept);
  sample.cloud = std::move(cloud);
  sample.keypoints = sample.scene_from_model * keypoints_;
  return sample;
}

SynthSample SynthGenerator::GenerateDepth(Rng& rng, DepthRenderer* renderer) const {
  if (!renderer) throw std::invalid_argument("SynthGenerator: depth clouds need a renderer");
  DepthSampleOptions depth;
  depth.points = options_.points;
  depth.noise_sigma = options_.noise;
  depth.dropout = options_.dropout;
  const int min_points = std::max(1, options_.ResolvedMinPoints());
  const double tolerance =
      options_.visibility_tolerance >= 0.0 ? options_.visibility_tolerance : 0.01 * diameter_;
  for (int attempt = 1; attempt <= options_.max_attempts; ++attempt) {
    const Pose pose = SamplePose(options_.pose, options_.camera, distance_, centre_, diameter_,
                                 CloudKind::kDepth, rng);
    renderer->Render(mesh_, pose, cull_back_faces_);
    if (static_cast<int>(renderer->covered_pixels().size()) < min_points) continue;
    PointSet cloud = renderer->SampleCloud(depth, rng);
    if (cloud.cols() < min_points) continue;
    SynthSample sample;
    sample.cloud = std::move(cloud);
    sample.scene_from_model = pose;
    sample.keypoints = pose * keypoints_;
    sample.visible = renderer->KeypointsVisible(sample.keypoints, tolerance);
    sample.attempts = attempt;
    return sample;
  }
  throw InputError(where_ + ": no view with at least " + std::to_string(min_points) +
                   " points in " + std::to_string(options_.max_attempts) +
                   " attempts (object too small or too far: lower --min-points or --distance)");
}

PointSet PerturbKeypoints(const PointSet& keypoints, double sigma, double fraction, double diameter, Rng& rng) {
  PointSet detected = keypoints;
  const double half_width = 0.5 * sigma * diameter;
  for (Eigen::Index i = 0; i < detected.cols(); ++i) {
    const bool perturbed = rng.Uniform() < fraction;
    const Eigen::Vector3d noise(rng.Uniform(-half_width, half_width),
                                rng.Uniform(-half_width, half_width),
                                rng.Uniform(-half_width, half_width));
    if (perturbed) detected.col(i) += noise;
  }
  return detected;
}

void SynthGenerator::Perturb(SynthSample* sample, Rng& rng) const {
  sample->detected_keypoints =
      PerturbKeypoints(sample->keypoints, options_.perturb_sigma, options_.perturb_fraction, diameter_, rng);
}

SynthSample SynthGenerator::Generate(std::size_t index, DepthRenderer* renderer) const {
  Rng rng = Rng::ForItem(options_.seed, index);
  SynthSample sample = options_.kind == CloudKind::kSim ? GenerateSim(rng)
                                                        : GenerateDepth(rng, renderer);
  if (options_.perturb) {
    Rng perturb_rng = Rng::ForItem(options_.seed ^ 0x9e3779b97f4a7c15ULL, index);
    Perturb(&sample, perturb_rng);
  }
  return sample;
}

}  // namespace c3po
