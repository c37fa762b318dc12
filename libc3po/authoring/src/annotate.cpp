// The annotation step: remove, add (snapped), propose (auto).
#include "c3po/authoring/annotate.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "c3po/base/error.hpp"

namespace c3po {
namespace {

std::string PointText(const Eigen::Vector3d& p) {
  std::ostringstream text;
  text << std::setprecision(6) << p.x() << "," << p.y() << "," << p.z();
  return text.str();
}

void AddSource(const Mesh& mesh, const KeypointSource& source, const AnnotationOptions& options,
               AnnotationResult* result) {
  if (!source.names.empty() && source.names.size() != static_cast<std::size_t>(source.points.cols())) {
    throw std::invalid_argument("KeypointSource: names must be empty or one per point");
  }
  const std::vector<SnapResult> snaps = SnapToSurface(mesh, source.points);
  PointSet points = source.points;
  for (std::size_t i = 0; i < snaps.size(); ++i) {
    const SnapResult& snap = snaps[i];
    if (options.snap && snap.distance > options.max_snap_distance) {
      std::ostringstream text;
      text << "point " << i << " (" << PointText(snap.requested) << ") is " << snap.distance
           << " from the surface, more than --max-snap " << options.max_snap_distance
           << " (use --no-snap to keep it off the surface)";
      throw InputError(source.label, text.str());
    }
    if (options.snap) points.col(static_cast<Eigen::Index>(i)) = snap.point;
    AddedKeypoint added;
    added.index = result->spec.num_keypoints() + static_cast<int>(i);
    added.name = source.names.empty() ? "" : source.names[i];
    added.source = source.label;
    added.snap = snap;
    added.snapped = options.snap;
    result->added.push_back(added);
  }
  AppendKeypoints(&result->spec, points, source.names);
}

void AddAuto(const Mesh& mesh, const AnnotationOptions& options, AnnotationResult* result) {
  AutoKeypointOptions auto_options = options.auto_options;
  auto_options.count = options.auto_count;
  const AutoKeypoints proposal = ProposeKeypoints(mesh, auto_options, result->spec.keypoints);
  result->auto_candidates = proposal.candidate_count;
  std::vector<std::string> names;
  int next = 0;
  for (Eigen::Index k = 0; k < proposal.points.cols(); ++k) {
    names.push_back(UnusedName(result->spec, "auto", &next));
  }
  const std::vector<SnapResult> snaps = SnapToSurface(mesh, proposal.points);
  for (Eigen::Index k = 0; k < proposal.points.cols(); ++k) {
    AddedKeypoint added;
    added.index = result->spec.num_keypoints() + static_cast<int>(k);
    added.name = names[k];
    added.source = "--auto";
    added.snap = snaps[k];
    added.saliency = proposal.saliency[k];
    result->added.push_back(added);
  }
  AppendKeypoints(&result->spec, proposal.points, names);
}

}  // namespace

double MeshUnitScale(const std::string& units) {
  if (units == "m") return 1.0;
  if (units == "cm") return 1e-2;
  if (units == "mm") return 1e-3;
  throw InputError("--units", "'" + units + "' is not one of m, cm, mm");
}

void AnnotationOptions::Check() const {
  if (!(max_snap_distance >= 0.0)) throw std::invalid_argument("AnnotationOptions: max_snap_distance < 0");
  if (auto_count < 0) throw std::invalid_argument("AnnotationOptions: auto_count < 0");
}

AnnotationResult AnnotateObject(const Mesh& mesh, const ObjectSpec& base,
                                const std::vector<KeypointSource>& sources,
                                const AnnotationOptions& options, const std::string& where) {
  options.Check();
  if (mesh.empty()) throw InputError(where, "mesh has no triangles");
  AnnotationResult result;
  KeypointRemoval removal = RemoveKeypoints(base, options.remove, options.drop_sets, where);
  result.spec = std::move(removal.spec);
  result.new_index_of_old = std::move(removal.new_index_of_old);
  result.dropped_sets = std::move(removal.dropped_sets);
  for (const KeypointSource& source : sources) AddSource(mesh, source, options, &result);
  if (options.auto_count > 0) AddAuto(mesh, options, &result);
  return result;
}

}  // namespace c3po
