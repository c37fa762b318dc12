// c3po synth --format bop: rendered scenes in the BOP layout with optional
// sensor artefacts (docs/synth_bop.md). Parses, calls the library, reports.
#include "synth_bop.hpp"

#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "c3po/base/error.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/synth/synth_bop.hpp"
#include "progress_bar.hpp"

namespace c3po::cli {
namespace {

double Number(const std::string& text, const std::string& what) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value)) {
    throw InputError(what, "'" + text + "' is not a number");
  }
  return value;
}

int WholeNumber(const std::string& text, const std::string& what) {
  const double value = Number(text, what);
  if (value != std::floor(value) || std::abs(value) > 1e6) {
    throw InputError(what, "'" + text + "' is not a whole number");
  }
  return static_cast<int>(value);
}

std::pair<double, double> Pair(const std::string& text, const std::string& what) {
  const auto comma = text.find(',');
  if (comma == std::string::npos) throw InputError(what, "expected A,B");
  return {Number(text.substr(0, comma), what), Number(text.substr(comma + 1), what)};
}

DepthArtefactOptions MakeArtefacts(const SynthBopCommand& o) {
  DepthArtefactOptions artefacts;
  if (o.artefacts == "realistic") {
    artefacts = RealisticArtefacts();
  } else if (o.artefacts != "none") {
    throw InputError("--artefacts", "'" + o.artefacts + "': expected none or realistic");
  }
  if (!o.depth_noise.empty()) {
    std::tie(artefacts.noise_a, artefacts.noise_b) = Pair(o.depth_noise, "--depth-noise");
  }
  if (!o.quantisation.empty()) artefacts.quantisation = Number(o.quantisation, "--quantisation");
  if (!o.holes.empty()) artefacts.dropout = Number(o.holes, "--holes");
  if (!o.hole_blobs.empty()) artefacts.hole_blobs = WholeNumber(o.hole_blobs, "--hole-blobs");
  if (!o.flying.empty()) artefacts.flying_fraction = Number(o.flying, "--flying-pixels");
  if (!o.bleed.empty()) artefacts.bleed = WholeNumber(o.bleed, "--bleed");
  artefacts.Check();
  return artefacts;
}

// "FILE.json" or "FILE.json:ID".
std::pair<std::string, int> DistractorSpec(const std::string& text, int default_id) {
  const auto colon = text.rfind(':');
  if (colon != std::string::npos && colon + 1 < text.size() &&
      text.find_first_not_of("0123456789", colon + 1) == std::string::npos) {
    return {text.substr(0, colon), WholeNumber(text.substr(colon + 1), "--distractor")};
  }
  return {text, default_id};
}

}  // namespace

const std::vector<std::string>& BopOnlyOptions() {
  static const std::vector<std::string> options{
      "--obj-id", "--depth-scale", "--images-per-scene", "--distractors", "--distractor",
      "--no-background", "--background-gap", "--min-visib-fract", "--artefacts", "--depth-noise",
      "--quantisation", "--holes", "--hole-blobs", "--flying-pixels", "--bleed"};
  return options;
}

void DeclareBopOptions(CLI::App& command, SynthBopCommand& o) {
  const std::string bop = "bop: ";
  command.add_option("--obj-id", o.obj_id, bop + "BOP object id of the target")->capture_default_str();
  command.add_option("--depth-scale", o.depth_scale,
                     bop + "millimetres per depth-image unit, or auto: the finest of 0.1 (YCB-V's), 0.2, 0.5, 1, "
                           "2, ... that holds the deepest surface in 16 bits")
      ->capture_default_str();
  command.add_option("--images-per-scene", o.images_per_scene, bop + "images per scene folder")
      ->capture_default_str();
  command.add_option("--distractors", o.distractors, bop + "further instances per image")
      ->capture_default_str();
  command.add_option("--distractor", o.distractor_objects,
                     bop + "object JSON[:OBJ_ID] drawn as a distractor (repeatable; default: the "
                           "target itself; ids default to obj-id + 1, + 2, ...)");
  command.add_flag("--no-background", o.no_background, bop + "no table plane behind the objects");
  command.add_option("--background-gap", o.background_gap,
                     bop + "least distance of the table behind the objects, x diameter")
      ->capture_default_str();
  command.add_option("--min-visib-fract", o.min_visib_fract,
                     bop + "redraw images where less of the target is visible")
      ->capture_default_str();
  command.add_option("--artefacts", o.artefacts, bop + "none or realistic (a Kinect-like preset; "
                                                       "the options below override it)")
      ->capture_default_str();
  command.add_option("--depth-noise", o.depth_noise, bop + "A,B: sigma(z) = A + B z^2 (metres)");
  command.add_option("--quantisation", o.quantisation,
                     bop + "disparity step Q (1/m): depth step Q z^2");
  command.add_option("--holes", o.holes, bop + "fraction of valid depth pixels dropped");
  command.add_option("--hole-blobs", o.hole_blobs, bop + "hole discs per image (on the objects)");
  command.add_option("--flying-pixels", o.flying,
                     bop + "probability that a depth-discontinuity pixel flies");
  command.add_option("--bleed", o.bleed, bop + "dilate mask_visib by K pixels");
}

namespace {

BopSynthOptions MakeBopSynthOptions(const SynthCommonForBop& common, const SynthBopCommand& o) {
  BopSynthOptions options;
  options.count = common.count;
  options.images_per_scene = o.images_per_scene;
  options.pose.mode = ParsePoseMode(common.pose);
  if (!common.distance.empty()) {
    std::tie(options.pose.distance_min, options.pose.distance_max) = Pair(common.distance, "--distance");
    if (!(options.pose.distance_min > 0.0)) throw InputError("--distance", "A must be > 0");
  }
  if (!common.intrinsics.empty()) options.camera = ParseIntrinsics(common.intrinsics);
  options.units_to_mm = 1000.0;   // LoadObject converts every mesh to metres (annotations/README.md)
  if (o.depth_scale != "auto") {
    options.depth_scale = Number(o.depth_scale, "--depth-scale");
    if (!(options.depth_scale > 0.0)) throw InputError("--depth-scale", "must be auto or > 0 mm per unit");
  }
  options.distractors = o.distractors;
  options.background = !o.no_background;
  options.background_gap = o.background_gap;
  options.min_visib_fract = o.min_visib_fract;
  if (common.min_points >= 0) options.min_visible_pixels = common.min_points;
  options.artefacts = MakeArtefacts(o);
  options.seed = common.seed;
  options.Check();
  return options;
}

// The --distractor objects' meshes (metres, like the target's), ids and files.
struct DistractorObjects {
  std::vector<Mesh> meshes;
  std::vector<int> ids;
  std::vector<std::string> files;

  std::vector<SynthBopObject> Objects() const {
    std::vector<SynthBopObject> objects;
    for (std::size_t k = 0; k < meshes.size(); ++k) objects.push_back({&meshes[k], ids[k]});
    return objects;
  }
};

DistractorObjects LoadDistractors(const SynthBopCommand& o) {
  DistractorObjects distractors;
  for (std::size_t k = 0; k < o.distractor_objects.size(); ++k) {
    const auto [file, id] = DistractorSpec(o.distractor_objects[k], o.obj_id + static_cast<int>(k) + 1);
    distractors.meshes.push_back(LoadObject(file).mesh());
    distractors.ids.push_back(id);
    distractors.files.push_back(file);
  }
  return distractors;
}

void PrintBopSynthReport(const BopSynthReport& report, const BopSceneGenerator& generator, const ObjectModel& object,
                         const std::string& output, int obj_id) {
  const BopSynthOptions& options = generator.options();
  std::printf("wrote %s: %zu images in %d scene(s) of %s (obj_id %d, d = %.4g m), %zu instances, "
              "pose %s, seed %llu\n",
              output.c_str(), report.images, report.scenes, object.name().c_str(), obj_id,
              report.diameter, report.instances,
              ToString(options.pose.mode), static_cast<unsigned long long>(options.seed));
  std::printf("camera fx %.6g fy %.6g cx %.6g cy %.6g, %dx%d, depth_scale %.6g mm; object centre "
              "depth in [%.4g, %.4g] m\n",
              options.camera.fx, options.camera.fy, options.camera.cx, options.camera.cy,
              options.camera.width, options.camera.height, options.depth_scale,
              report.distance_range.first, report.distance_range.second);
  std::printf("target: mean visib_fract %.3f, at least %ld visible pixels; %.2f draws per image\n",
              report.mean_target_visib_fract, report.target_visible_pixels_min, report.mean_attempts);
  const DepthArtefactOptions& a = options.artefacts;
  if (a.AnyDepth() || a.bleed > 0) {
    std::printf("artefacts: flying pixels %ld, dropped %ld, mask pixels bled %ld (sigma(z) = %.4g + "
                "%.4g z^2 m, quantisation %.4g /m, holes %.3g + %d blobs, flying %.3g, bleed %d "
                "px)\n",
                report.flying, report.dropped, report.bled, a.noise_a, a.noise_b, a.quantisation,
                a.dropout, a.hole_blobs, a.flying_fraction, a.bleed);
  }
  if (report.out_of_range > 0) {
    std::printf("%ld pixels beyond 65535 x %.4g mm written as 0 (no measurement)\n",
                report.out_of_range, options.depth_scale);
  }
  std::printf("%.2f s (%.1f images/s)\n", report.seconds,
              report.seconds > 0 ? static_cast<double>(report.images) / report.seconds : 0.0);
}

}  // namespace

int RunSynthBop(const SynthCommonForBop& common, const SynthBopCommand& o) {
  const ObjectModel object = LoadObject(common.object);
  const BopSynthOptions options = MakeBopSynthOptions(common, o);
  const DistractorObjects distractors = LoadDistractors(o);
  if (!distractors.meshes.empty() && options.distractors == 0) {
    throw InputError("--distractor", "given, but --distractors is 0 (how many per image?)");
  }
  const BopSceneGenerator generator({&object.mesh(), o.obj_id}, distractors.Objects(), options, common.object);

  nlohmann::json provenance{{"object", common.object}, {"object_name", object.name()},
                            {"units", object.spec().units}, {"obj_id", o.obj_id},
                            {"distractor_objects", distractors.files},
                            {"distractor_obj_ids", distractors.ids}};
  ProgressBar progress("synth bop", static_cast<std::size_t>(options.count));
  const BopSynthReport report = WriteBopDataset(
      generator, common.output, provenance.dump(),
      [&](std::size_t done, std::size_t) { progress.Update(done); });
  progress.Finish();
  PrintBopSynthReport(report, generator, object, common.output, o.obj_id);
  return 0;
}

}  // namespace c3po::cli
