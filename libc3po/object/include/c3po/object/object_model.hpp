#pragma once
// An object: mesh B, dense surface sample B̂ with a k-d tree in the model frame,
// diameter d, semantic keypoints b (3xN), indicator sets and certificate
// thresholds (paper Sections III, V).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/geometry/kdtree.hpp"
#include "c3po/geometry/mesh.hpp"
#include "c3po/geometry/nearest_grid.hpp"

namespace c3po {

// What an object JSON file says (annotations/README.md documents the schema).
struct ObjectSpec {
  int schema_version = 1;
  std::string name;
  std::string mesh_path;                 // absolute (resolved) path in memory
  std::string units = "m";               // "m" or "mm" (of the mesh file)
  PointSet keypoints;                    // 3 x N, model frame, object units (metres)
  std::vector<std::string> keypoint_names;            // empty or N
  std::vector<std::vector<int>> indicator_sets;       // indices into keypoints
  double eps_oc = 0.0;                   // absolute, object units
  double delta_nd = 0.0;                 // absolute, object units
  // Optional metadata written by tools (e.g. measured precision/recall of
  // automatic indicator sets); kept verbatim as a JSON string.
  std::string extra_json;

  int num_keypoints() const { return static_cast<int>(keypoints.cols()); }
  std::string KeypointName(int i) const;   // name or "kp<i>"
  // Throws InputError("<where>: <field>: problem") on inconsistent content.
  void Validate(const std::string& where) const;
};

struct ObjectModelOptions {
  int sample_size = 10000;     // |B̂|
  std::uint64_t seed = 0;      // seed of the surface sample
  void Check() const;
};

class ObjectModel {
 public:
  ObjectModel(ObjectSpec spec, Mesh mesh, const ObjectModelOptions& options = {});

  const ObjectSpec& spec() const { return spec_; }
  ObjectSpec& mutable_spec() { return spec_; }
  const std::string& name() const { return spec_.name; }
  const Mesh& mesh() const { return mesh_; }
  const PointSet& keypoints() const { return spec_.keypoints; }
  int num_keypoints() const { return spec_.num_keypoints(); }
  const PointSet& sample() const { return tree_->points(); }   // B̂, model frame
  const PointTree& tree() const { return *tree_; }
  // The exact nearest-neighbour grid over B̂ that NearestInPosedModel queries,
  // built at its first use (thread-safe; copies of the model share it).
  const NearestGrid& grid() const;
  // Unit outward normals of B̂ (of the triangle each sample point lies on).
  const PointSet& sample_normals() const { return *normals_; }
  // Mesh triangle each sample point lies on.
  const std::vector<int>& sample_triangles() const { return *triangles_; }
  // 1 where a sample point lies at an edge or crease of the mesh (a neighbour
  // among its 8 nearest has a normal > 30 degrees off its own line; the
  // opposite face of a thin wall is not a crease): its normal does not
  // represent nearby points (local non-degeneracy skips them).
  const std::vector<char>& sample_on_crease() const { return *crease_; }
  double diameter() const { return diameter_; }
  // Mean nearest-neighbour spacing of B̂ (an estimate of the sampling density
  // term eps_s of Theorem 12).
  double SampleSpacing() const;
  // Stable hash of the keypoints (and name), for model files.
  std::string KeypointHash() const;

  // Nearest model-sample point of every scene point under pose T, computed as
  // queries of R^T (x - t) against the model-frame grid (no per-pose rebuild;
  // exact, nearest_grid.hpp). `hints` (one sample index per scene point, e.g.
  // its nearest at the previous iterate) speed up the queries the grid hands
  // to the tree.
  void NearestInPosedModel(const PointSet& scene, const Pose& scene_from_model, Eigen::VectorXi* indices,
                           Eigen::VectorXd* squared_distances, const Eigen::VectorXi* hints = nullptr) const;
  // Distances (not squared) of every scene point to the posed model sample.
  Eigen::VectorXd DistancesToPosedModel(const PointSet& scene, const Pose& scene_from_model) const;

 private:
  ObjectSpec spec_;
  Mesh mesh_;
  std::shared_ptr<const PointTree> tree_;
  struct LazyGrid;
  std::shared_ptr<LazyGrid> grid_;
  std::shared_ptr<const PointSet> normals_;
  std::shared_ptr<const std::vector<int>> triangles_;
  std::shared_ptr<const std::vector<char>> crease_;
  double diameter_ = 0.0;
  mutable double spacing_ = -1.0;
};

// Hausdorff(T1·B̂, T2·B̂) = Hausdorff(B̂, T·B̂), T = T1^-1 T2, with a subsample
// Q of B̂ as queries and the model tree as targets (no rebuild). A distance
// between posed shapes: symmetries of the object cost nothing.
double PosedModelHausdorff(const ObjectModel& object, const PointSet& queries, const Pose& first,
                           const Pose& second);

// The same with distances to the model *surface*: each point's distance to
// the mesh triangles of its 16 nearest sample points (exact point-to-triangle
// distances; an upper bound on the distance to the whole surface, tight
// where the nearest triangle is among them). Free of the sampling floor
// (~ the sample spacing) that PosedModelHausdorff carries: an exact symmetry
// of the surface measures as the fit's difference, not as the spacing.
double PosedSurfaceHausdorff(const ObjectModel& object, const PointSet& queries, const Pose& first,
                             const Pose& second);

}  // namespace c3po
