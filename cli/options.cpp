// Shared command-line options (options.hpp).
#include "options.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <stdexcept>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/io/camera_io.hpp"
#include "c3po/method/global_uniqueness.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/plugins/registry.hpp"

namespace c3po::cli {

CLI::Validator WritableFile(bool dash_is_stdout) {
  return CLI::Validator(
      [dash_is_stdout](std::string& path) -> std::string {
        if (dash_is_stdout && path == "-") return "";
        try {
          CheckWritableFile(path);
        } catch (const InputError& error) {
          return error.what();
        }
        return "";
      },
      "FILE");
}

void AddThresholdOptions(CLI::App& command, ThresholdFlags* flags, AutoEpsOc auto_eps_oc) {
  flags->auto_mode = auto_eps_oc;
  command.add_option("--eps-oc", flags->eps_oc,
                     auto_eps_oc == AutoEpsOc::kAllowed
                         ? "Observable-correctness threshold: distance, fraction of d (3%d) or auto (estimated from "
                           "the clouds; default: the object's)"
                         : "Observable-correctness threshold: distance or fraction of d (3%d) (default: the object's)");
  command.add_option("--delta-nd", flags->delta_nd,
                     "Non-degeneracy threshold: distance or fraction of d (default: the object's)");
}

CertificateOptions ResolveThresholds(const ThresholdFlags& flags, const ObjectModel& object) {
  CertificateOptions options = CertificateOptions::FromObject(object.spec());
  if (flags.auto_eps_oc() && flags.auto_mode == AutoEpsOc::kRefused) {
    throw InputError("--eps-oc", "'auto' is not available here (give a distance, e.g. 0.01 or 3%d)");
  }
  if (!flags.eps_oc.empty() && !flags.auto_eps_oc()) {
    options.eps_oc = ParseThreshold(flags.eps_oc, object.diameter(), "--eps-oc");
  }
  if (!flags.delta_nd.empty()) options.delta_nd = ParseThreshold(flags.delta_nd, object.diameter(), "--delta-nd");
  return options;
}

void AddCorrectorOptions(CLI::App& command, CorrectorFlags* flags) {
  command.add_option("--solver", flags->solver, "Corrector solver: fast (default) or gd (the reference's)");
  AddLossOption(command, &flags->loss);
}

void AddLossOption(CLI::App& command, std::string* loss) {
  command.add_option("--loss", *loss, "Point-cloud loss: mean (paper, default) or max (reference code)");
}

void ResolveCorrector(const CorrectorFlags& flags, CorrectorOptions* options) {
  options->solver = ParseCorrectorSolver(flags.solver);
  options->loss = ParsePointCloudLoss(flags.loss);
}

void AddRobustOptions(CLI::App& command, RobustFlags* flags) {
  command.add_option("--max-outliers", flags->max_outliers,
                     "Outlier budget m of the certificates: a count (10) or a percentage of each cloud's points "
                     "(2%); default 0 = the paper; depth-image/BOP input: 2% (with the free-space test, unless "
                     "--indicator-sets on for an object with sets)");
  command.add_option("--indicator-sets", flags->indicator_sets,
                     "on: nd needs one of the object's indicator sets supported (the paper's eq. 21); off: the sets "
                     "are ignored, as for an object without any. Default on, off for depth-image/BOP input with the "
                     "free-space test (the mask erosion removes their corners' support; docs/method.md)")
      ->check(CLI::IsMember({"on", "off"}));
  command.add_option("--robust-loss", flags->robust_loss,
                     "Robust kernel of the corrector's point-cloud term, truncated at eps_oc: none, tls (truncated "
                     "least squares, GNC) or gm (Geman-McClure); default none, tls for depth-image/BOP input");
  command.add_option("--nd-min-eigenvalue", flags->nd_min_eigenvalue,
                     "Local non-degeneracy threshold on the smallest generalised eigenvalue (data vs model "
                     "point-to-plane information); 0 = local test off");
  command.add_flag("--no-global-check", flags->no_global_check,
                   "nd without the global rival search (restarts of the corrector at turned poses; on by default)");
  command.add_flag("--reestimate", flags->reestimate,
                   "When the estimate fails oc or free space, restart the corrector at turns about 13 axes and "
                   "certify the best fit that passes instead, unless another restart fits too (default: on for "
                   "certify's and eval's depth-image/BOP input, off for clouds and selftrain)");
  command.add_flag("--no-reestimate", flags->no_reestimate, "No re-estimation, whatever the input")
      ->excludes("--reestimate");
  command.add_option("--reestimate-steps", flags->reestimate_steps,
                     "--reestimate starts: rotations by k*360/N deg about each of 13 axes (N even, default 12)");
  command.add_flag("--no-weak-motion-check", flags->no_weak_motion_check,
                   "A single motion the local test finds weak fails nd (by default the pose is displaced along it "
                   "and refitted: no second fit = constrained)");
  command.add_flag("--no-centre", flags->no_centre,
                   "A pose refused only by rivals within twice the rival distance stays refused (by default the "
                   "centre of it and its rivals is certified instead when it passes everything and lies within the "
                   "rival distance of all of them)");
  command.add_option("--tolerance", flags->tolerance,
                     "The accuracy you need: a certified pose lies within it of the truth (Hausdorff, + sensor "
                     "noise), as far as the rival search reaches; a second fit farther than the tolerance - eps_oc "
                     "refuses the pose. A distance (2cm, 0.02) or a fraction of d (10%d); default 10%d, at least "
                     "3*eps_oc (JSON certified_bound; docs/method.md \"Tolerance\")");
  command.add_option("--rival-distance", flags->rival_distance,
                     "Expert, instead of --tolerance: a second fit counts as a rival beyond this Hausdorff distance "
                     "of the estimate (default tolerance - eps_oc); the certified bound is this + eps_oc");
  command.add_option("--global-steps", flags->global_steps,
                     "Rival starts: rotations by k*360/N deg about each principal axis (N even, default 4), "
                     "half-turns about the 10 diagonals of the principal frame, and the estimate itself");
  command.add_flag("--no-free-space", flags->no_free_space,
                   "Depth-image inputs: no free-space test (on by default)");
  command.add_option("--free-space-fraction", flags->free_space_fraction,
                     "Depth-image inputs: a rival pose (or re-estimation candidate) that sees through more than this "
                     "fraction of its measured silhouette pixels is refuted (default 0.02)");
  command.add_option("--free-space-accept", flags->free_space_accept,
                     "Depth-image inputs: the estimate is certified only if it sees through at most this fraction "
                     "(default 0.015, at most --free-space-fraction)");
  command.add_option("--outside-mask-fraction", flags->outside_mask,
                     "Depth-image inputs: the estimate is certified only if at most this fraction of its measured "
                     "silhouette pixels show its surface outside the segment's mask (default 0.05; 1 = off)");
  command.add_option("--uncovered-mask-fraction", flags->uncovered_mask,
                     "Depth-image inputs: the estimate is certified only if at most this fraction of the mask's "
                     "pixels at its depth lie outside its silhouette (default 0.035; 1 = off)");
}

namespace {

// A fraction in [0, 1) (or [0, 1] when `one_allowed`) given to `option`, or
// exit status 2 naming it.
double ParseFraction(const std::string& text, const char* option, bool one_allowed = false) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !(value >= 0) || !(one_allowed ? value <= 1 : value < 1)) {
    throw InputError(option, "'" + text + "' must be a number in [0, 1" + (one_allowed ? "]" : ")"));
  }
  return value;
}

// --free-space-fraction F alone lowers the acceptance limit to F when F is
// smaller; an acceptance limit above the refutation limit is refused.
void ResolveFreeSpaceLimits(const RobustFlags& flags, FreeSpaceOptions* options) {
  if (!flags.free_space_fraction.empty()) {
    options->max_fraction = ParseFraction(flags.free_space_fraction, "--free-space-fraction");
    options->accept_fraction = std::min(options->accept_fraction, options->max_fraction);
  }
  if (!flags.free_space_accept.empty()) {
    options->accept_fraction = ParseFraction(flags.free_space_accept, "--free-space-accept");
    if (options->accept_fraction > options->max_fraction) {
      char limit[32];
      std::snprintf(limit, sizeof limit, "%g", options->max_fraction);
      throw InputError("--free-space-accept",
                       "'" + flags.free_space_accept + "' must not exceed the free-space fraction (" + limit + ")");
    }
  }
  if (!flags.outside_mask.empty()) {
    options->outside_mask_fraction = ParseFraction(flags.outside_mask, "--outside-mask-fraction", true);
  }
  if (!flags.uncovered_mask.empty()) {
    options->uncovered_mask_fraction = ParseFraction(flags.uncovered_mask, "--uncovered-mask-fraction", true);
  }
}

}  // namespace

void ResolveRobust(const RobustFlags& flags, InputKind input, const ObjectModel& object,
                   CertificateOptions* certificate, CorrectorOptions* corrector) {
  const bool robust_frames = input == InputKind::kCameraFrames && !flags.no_free_space;
  certificate->use_indicator_sets = flags.indicator_sets.empty() ? !robust_frames : flags.indicator_sets == "on";
  const bool sets_in_use = certificate->use_indicator_sets && !object.spec().indicator_sets.empty();
  if (!flags.max_outliers.empty()) {
    certificate->max_outliers = ParseOutlierBudget(flags.max_outliers);
  } else {
    certificate->max_outliers = OutlierBudget{};
    if (robust_frames && !sets_in_use) certificate->max_outliers.fraction = kDepthImageOutlierFraction;
  }
  if (!flags.robust_loss.empty()) {
    corrector->robust_loss = ParseRobustLoss(flags.robust_loss);
  } else {
    corrector->robust_loss = input == InputKind::kClouds ? RobustLoss::kNone : kDepthImageRobustLoss;
  }
  if (!flags.nd_min_eigenvalue.empty()) {
    char* end = nullptr;
    const double value = std::strtod(flags.nd_min_eigenvalue.c_str(), &end);
    if (*end != '\0' || !(value >= 0) || !(value < 1e6)) {
      throw InputError("--nd-min-eigenvalue", "'" + flags.nd_min_eigenvalue + "' must be a number >= 0");
    }
    certificate->local_nondegeneracy = value > 0;
    if (value > 0) certificate->local.min_eigenvalue = value;
  }
  certificate->global.enabled = !flags.no_global_check;
  certificate->local.weak_motion_check = !flags.no_weak_motion_check;
  certificate->global.centre = !flags.no_centre;
  const bool reestimate_by_default = input == InputKind::kCameraFrames && flags.reestimate_camera_frames;
  certificate->global.reestimate = !flags.no_reestimate && (flags.reestimate || reestimate_by_default);
  certificate->global.steps = flags.global_steps;
  if (!flags.tolerance.empty() && !flags.rival_distance.empty()) {
    throw InputError("--tolerance", "give --tolerance or --rival-distance, not both (the rival distance is the tolerance - eps_oc)");
  }
  certificate->global.rival_distance =
      flags.rival_distance.empty() ? 0.0 : ParseThreshold(flags.rival_distance, object.diameter(), "--rival-distance");
  certificate->global.tolerance =
      flags.tolerance.empty() ? 0.0 : ParseThreshold(flags.tolerance, object.diameter(), "--tolerance");
  if (certificate->global.tolerance > 0.0 && certificate->eps_oc > 0.0 &&
      !(certificate->global.tolerance > certificate->eps_oc)) {
    char text[160];
    std::snprintf(text, sizeof text, "'%s' = %g must exceed eps_oc = %g: no certificate is more precise than its own fit",
                  flags.tolerance.c_str(), certificate->global.tolerance, certificate->eps_oc);
    throw InputError("--tolerance", text);
  }
  certificate->global.reestimate_steps = flags.reestimate_steps;
  if (flags.reestimate_steps < 2 || flags.reestimate_steps > 36 || flags.reestimate_steps % 2 != 0) {
    throw InputError("--reestimate-steps", std::to_string(flags.reestimate_steps) + " must be even and in [2, 36]");
  }
  if (flags.global_steps < 2 || flags.global_steps > 36 || flags.global_steps % 2 != 0) {
    throw InputError("--global-steps", std::to_string(flags.global_steps) + " must be even and in [2, 36]");
  }
  certificate->free_space.enabled = !flags.no_free_space;
  ResolveFreeSpaceLimits(flags, &certificate->free_space);
}

std::string DescribeRobust(const CertificateOptions& certificate, const CorrectorOptions& corrector) {
  char text[200];
  if (certificate.local_nondegeneracy) {
    std::snprintf(text, sizeof text, "m = %s, robust loss = %s, local nd >= %g",
                  certificate.max_outliers.ToString().c_str(), ToString(corrector.robust_loss),
                  certificate.local.min_eigenvalue);
  } else {
    std::snprintf(text, sizeof text, "m = %s, robust loss = %s, local nd off",
                  certificate.max_outliers.ToString().c_str(), ToString(corrector.robust_loss));
  }
  std::string described = text;
  if (!certificate.use_indicator_sets) described += ", indicator sets off";
  if (certificate.global.enabled) {
    described += ", global rivals " + std::to_string(RivalHypotheses(certificate.global).size());
    if (certificate.global.rival_distance > 0.0) {
      char beyond[48];
      std::snprintf(beyond, sizeof beyond, " beyond %g m", certificate.global.rival_distance);
      described += beyond;
    } else if (certificate.global.tolerance > 0.0) {
      char within[48];
      std::snprintf(within, sizeof within, ", tolerance %g m", certificate.global.tolerance);
      described += within;
    }
  } else {
    described += ", global check off";
  }
  // Re-estimation runs with or without the rival search (pipeline.cpp).
  if (certificate.global.reestimate) described += ", re-estimation on";
  if (!certificate.global.centre) described += ", centring off";
  return described;
}

std::string RobustCommandLine(const RobustFlags& flags) {
  std::string line;
  if (!flags.max_outliers.empty()) line += " --max-outliers " + flags.max_outliers;
  if (!flags.robust_loss.empty()) line += " --robust-loss " + flags.robust_loss;
  if (!flags.indicator_sets.empty()) line += " --indicator-sets " + flags.indicator_sets;
  if (!flags.nd_min_eigenvalue.empty()) line += " --nd-min-eigenvalue " + flags.nd_min_eigenvalue;
  if (flags.no_global_check) line += " --no-global-check";
  if (flags.no_weak_motion_check) line += " --no-weak-motion-check";
  if (flags.no_centre) line += " --no-centre";
  if (flags.reestimate) line += " --reestimate";
  if (flags.no_reestimate) line += " --no-reestimate";
  if (flags.global_steps != 4) line += " --global-steps " + std::to_string(flags.global_steps);
  if (!flags.rival_distance.empty()) line += " --rival-distance " + flags.rival_distance;
  if (!flags.tolerance.empty()) line += " --tolerance " + flags.tolerance;
  if (flags.reestimate_steps != 12) line += " --reestimate-steps " + std::to_string(flags.reestimate_steps);
  if (flags.no_free_space) line += " --no-free-space";
  if (!flags.free_space_fraction.empty()) line += " --free-space-fraction " + flags.free_space_fraction;
  if (!flags.free_space_accept.empty()) line += " --free-space-accept " + flags.free_space_accept;
  if (!flags.outside_mask.empty()) line += " --outside-mask-fraction " + flags.outside_mask;
  if (!flags.uncovered_mask.empty()) line += " --uncovered-mask-fraction " + flags.uncovered_mask;
  return line;
}

void AddDetectorOptions(CLI::App& command, DetectorFlags* flags, DetectorCount count) {
  const bool many = count == DetectorCount::kMany;
  CLI::Option* model = command.add_option(
      "--model", flags->models,
      many ? "Trained detector model file (row label = file stem); repeatable" : "Trained detector model file");
  CLI::Option* detector = command.add_option(
      "--detector", flags->detectors,
      std::string("Detector without a model file (svd, fpfh, manifest = the manifest's detected_keypoints, or a "
                  "plugin's)") + (many ? "; repeatable" : ""));
  CLI::Option* plugin =
      command.add_option("--plugin", flags->plugins, "Load a detector plugin (shared library); repeatable");
  // Each occurrence takes one value, so a positional after it stays positional.
  for (CLI::Option* option : {model, detector, plugin}) option->allow_extra_args(false);
}

void LoadPlugins(const DetectorFlags& flags) {
  for (const std::string& plugin : flags.plugins) LoadPlugin(plugin);
}

std::unique_ptr<Detector> MakeDetector(const std::string& model, const std::string& detector,
                                       const ObjectModel& object) {
  if (!model.empty()) return LoadDetectorModel(model, object);
  if (detector == kManifestDetector) return nullptr;
  return CreateDetector(detector, object);
}

void AddSymmetryOptions(CLI::App& command, SymmetryFlags* flags, const std::string& off_flag,
                        const std::string& off_help) {
  command.add_flag("!" + off_flag, flags->enabled, off_help);
  command.add_option("--symmetry-tolerance", flags->tolerance,
                     "A rotation moving the model surface by at most this Hausdorff distance is a symmetry "
                     "(a distance, or e.g. 0.5%d of the diameter; default eps_oc/4)");
}

std::vector<ModelSymmetry> ObjectSymmetries(const SymmetryFlags& flags, const ObjectModel& object,
                                            const std::string& use) {
  if (!flags.enabled) return {};
  SymmetrySearchOptions options;
  options.tolerance = flags.tolerance.empty()
                          ? 0.25 * object.spec().eps_oc
                          : ParseThreshold(flags.tolerance, object.diameter(), "--symmetry-tolerance");
  const std::vector<ModelSymmetry> symmetries = FindModelSymmetries(object, options);
  std::fprintf(stderr, "%s: %zu symmetr%s within %.3g (surface Hausdorff)%s%s\n", object.name().c_str(),
               symmetries.size(), symmetries.size() == 1 ? "y" : "ies", options.tolerance,
               symmetries.empty() ? "" : ": ", symmetries.empty() ? "" : use.c_str());
  for (const ModelSymmetry& s : symmetries) {
    std::fprintf(stderr, "  %6.1f deg about (%+.3f, %+.3f, %+.3f), Hausdorff %.3g\n", s.angle * 180.0 / M_PI,
                 s.axis.x(), s.axis.y(), s.axis.z(), s.hausdorff);
  }
  return symmetries;
}

void AddSeedOption(CLI::App& command, std::uint64_t* seed, const std::string& what) {
  command.add_option("--seed", *seed, "Seed (" + what + ")");
}

void AddThreadsOption(CLI::App& command, int* threads, const std::string& what) {
  command.add_option("--threads", *threads, "Worker threads (" + what + ")");
}


void SetMaskErosion(const std::string& text, SegmentOptions* options) {
  const auto refuse = [&text]() -> CLI::ValidationError {
    return CLI::ValidationError("--erode-mask", "'" + text + "' must be a width (3mm, 0.5cm, 0.003m) or pixels (4, 4px) in [0, 1000]");
  };
  const bool pixels = text.size() > 2 && text.compare(text.size() - 2, 2, "px") == 0;
  const std::string number = pixels ? text.substr(0, text.size() - 2) : text;
  char* end = nullptr;
  const long count = std::strtol(number.c_str(), &end, 10);
  if (!number.empty() && *end == '\0') {
    if (count < 0 || count > 1000) throw refuse();
    options->erode_mask = static_cast<int>(count);
    options->erode_mask_metres = 0.0;
    return;
  }
  if (pixels || (text.back() != 'm')) throw refuse();   // a width needs its unit (mm, cm, m)
  double width = 0.0;
  try {
    width = ParseThreshold(text, 0.0, "--erode-mask");
  } catch (const InputError&) {
    throw refuse();
  }
  if (width > 1.0) throw refuse();
  options->erode_mask = 0;
  options->erode_mask_metres = width;
}

void AddSegmentOptions(CLI::App& command, SegmentOptions* options) {
  command
      .add_option_function<std::string>(
          "--erode-mask", [options](const std::string& text) { SetMaskErosion(text, options); },
          "Erode masks for the estimate (the detector and the corrector) by a width at the segment's depth (3mm, "
          "0.5cm: the same band on every camera) or by K pixels (4, 4px); 0 = off. Lowered where it would leave "
          "less than half of the segment (default 4)")
      ->type_name("W");
  command.add_option("--depth-edge", options->max_relative_depth_step,
                     "Drop pixels whose depth differs from a neighbour's by more than this fraction of their "
                     "depth (0 = off)")
      ->capture_default_str();
  command.add_option("--support-plane", options->support_plane_distance,
                     "Drop mask points within this distance (m) of the background's dominant plane (the table "
                     "masks bleed onto; 0 = off)")
      ->capture_default_str();
  command.add_option("--max-points", options->max_points,
                     "At most this many points per image segment, evenly strided (0 = all)")
      ->capture_default_str();
}

void CheckSegmentOptions(const SegmentOptions& options, const std::string& command) {
  try {
    options.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(command, e.what());
  }
}

void AddEvidenceOption(CLI::App& command, std::string* flag) {
  command.add_option("--evidence-erode-mask", *flag,
                     "Erode masks by K pixels for the certificate's evidence; auto (default): 0 = every mask point "
                     "when the budget --max-outliers is > 0 (it counts the mask's stray pixels), else the estimate's "
                     "--erode-mask");
}

void ResolveEvidence(const std::string& flag, const CertificateOptions& certificate, SegmentOptions* segment) {
  if (flag.empty() || flag == "auto") {
    segment->evidence_erode_mask = certificate.max_outliers.IsZero() ? -1 : 0;
    return;
  }
  char* end = nullptr;
  const long value = std::strtol(flag.c_str(), &end, 10);
  if (end == flag.c_str() || *end != '\0' || value < 0 || value > 1000) {
    throw InputError("--evidence-erode-mask", "'" + flag + "' must be auto or a pixel count in [0, 1000]");
  }
  segment->evidence_erode_mask = static_cast<int>(value);
}

std::string DescribeEvidence(const SegmentOptions& segment) {
  const bool same_pixels = segment.erode_mask_metres == 0.0 && segment.evidence_erode_mask == segment.erode_mask;
  if (segment.evidence_erode_mask < 0 || same_pixels) return "";
  if (segment.evidence_erode_mask == 0) return "; evidence: every mask point";
  return "; evidence: mask eroded by " + std::to_string(segment.evidence_erode_mask) + " px";
}

void AddFrameOptions(CLI::App& command, FrameFlags* flags) {
  command.add_option("--depth", flags->depth_path,
                     "Depth image: 16-bit PNG (value x depth_scale = mm) or .npy float metres");
  command.add_option("--mask", flags->mask_path, "Mask PNG (8/16-bit; non-zero = object, or --label-id)");
  command.add_option("--label-id", flags->label_id, "Mask is a label image: the object's pixels have this value");
  command.add_option("--camera", flags->camera_path,
                     "Camera JSON (cam_K row-major + depth_scale; BOP camera.json, or a scene_camera.json: "
                     "one image, or the --im-id entry)");
  command.add_option("--im-id", flags->im_id, "With --camera scene_camera.json: the image whose camera to use");
  command.add_option("--intrinsics", flags->intrinsics, "fx,fy,cx,cy (instead of --camera)");
  command.add_option("--depth-scale", flags->depth_scale, "Millimetres per depth unit (overrides the camera file's)");
}

FrameInput ResolveFrame(const FrameFlags& flags, const std::string& command) {
  if (flags.depth_path.empty() || flags.mask_path.empty()) throw InputError(command, "--depth and --mask go together");
  FrameInput frame;
  frame.depth_path = flags.depth_path;
  frame.mask_path = flags.mask_path;
  frame.label_id = flags.label_id;
  if (!flags.camera_path.empty() && !flags.intrinsics.empty()) {
    throw InputError(command, "give --camera FILE or --intrinsics fx,fy,cx,cy, not both");
  }
  if (flags.im_id && flags.camera_path.empty()) throw InputError("--im-id", "picks an entry of --camera FILE (a scene_camera.json); give --camera");
  if (!flags.camera_path.empty()) {
    frame.camera = ReadCameraJson(flags.camera_path, flags.depth_scale, flags.im_id);
  } else if (flags.intrinsics.empty()) {
    throw InputError(command, "--depth needs --camera FILE or --intrinsics fx,fy,cx,cy");
  } else if (!flags.depth_scale) {
    throw InputError(command, "--intrinsics needs --depth-scale S (mm per depth unit)");
  } else {
    frame.camera = CameraFromIntrinsics(flags.intrinsics, *flags.depth_scale);
  }
  return frame;
}

BopInstances ListBopInstancesWarning(const std::string& dir, const BopOptions& options, const std::string& command) {
  BopInstances listed = ListBopInstances(dir, options);
  for (const std::string& warning : listed.warnings) std::cerr << command << ": warning: " << warning << "\n";
  return listed;
}

void AddBopOptions(CLI::App& command, BopFlags* flags, BopDetections detections) {
  command.add_option("--bop", flags->dir, "BOP scene folder or split folder of numbered scenes");
  command.add_option("--obj-id", flags->options.obj_id, "BOP object id (with --bop)");
  command.add_option("--targets", flags->options.targets_path,
                     "BOP targets JSON (test_targets_bop19.json): only these images");
  if (detections == BopDetections::kAllowed) {
    command.add_option("--detections", flags->options.detections_path,
                       "BOP/COCO detections JSON (RLE masks) instead of ground-truth masks");
    command.add_option("--min-score", flags->options.min_score, "Skip detections scoring below this")
        ->capture_default_str();
  }
}

void AddCameraCloudOptions(CLI::App& command, CameraCloudFlags* flags, const std::string& augment_prefix,
                           const std::string& copies_help) {
  flags->noise_flag = "--" + augment_prefix + "noise";
  AddFrameOptions(command, &flags->frame);
  AddBopOptions(command, &flags->bop, BopDetections::kRefused);
  AddSegmentOptions(command, &flags->segment);
  command.add_option("--copies", flags->augment.copies, copies_help);
  command.add_option("--" + augment_prefix + "dropout", flags->augment.drop_fraction,
                     "Augmentation: fraction of each copy's points dropped")
      ->capture_default_str();
  command.add_option(flags->noise_flag, flags->noise,
                     "Augmentation: Gaussian noise sigma per coordinate of each copy (a distance: 1mm, 0.001, 0.5%d)")
      ->capture_default_str();
}

void ReportFlags::Check() const {
  if (views < 0) throw InputError("--views must be >= 0");
}

void AddReportOptions(CLI::App& command, ReportFlags* flags, const std::string& contents) {
  command.add_option("--report", flags->path, "Write a self-contained HTML report: " + contents)->check(WritableFile());
  command.add_option("--views", flags->views,
                     "3D examples in the report: this many certified and rejected (default 3)");
}

void AddShardOption(CLI::App& command, std::string* shard, const std::string& what) {
  command.add_option("--shard", *shard, "Process part K of N (K/N, 1-based) of the " + what +
                                            ": disjoint, deterministic; join with c3po merge");
}

}  // namespace c3po::cli
