// c3po annotate: make or edit an object file (keypoints on a CAD mesh), and
// optionally the self-contained HTML page to see and pick keypoints.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "c3po/authoring/annotate.hpp"
#include "c3po/base/error.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/io/mesh_io.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/web/annotation_page.hpp"
#include "command.hpp"
#include "options.hpp"

namespace c3po::cli {
namespace {

namespace fs = std::filesystem;

struct AnnotateCommand {
  std::string mesh;
  std::string output;
  std::string units;            // empty: m, or the edited object's units
  std::vector<std::string> keypoints;
  std::vector<std::string> names;
  bool no_snap = false;
  std::string max_snap = "5%d";
  int auto_count = 0;
  std::uint64_t seed = 0;
  std::string from_json, key;
  std::string from_keypointnet, model_id;
  std::string edit;
  std::vector<int> remove;
  bool drop_sets = false;
  std::string html;
  std::string eps_oc, delta_nd;  // empty: 3%d / 1.5%d, or the edited object's values
  std::string object_name;
};

void Declare(CLI::App& command, AnnotateCommand& o) {
  command.add_option("mesh", o.mesh, "Mesh file (OBJ, PLY, STL, OFF, glTF, ...); optional with --edit");
  command.add_option("-o,--output", o.output, "Object JSON to write (may be the --edit file)")
      ->check(WritableFile())->required();
  command.add_option("--units", o.units, "Units of the mesh file (default m, or the edited object's)")
      ->check(CLI::IsMember({"m", "cm", "mm"}));
  command.add_option("--keypoint", o.keypoints, "Keypoint X,Y,Z in metres (repeatable), snapped to the surface")
      ->allow_extra_args(false);
  command.add_option("--name", o.names, "Name of the --keypoint of the same rank (repeatable)")
      ->allow_extra_args(false);
  command.add_flag("--no-snap", o.no_snap, "Keep given points as they are (no snapping, no distance check)");
  command.add_option("--max-snap", o.max_snap, "Largest allowed snap distance (distance or 5%d)")
      ->capture_default_str();
  command.add_option("--auto", o.auto_count, "Propose K distinctive, spread-out keypoints")
      ->check(CLI::Range(1, 1000));
  command.add_option("--seed", o.seed, "Seed of --auto")->capture_default_str();
  auto* from_json = command.add_option("--from-json", o.from_json, "Import points from JSON keypoints[NAME] or NAME");
  auto* key = command.add_option("--key", o.key, "List name in the --from-json file");
  from_json->needs(key);
  key->needs(from_json);
  auto* kpnet = command.add_option("--from-keypointnet", o.from_keypointnet, "Import KeypointNet annotations");
  auto* model_id = command.add_option("--model-id", o.model_id, "Model id in the --from-keypointnet file");
  kpnet->needs(model_id);
  model_id->needs(kpnet);
  command.add_option("--edit", o.edit, "Existing object JSON to edit");
  command.add_option("--remove", o.remove, "Remove keypoint I of the edited object (repeatable)")
      ->allow_extra_args(false);
  command.add_flag("--drop-sets", o.drop_sets, "Drop indicator sets that contain a removed keypoint");
  command.add_option("--html", o.html, "Also write the self-contained annotation page")->check(WritableFile());
  command.add_option("--eps-oc", o.eps_oc, "Observable-correctness threshold (distance or 3%d)");
  command.add_option("--delta-nd", o.delta_nd, "Non-degeneracy threshold (distance or 1.5%d)");
  command.add_option("--object-name", o.object_name, "Object name (default: mesh file stem)");
}

// The object before any keypoint is added: the edited one, or a fresh one.
ObjectSpec BaseSpec(const AnnotateCommand& o) {
  ObjectSpec spec;
  if (!o.edit.empty()) spec = ReadObjectSpec(o.edit);
  if (!o.mesh.empty()) spec.mesh_path = fs::absolute(o.mesh).lexically_normal().string();
  if (!o.units.empty()) spec.units = o.units;
  if (!o.object_name.empty()) spec.name = o.object_name;
  if (spec.name.empty()) spec.name = fs::path(o.mesh).stem().string();
  return spec;
}

std::vector<KeypointSource> Sources(const AnnotateCommand& o) {
  std::vector<KeypointSource> sources;
  if (o.names.size() > o.keypoints.size()) {
    throw InputError("--name", std::to_string(o.names.size()) + " names for " +
                                   std::to_string(o.keypoints.size()) + " --keypoint points");
  }
  if (!o.keypoints.empty()) {
    KeypointSource given{"--keypoint", PointSet(3, static_cast<Eigen::Index>(o.keypoints.size())), {}};
    for (std::size_t i = 0; i < o.keypoints.size(); ++i) {
      given.points.col(static_cast<Eigen::Index>(i)) = ParsePointText(o.keypoints[i], "--keypoint");
    }
    if (!o.names.empty()) {
      given.names = o.names;
      given.names.resize(o.keypoints.size());
    }
    sources.push_back(given);
  }
  if (!o.from_json.empty()) {
    sources.push_back({o.from_json, ReadPointListJson(o.from_json, o.key), {}});
  }
  if (!o.from_keypointnet.empty()) {
    const KeypointNetModel model = ReadKeypointNet(o.from_keypointnet, o.model_id);
    sources.push_back({o.from_keypointnet, model.points, model.Names()});
  }
  return sources;
}

void ReportKeypoints(const AnnotationResult& result) {
  if (!result.dropped_sets.empty() || !result.new_index_of_old.empty()) {
    int removed = 0;
    for (int j : result.new_index_of_old) removed += j < 0;
    if (removed > 0) std::printf("removed %d keypoint(s); indicator sets remapped\n", removed);
  }
  for (const auto& set : result.dropped_sets) {
    std::string text;
    for (int i : set) text += (text.empty() ? "" : ",") + std::to_string(i);
    std::printf("dropped indicator set {%s} (old indices; it contained a removed keypoint)\n", text.c_str());
  }
  for (const AddedKeypoint& k : result.added) {
    const Eigen::Vector3d p = result.spec.keypoints.col(k.index);
    std::printf("keypoint %d \"%s\" from %s: (%.6g, %.6g, %.6g)", k.index,
                result.spec.KeypointName(k.index).c_str(), k.source.c_str(), p.x(), p.y(), p.z());
    if (k.saliency >= 0) {
      std::printf(", saliency %.3f, on the surface (distance %.3g)\n", k.saliency, k.snap.distance);
    } else if (k.snapped) {
      std::printf(", snapped %.6g to the surface\n", k.snap.distance);
    } else {
      std::printf(", not snapped, %.6g from the surface\n", k.snap.distance);
    }
  }
  if (result.auto_candidates > 0) {
    std::printf("--auto chose among %d salient candidates\n", result.auto_candidates);
  }
}

int Run(const AnnotateCommand& o) {
  if (o.mesh.empty() && o.edit.empty()) throw InputError("annotate", "give a MESH or --edit OBJECT.json");
  if (!o.remove.empty() && o.edit.empty()) throw InputError("--remove", "only with --edit OBJECT.json");
  ObjectSpec base = BaseSpec(o);
  const Mesh mesh = LoadMesh(base.mesh_path, MeshUnitScale(base.units));
  const double diameter = mesh.Diameter();
  std::printf("mesh %s: %lld vertices, %lld triangles, units %s, diameter d = %.6g m\n",
              base.mesh_path.c_str(), static_cast<long long>(mesh.vertices.cols()),
              static_cast<long long>(mesh.triangles.cols()), base.units.c_str(), diameter);

  AnnotationOptions options;
  options.snap = !o.no_snap;
  options.max_snap_distance = ParseThreshold(o.max_snap, diameter, "--max-snap");
  options.remove = o.remove;
  options.drop_sets = o.drop_sets;
  options.auto_count = o.auto_count;
  options.auto_options.seed = o.seed;
  const std::string where = o.edit.empty() ? base.mesh_path : o.edit;
  AnnotationResult result = AnnotateObject(mesh, base, Sources(o), options, where);
  ReportKeypoints(result);

  ObjectSpec& spec = result.spec;
  const bool keep_thresholds = !o.edit.empty();
  if (!o.eps_oc.empty() || !keep_thresholds) {
    spec.eps_oc = ParseThreshold(o.eps_oc.empty() ? "3%d" : o.eps_oc, diameter, "--eps-oc");
  }
  if (!o.delta_nd.empty() || !keep_thresholds) {
    spec.delta_nd = ParseThreshold(o.delta_nd.empty() ? "1.5%d" : o.delta_nd, diameter, "--delta-nd");
  }
  std::printf("eps_oc = %.6g (%.3g %% of d), delta_nd = %.6g (%.3g %% of d)\n", spec.eps_oc,
              100 * spec.eps_oc / diameter, spec.delta_nd, 100 * spec.delta_nd / diameter);
  spec.Validate(o.output);
  if (!o.html.empty()) WriteAnnotationPage(spec, mesh, o.output, o.html);
  WriteObjectSpec(spec, o.output);
  std::printf("wrote %s: %d keypoints, %zu indicator sets\n", o.output.c_str(), spec.num_keypoints(),
              spec.indicator_sets.size());
  if (!o.html.empty()) std::printf("wrote %s (open it in a browser; no network needed)\n", o.html.c_str());
  return 0;
}

const char* const kNotes = R"(
Notes:
  Coordinates (--keypoint, --from-json, --from-keypointnet) are in object units
  (metres); the mesh is converted from --units first. Each point is snapped to
  the nearest surface point and the distance printed; a point farther than
  --max-snap is an error unless --no-snap.
  Sources combine, in this order: --edit's keypoints (minus --remove), --keypoint,
  --from-json, --from-keypointnet, then --auto (spread away from all of those).
  --remove I refers to the edited object's indices; indicator sets are renumbered.
  A set that contains a removed keypoint makes the command refuse, unless
  --drop-sets, which drops such sets (printed). The annotation page (--html) applies
  the same rule when a keypoint is clicked away.
  eps_oc / delta_nd default to 3%d / 1.5%d of the diameter d (kept when editing) and
  are written as absolute distances.
More examples:
  c3po annotate mug.obj --auto 8 --seed 1 -o mug.json --html mug.html
  c3po annotate textured.obj -o mug.json --from-json keypoints.json --key farthest8
  c3po annotate --edit mug.json --remove 3 --drop-sets --keypoint 0.01,0.02,0.1 -o mug.json)";

}  // namespace

RunFunction SetupAnnotate(CLI::App& command) {
  auto options = std::make_shared<AnnotateCommand>();
  Declare(command, *options);
  command.footer(command.get_footer() + kNotes);
  return [options]() { return Run(*options); };
}

}  // namespace c3po::cli
