#pragma once
// The command-line options several subcommands share, declared once and bound
// to the library's options structs: certificate thresholds (--eps-oc,
// --delta-nd: a distance, a fraction of d such as 3%d, or `auto` where the
// command allows it), corrector (--solver, --loss), detector choice (--model,
// --detector, --plugin), --seed and --threads. A new option group (camera
// inputs, --max-outliers, ...) is one more struct + Add/Resolve pair here.
// No maths: resolving only parses text and fills structs.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "c3po/io/bop.hpp"
#include "c3po/io/segment.hpp"
#include "c3po/io/shard.hpp"
#include "c3po/method/certificate.hpp"
#include "c3po/method/corrector.hpp"
#include "c3po/method/detector.hpp"
#include "c3po/method/model_symmetries.hpp"
#include "c3po/method/selftrain_inputs.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po::cli {

// The CLI11 check of an output file option (-o, --report, --json, ...): the
// file can be written there now (CheckWritableFile: its folder exists and
// takes a new file), so a typo in the path fails at once, not after the run.
// `dash_is_stdout`: "-" passes (the option's stdout spelling).
CLI::Validator WritableFile(bool dash_is_stdout = false);

// --report FILE and --views N of certify and eval (the HTML reports).
struct ReportFlags {
  std::string path;   // "" = no report
  int views = 3;      // certified and rejected 3D examples
  void Check() const; // throws InputError for --views < 0
};
void AddReportOptions(CLI::App& command, ReportFlags* flags, const std::string& contents);

enum class AutoEpsOc { kRefused, kAllowed };
// --eps-oc, --delta-nd as typed ("" = the object's value).
struct ThresholdFlags {
  std::string eps_oc;
  std::string delta_nd;
  AutoEpsOc auto_mode = AutoEpsOc::kRefused;   // set by AddThresholdOptions
  bool auto_eps_oc() const { return eps_oc == "auto"; }
};
void AddThresholdOptions(CLI::App& command, ThresholdFlags* flags, AutoEpsOc auto_eps_oc);
// The object's thresholds overridden by the flags (absolute, object units).
// With --eps-oc auto (where allowed), eps_oc stays the object's: CertifyBatch
// decides it. Throws InputError("--eps-oc: ...") for a bad value, and for
// `auto` where it is refused.
CertificateOptions ResolveThresholds(const ThresholdFlags& flags, const ObjectModel& object);

// --solver, --loss.
struct CorrectorFlags {
  std::string solver = "fast";
  std::string loss = "mean";
};
void AddCorrectorOptions(CLI::App& command, CorrectorFlags* flags);
// --loss alone (for a command that compares several solvers).
void AddLossOption(CLI::App& command, std::string* loss);
// `options` with solver and loss set from the flags (InputError on bad names).
void ResolveCorrector(const CorrectorFlags& flags, CorrectorOptions* options);

// --max-outliers, --robust-loss, --nd-min-eigenvalue (issue 16): the outlier
// budget m of oc_m / nd_m, the corrector's robust kernel, the local
// non-degeneracy threshold. The meaning lives in the library (certificate.hpp,
// corrector.hpp, local_nondegeneracy.hpp).
struct RobustFlags {
  std::string max_outliers;        // "" = the input's default (InputKind below)
  std::string robust_loss;         // "" = the input's default (InputKind below)
  std::string indicator_sets;      // --indicator-sets on|off ("" = the input's default, InputKind below)
  std::string nd_min_eigenvalue;   // "" = default; 0 = local test off
  bool no_global_check = false;    // --no-global-check: nd without the rival search
  bool reestimate = false;         // --reestimate: restart a refuted estimate at the rival turns
  bool no_reestimate = false;      // --no-reestimate
  // The default without either flag for InputKind::kCameraFrames (certify,
  // eval: on; selftrain sets it off -- its rounds certify every instance again).
  bool reestimate_camera_frames = true;
  bool no_weak_motion_check = false;   // --no-weak-motion-check: a single weak motion fails nd
  bool no_centre = false;              // --no-centre: a pose refused by near rivals is not centred
  int global_steps = 4;            // --global-steps
  int reestimate_steps = 12;       // --reestimate-steps
  bool no_free_space = false;      // --no-free-space (depth-image inputs)
  std::string free_space_fraction; // --free-space-fraction ("" = default)
  std::string free_space_accept;   // --free-space-accept ("" = default, at most the fraction)
  std::string outside_mask;        // --outside-mask-fraction ("" = default)
  std::string uncovered_mask;      // --uncovered-mask-fraction ("" = default)
  std::string rival_distance;      // --rival-distance ("" = the tolerance - eps_oc)
  std::string tolerance;           // --tolerance ("" = GlobalUniquenessOptions::Tolerance's default)
};
void AddRobustOptions(CLI::App& command, RobustFlags* flags);
// What the clouds of a run are; where --max-outliers / --robust-loss are not
// given it decides the defaults (docs/method.md "Options and defaults"):
enum class InputKind {
  kClouds,          // ready-made clouds: the paper, m = 0 and no kernel
  // Segments cut from camera frames mixed with clouds that have no frame
  // (selftrain's camera inputs with --data): kernel kDepthImageRobustLoss,
  // m = 0.
  kCameraSegments,
  // Depth frames certified with their frame (certify --depth/--mask, --bop;
  // eval --bop; selftrain's camera inputs alone): kernel
  // kDepthImageRobustLoss and, while the free-space test is on, the budget
  // kDepthImageOutlierFraction with the indicator sets off (nd_m with a
  // percentage budget needs more than m points within delta_nd of every set
  // keypoint, which a small delta_nd cannot supply; measured: the bundled
  // box certifies 29 of 30 rendered frames without its sets, 12 with them at
  // m = 0). The budget was measured sound on real frames only with free space
  // (without it, 8 false certificates of 200: mustard flips); there, and with
  // --indicator-sets on for an object with sets, m stays 0. A refuted
  // estimate is re-estimated (RobustFlags::reestimate_camera_frames; the
  // mask is the object's, so a second basin is worth seconds).
  kCameraFrames,
};
// Fills the certificate's budget, local test and rival search and the corrector's kernel
// (InputError naming the option on a bad value). certify, eval, selftrain
// and bench share it, so one input gets one set of defaults everywhere.
void ResolveRobust(const RobustFlags& flags, InputKind input, const ObjectModel& object,
                   CertificateOptions* certificate, CorrectorOptions* corrector);
// "m = 2%, robust loss = tls, local nd >= 0.02" for the printed summary.
std::string DescribeRobust(const CertificateOptions& certificate, const CorrectorOptions& corrector);
// " --max-outliers 2% --robust-loss tls" (the flags given, for a command line).
std::string RobustCommandLine(const RobustFlags& flags);

// --model, --detector, --plugin: one detector (certify) or several (eval).
struct DetectorFlags {
  std::vector<std::string> models;
  std::vector<std::string> detectors;   // registry names, or "manifest"
  std::vector<std::string> plugins;
};
enum class DetectorCount { kOne, kMany };
void AddDetectorOptions(CLI::App& command, DetectorFlags* flags, DetectorCount count);
// Loads the --plugin libraries (before any detector is made).
void LoadPlugins(const DetectorFlags& flags);
// kOne: exactly one of --model / --detector. nullptr for --detector manifest
// (the manifest's detected_keypoints are the detections).
std::unique_ptr<Detector> MakeDetector(const std::string& model, const std::string& detector,
                                       const ObjectModel& object);
constexpr const char* kManifestDetector = "manifest";

// Camera inputs (docs/camera_inputs.md). --erode-mask, --depth-edge,
// --max-points: the segment preprocessing (defaults: SegmentOptions).
void AddSegmentOptions(CLI::App& command, SegmentOptions* options);
// --erode-mask's value: "3mm" / "0.5cm" / "0.003m" (a width at the segment's
// depth) or "4" / "4px" (pixels); CLI::ValidationError otherwise.
void SetMaskErosion(const std::string& text, SegmentOptions* options);
// options->Check() as an InputError naming the command.
void CheckSegmentOptions(const SegmentOptions& options, const std::string& command);
// --evidence-erode-mask: "auto" (default) or K pixels. Resolved into
// segment->evidence_erode_mask: K as given; auto = 0 (the certificate judges
// every mask point) when the certificate has an outlier budget m > 0 to count
// the mask's stray pixels, else -1 (it judges the estimate's eroded cloud).
// InputError("--evidence-erode-mask", ...) when neither.
void AddEvidenceOption(CLI::App& command, std::string* flag);
void ResolveEvidence(const std::string& flag, const CertificateOptions& certificate, SegmentOptions* segment);
// "; evidence: every mask point" / "; evidence: mask eroded by K px" / "" (-1).
std::string DescribeEvidence(const SegmentOptions& segment);

// --depth, --mask, --label-id, --camera, --im-id, --intrinsics, --depth-scale: one frame.
struct FrameFlags {
  std::string depth_path;
  std::string mask_path;
  int label_id = -1;
  std::string camera_path;
  std::string intrinsics;
  std::optional<double> depth_scale;
  std::optional<int> im_id;   // --im-id: the entry of a scene_camera.json of several images
  bool given() const { return !depth_path.empty() || !mask_path.empty(); }
};
void AddFrameOptions(CLI::App& command, FrameFlags* flags);
// The frame the flags name (reads the camera file). InputError when --depth
// and --mask are not given together, or the camera is missing / given twice.
FrameInput ResolveFrame(const FrameFlags& flags, const std::string& command);

// --bop, --obj-id, --targets and (certify) --detections, --min-score.
struct BopFlags {
  std::string dir;
  BopOptions options;
};
enum class BopDetections { kRefused, kAllowed };
void AddBopOptions(CLI::App& command, BopFlags* flags, BopDetections detections);
// ListBopInstances(dir, options), its warnings (unusable ground-truth poses,
// reported as null) printed to stderr as "COMMAND: warning: ...".
BopInstances ListBopInstancesWarning(const std::string& dir, const BopOptions& options, const std::string& command);

// Camera inputs of the training commands (selftrain, train): one frame
// (--depth/--mask/--camera) and/or BOP instances (--bop/--obj-id/--targets),
// the segment preprocessing, and the paper's augmentation: --copies N per
// real instance, each dropping a fraction of its points and adding noise
// (selftrain_inputs.hpp AugmentOptions). The dropout/noise flags are named
// <augment_prefix>dropout / <augment_prefix>noise: "" in selftrain, "copy-"
// in train (whose --dropout/--noise are its per-epoch augmentation).
struct CameraCloudFlags {
  FrameFlags frame;
  BopFlags bop;
  // selftrain only (--add-obj-id): BOP objects whose instances are added as
  // unlabelled clouds of other objects (a mixed set; the label is only reported).
  std::vector<int> other_obj_ids;
  SegmentOptions segment;
  AugmentOptions augment;        // noise_sigma and seed are set when loading
  std::string noise = "1mm";     // a distance: 1mm, 0.001, 0.5%d
  std::string noise_flag = "--noise";   // its name (set by AddCameraCloudOptions)
  bool given() const { return frame.given() || !bop.dir.empty(); }
};
void AddCameraCloudOptions(CLI::App& command, CameraCloudFlags* flags, const std::string& augment_prefix,
                           const std::string& copies_help);

// --shard K/N ("" = the whole run); ParseShard (c3po/io/shard.hpp) resolves it.
void AddShardOption(CLI::App& command, std::string* shard, const std::string& what);

// --no-symmetry-aware-* / --symmetry-tolerance: the object's rotational
// symmetries (method/model_symmetries.hpp), used by train (loss) and eval
// (errors to the nearest symmetric truth).
struct SymmetryFlags {
  bool enabled = true;
  std::string tolerance;    // distance or fraction of d; "" = the object's eps_oc / 4
};
void AddSymmetryOptions(CLI::App& command, SymmetryFlags* flags, const std::string& off_flag,
                        const std::string& off_help);
// The symmetries (none when disabled), listed on stderr with their evidence
// as "<object>: N symmetries within TOL ...". InputError on a bad tolerance.
std::vector<ModelSymmetry> ObjectSymmetries(const SymmetryFlags& flags, const ObjectModel& object,
                                            const std::string& use);

void AddSeedOption(CLI::App& command, std::uint64_t* seed, const std::string& what);
void AddThreadsOption(CLI::App& command, int* threads, const std::string& what);

}  // namespace c3po::cli
