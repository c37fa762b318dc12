// c3po synth: simulated (sim) or rendered depth (depth) clouds with ground
// truth, written as a dataset folder (manifest.jsonl + binary PLY clouds), or
// with --format bop rendered scenes in the BOP layout (cli/synth_bop.cpp).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <tuple>

#include "c3po/base/error.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/synth/synth.hpp"
#include "command.hpp"
#include "progress_bar.hpp"
#include "synth_bop.hpp"

namespace c3po::cli {
namespace {

struct SynthCommand {
  std::string format = "manifest";
  std::string object;
  std::string output;
  std::string kind;
  int count = 0;
  int points = 1000;
  std::string pose = "hard";
  std::string noise = "0";
  double dropout = 0.0;
  int min_points = -1;
  std::string distance;
  std::string intrinsics;
  std::string perturb_sigma;
  std::string perturb_fraction;
  std::uint64_t seed = 0;
  SynthBopCommand bop;
  std::string shard;
};

void Declare(CLI::App& command, SynthCommand& o) {
  command.add_option("object", o.object, "Object JSON (annotations/*.json or from c3po annotate)")
      ->required();
  command.add_option("-o,--output", o.output, "Dataset folder to write (replaced when complete)")
      ->required();
  command.add_option("--format", o.format, "manifest (manifest.jsonl + PLY clouds) or bop (a BOP "
                                           "split folder: depth PNGs, masks, scene_gt.json, ...)")
      ->capture_default_str();
  command.add_option("--kind", o.kind, "sim: uniform samples of the whole surface; depth: what a "
                                       "pinhole depth camera sees (required for --format manifest)");
  command.add_option("--count", o.count, "Number of clouds (bop: images)")->required();
  command.add_option("--points", o.points, "Points per cloud (depth: fewer if fewer pixels)")
      ->capture_default_str();
  command.add_option("--pose", o.pose, "easy (<= 0.8 rad from a reference view), hard (any "
                                       "rotation), paper (any rotation, t in [0,1]^3)")
      ->capture_default_str();
  command.add_option("--noise", o.noise, "Gaussian noise sigma: distance, 1mm or 0.5%d (sim: per "
                                         "coordinate, depth: of the depth)")
      ->capture_default_str();
  command.add_option("--dropout", o.dropout, "Drop each point with this probability, in [0, 1)")
      ->capture_default_str();
  command.add_option("--min-points", o.min_points,
                     "depth: redraw views with fewer points (default points/2); bop: with fewer "
                     "visible target pixels (default 200)");
  command.add_option("--distance", o.distance,
                     "A,B: depth of the object centre in metres (default [0.5, 1.5] x the "
                     "distance where d spans 40 % of the image height)");
  command.add_option("--intrinsics", o.intrinsics,
                     "fx,fy,cx,cy,width,height (default 525,525,319.5,239.5,640,480; bop: YCB-V's "
                     "1066.778,1067.487,312.9869,241.3109,640,480)");
  command.add_option("--perturb-sigma", o.perturb_sigma,
                     "Write detected_keypoints: keypoints moved by U[-S d/2, S d/2] per coordinate");
  command.add_option("--perturb-fraction", o.perturb_fraction,
                     "Probability that a keypoint is perturbed (default 0.8)");
  command.add_option("--seed", o.seed, "Seed (same seed, same bytes)")->capture_default_str();
  DeclareBopOptions(command, o.bop);
  command.add_option("--shard", o.shard,
                     "manifest: write part K of N (K/N) of the clouds under their global names; "
                     "join with c3po merge");
}

// Options given on the command line that the chosen format does not use.
void CheckFormatOptions(const CLI::App& command, const SynthCommand& o) {
  if (o.format == "bop") {
    for (const char* name : {"--kind", "--points", "--noise", "--dropout", "--perturb-sigma",
                             "--perturb-fraction", "--shard"}) {
      if (command.count(name) > 0) {
        throw InputError(name, "not used by --format bop (see --artefacts and docs/synth_bop.md)");
      }
    }
  } else if (o.format == "manifest") {
    for (const std::string& name : BopOnlyOptions()) {
      if (command.count(name) > 0) throw InputError(name, "only used with --format bop");
    }
    if (o.kind.empty()) throw InputError("--kind", "required (sim or depth) for --format manifest");
  } else {
    throw InputError("--format", "'" + o.format + "': expected manifest or bop");
  }
}

// A non-negative distance: "0", "0.001", "1mm", "0.5%d".
double ParseNoise(const std::string& text, double diameter) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() && *end == '\0' && value == 0.0) return 0.0;
  return ParseThreshold(text, diameter, "--noise");
}

double ParseNumber(const std::string& text, const std::string& what) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') throw InputError(what, "'" + text + "' is not a number");
  return value;
}

std::pair<double, double> ParseDistance(const std::string& text) {
  const auto comma = text.find(',');
  if (comma == std::string::npos) throw InputError("--distance", "expected A,B in metres");
  return {ParseNumber(text.substr(0, comma), "--distance"),
          ParseNumber(text.substr(comma + 1), "--distance")};
}

SynthOptions MakeOptions(const SynthCommand& o, double diameter) {
  SynthOptions options;
  options.kind = ParseCloudKind(o.kind);
  options.count = o.count;
  options.points = o.points;
  options.pose.mode = ParsePoseMode(o.pose);
  options.noise = ParseNoise(o.noise, diameter);
  options.dropout = o.dropout;
  options.min_points = o.min_points;
  if (o.min_points < -1) throw InputError("--min-points", "must be >= 0");
  if (!o.distance.empty()) {
    std::tie(options.pose.distance_min, options.pose.distance_max) = ParseDistance(o.distance);
    if (!(options.pose.distance_min > 0.0)) throw InputError("--distance", "A must be > 0");
  }
  if (!o.intrinsics.empty()) options.camera = ParseIntrinsics(o.intrinsics);
  options.perturb = !o.perturb_sigma.empty() || !o.perturb_fraction.empty();
  if (!o.perturb_sigma.empty()) options.perturb_sigma = ParseNumber(o.perturb_sigma, "--perturb-sigma");
  if (!o.perturb_fraction.empty()) {
    options.perturb_fraction = ParseNumber(o.perturb_fraction, "--perturb-fraction");
  }
  options.seed = o.seed;
  if (!o.shard.empty()) options.shard = ParseShard(o.shard);
  options.Check();
  return options;
}

int Run(const CLI::App& command, const SynthCommand& o) {
  CheckFormatOptions(command, o);
  if (o.format == "bop") {
    SynthCommonForBop common;
    common.object = o.object;
    common.output = o.output;
    common.count = o.count;
    common.pose = o.pose;
    common.min_points = o.min_points;
    common.distance = o.distance;
    common.intrinsics = o.intrinsics;
    common.seed = o.seed;
    if (o.min_points < -1) throw InputError("--min-points", "must be >= 0");
    return RunSynthBop(common, o.bop);
  }
  const ObjectModel object = LoadObject(o.object);
  const SynthOptions options = MakeOptions(o, object.diameter());
  ProgressBar progress(std::string("synth ") + ToString(options.kind),
                       static_cast<std::size_t>(options.count));
  const SynthReport report =
      WriteSynthDataset(object.mesh(), object.spec(), options, o.output,
                        [&](std::size_t done, std::size_t) { progress.Update(done); }, o.object);
  progress.Finish();
  std::printf("wrote %s: %zu %s clouds of %s (d = %.4g m), %.1f points on average (%d to %d), "
              "pose %s, seed %llu\n",
              o.output.c_str(), report.count, ToString(options.kind), object.name().c_str(),
              report.diameter, report.mean_points, report.min_cloud_points, report.max_cloud_points,
              ToString(options.pose.mode), static_cast<unsigned long long>(options.seed));
  if (options.pose.mode == PoseMode::kPaper) {
    if (options.kind == CloudKind::kSim) {
      std::printf("object centre in [0, 1]^3 m\n");
    } else {
      std::printf("object centre in [-0.5, 0.5]^2 x [%.4g, %.4g] m", report.distance_range.second,
                  report.distance_range.second + 1.0);
    }
  } else {
    std::printf("object centre depth in [%.4g, %.4g] m", report.distance_range.first,
                report.distance_range.second);
  }
  if (options.pose.mode != PoseMode::kPaper || options.kind == CloudKind::kDepth) {
    if (options.kind == CloudKind::kDepth) {
      std::printf("; %.2f views drawn per cloud; %.1f %% of keypoints visible on average",
                  report.mean_attempts, 100.0 * report.visible_keypoint_fraction);
    }
    std::printf("\n");
  }
  if (options.noise > 0.0) std::printf("noise sigma = %.4g m\n", options.noise);
  if (options.perturb) {
    std::printf("detected_keypoints: %.0f %% of keypoints moved by U[-%.4g, %.4g] m per coordinate\n",
                100.0 * options.perturb_fraction, 0.5 * options.perturb_sigma * report.diameter,
                0.5 * options.perturb_sigma * report.diameter);
  }
  std::printf("%.2f s (%.1f clouds/s)\n", report.seconds,
              report.seconds > 0 ? static_cast<double>(report.count) / report.seconds : 0.0);
  return 0;
}

}  // namespace

RunFunction SetupSynth(CLI::App& command) {
  auto options = std::make_shared<SynthCommand>();
  Declare(command, *options);
  return [options, app = &command]() { return Run(*app, *options); };
}

}  // namespace c3po::cli
