#pragma once
// Keypoint annotation of a CAD mesh (`c3po annotate`): snapping user points to
// the surface, proposing distinctive spread-out keypoints automatically,
// importing point lists (JSON, KeypointNet) and editing an existing object
// (removing keypoints with indicator-set remapping).
//
// All coordinates are in object units (metres for real objects): the mesh is
// loaded already scaled (LoadMesh(path, scale)), and imported points are taken
// in the same units as the object file.
#include <cstdint>
#include <string>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

// ---- snapping ---------------------------------------------------------------

struct SnapResult {
  Eigen::Vector3d requested = Eigen::Vector3d::Zero();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // on the surface (or requested if not snapped)
  double distance = 0.0;                              // |requested - closest surface point|
  int triangle = -1;                                  // triangle of the closest surface point
};

// Exact closest surface point of every column of `points` (O(T) each; both cores).
std::vector<SnapResult> SnapToSurface(const Mesh& mesh, const PointSet& points);

// ---- automatic keypoints ------------------------------------------------------

struct AutoKeypointOptions {
  int count = 8;                  // K keypoints to propose
  std::uint64_t seed = 0;         // surface sample and first farthest-point pick
  int sample_size = 20000;        // dense surface sample for saliency
  int small_neighbourhood = 16;   // k of the fine PCA scale
  int large_neighbourhood = 64;   // k of the coarse PCA scale
  double salient_fraction = 0.15; // keep this top fraction of samples as candidates
  int max_mesh_vertices = 100000; // mesh vertices join the candidates up to this many
  void Check() const;
};

struct AutoKeypoints {
  PointSet points;                  // 3 x K, on the surface
  std::vector<double> saliency;     // saliency of each keypoint (surface variation)
  std::vector<int> triangle;        // triangle each keypoint lies on
  int candidate_count = 0;          // saliency peaks FPS chose from
  double min_separation = 0.0;      // smallest distance between two proposed keypoints
};

// Surface variation λ0/(λ0+λ1+λ2) of the covariance of each point's k nearest
// neighbours (Pauly et al. 2002): 0 on planes, up to 1/3 at isotropic corners.
std::vector<double> SurfaceVariation(const PointSet& points, int neighbours);

// Distinctive, spread-out keypoints. Points: a dense surface sample (seeded)
// plus the mesh vertices (exact corners). Saliency = max of the surface
// variation at two scales. Candidates = the most salient `salient_fraction`
// plus the extremal points along the shape's principal axes (tips). Peaks =
// candidates that are saliency maxima among their large neighbourhood, plus
// the tips. Farthest-point sampling among the peaks (first pick drawn with
// `seed`, or the peak farthest from `existing` keypoints when there are any),
// continued among all candidates if there are fewer peaks than `count`.
// Deterministic for a seed. Throws InputError when the mesh does not offer
// `count` distinct candidates.
AutoKeypoints ProposeKeypoints(const Mesh& mesh, const AutoKeypointOptions& options,
                               const PointSet& existing = PointSet(3, 0));

// ---- imports ------------------------------------------------------------------

// "X,Y,Z" (spaces allowed) -> point. Throws InputError(what + ": ...").
Eigen::Vector3d ParsePointText(const std::string& text, const std::string& what);

// A JSON object whose `keypoints[key]` (or top-level `key`) is a list of
// [x, y, z] (or one [x, y, z]). Throws InputError("path: ...") naming the
// available keys when `key` is absent.
PointSet ReadPointListJson(const std::string& path, const std::string& key);

struct KeypointNetModel {
  std::string class_id;
  std::string model_id;
  PointSet points;                 // 3 x N, the `xyz` of each keypoint
  std::vector<int> semantic_ids;   // N
  std::vector<std::string> Names() const;   // "semantic<k>"
};

// KeypointNet annotation file: a list of {"class_id", "model_id", "keypoints":
// [{"xyz": [x,y,z], "semantic_id": k, ...}]}. Throws InputError("path: model
// id 'ID' not found ...") for an unknown model id.
KeypointNetModel ReadKeypointNet(const std::string& path, const std::string& model_id);

// ---- editing ------------------------------------------------------------------

struct KeypointRemoval {
  ObjectSpec spec;                      // keypoints removed, sets remapped
  std::vector<int> new_index_of_old;    // -1 for removed keypoints
  std::vector<std::vector<int>> dropped_sets;   // old indices of the dropped sets
};

// Removes keypoints `remove` (indices into spec's list, any order, duplicates
// allowed) and remaps indicator sets to the new indices. A set containing a
// removed keypoint is dropped when `drop_sets`, otherwise InputError(where +
// ": ...") names the set. Out-of-range indices are an InputError.
KeypointRemoval RemoveKeypoints(const ObjectSpec& spec, const std::vector<int>& remove,
                                bool drop_sets, const std::string& where);

// Appends keypoints with names ("" = unnamed); keeps keypoint_names empty when
// every name is empty.
void AppendKeypoints(ObjectSpec* spec, const PointSet& points,
                     const std::vector<std::string>& names);

// "<prefix><i>" with the smallest i >= 0 not yet used as a name in `spec`.
std::string UnusedName(const ObjectSpec& spec, const std::string& prefix, int* next_index);

// ---- the whole annotation step (what `c3po annotate` runs) ------------------

// Metres per mesh unit: "m" 1, "cm" 0.01, "mm" 0.001; InputError otherwise.
double MeshUnitScale(const std::string& units);

// Points from one origin (--keypoint, --from-json, ...); `names` empty or one
// per point ("" = unnamed).
struct KeypointSource {
  std::string label;
  PointSet points = PointSet(3, 0);
  std::vector<std::string> names;
};

struct AnnotationOptions {
  bool snap = true;                 // snap source points to the surface
  double max_snap_distance = 0.0;   // absolute; farther points are an error when snapping
  std::vector<int> remove;          // indices into the base object's keypoints
  bool drop_sets = false;           // drop indicator sets that contain removed keypoints
  int auto_count = 0;               // --auto K (0 = none)
  AutoKeypointOptions auto_options; // its count is set from auto_count
  void Check() const;
};

struct AddedKeypoint {
  int index = -1;             // in the resulting object
  std::string name;
  std::string source;         // label of its KeypointSource, or "--auto"
  SnapResult snap;            // distance of the given point to the surface
  bool snapped = false;       // point moved onto the surface
  double saliency = -1.0;     // --auto keypoints only
};

struct AnnotationResult {
  ObjectSpec spec;                           // keypoints edited; thresholds untouched
  std::vector<int> new_index_of_old;         // base keypoint i -> index now (-1 removed)
  std::vector<std::vector<int>> dropped_sets;  // old indices
  std::vector<AddedKeypoint> added;
  int auto_candidates = 0;
};

// Removes `options.remove` from `base` (RemoveKeypoints; errors name `where`),
// then appends the sources' points in order (snapped to `mesh` unless
// !options.snap; a point farther than max_snap_distance is an InputError
// naming its source), then `auto_count` proposed keypoints named "auto<i>"
// spread away from every keypoint already present.
AnnotationResult AnnotateObject(const Mesh& mesh, const ObjectSpec& base,
                                const std::vector<KeypointSource>& sources,
                                const AnnotationOptions& options, const std::string& where);

}  // namespace c3po
