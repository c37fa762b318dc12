#pragma once
// Rotational symmetries of an object's surface, and the labellings they make
// equivalent (docs/method.md "Symmetric labellings in supervised training").
//
// A symmetry is a rotation S about the centroid of B̂ with
// Hausdorff(B, S·B) <= tolerance, measured to the mesh surface
// (PosedSurfaceHausdorff: free of the sampling floor). The candidates are the
// rotations by 2πk/n (n = 2..max_order) about each principal axis and the 24
// rotations that map the principal frame onto itself (signed permutations):
// every symmetry of an object whose principal extents differ is among them
// (a symmetry preserves the inertia tensor, hence maps each principal axis to
// ± itself). Equal extents leave the principal axes arbitrary in their
// eigenspace, so the same candidates are also built from the mesh's dominant
// face-normal directions (>= 5 % of the area each) and the frames of their
// orthogonal pairs: a cube's 23 and a square prism's 7 are found; an object
// with equal extents and no dominant flat faces may lose symmetries about
// other axes. A continuous symmetry (a can) shows as its rotations of order
// <= max_order.
//
// For a cloud of a symmetric object at pose T, the poses T·S give the same
// surface: its keypoint labels y = T b and y_S = T S b are equally right, and
// a detector trained on y alone by mean squared error learns their average
// (which is no labelling). Training against min_S ||ỹ - y_S||² lets it choose
// one per cloud.
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct SymmetrySearchOptions {
  double tolerance = 0.0;     // object units: largest surface Hausdorff distance of a symmetry
  int max_order = 8;          // axis rotations by 2πk/n for n = 2..max_order
  int queries = 2000;         // sample points of B̂ measured (strided)
  void Check() const;         // throws std::invalid_argument
};

struct ModelSymmetry {
  Pose model_from_model;      // x -> R x + t, a rotation about the centroid of B̂
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   // unit rotation axis (model frame)
  double angle = 0.0;         // radians, in (0, π]
  double hausdorff = 0.0;     // PosedSurfaceHausdorff(B, S·B): the evidence
};

// The symmetries (identity excluded), each rotation once (within 3°),
// ordered by angle, then axis.
std::vector<ModelSymmetry> FindModelSymmetries(const ObjectModel& object, const SymmetrySearchOptions& options);

// The other labellings of posed keypoints y = T b: T S b for every symmetry,
// with T registered from the object's keypoints b to y (SVD). Empty when
// there is no symmetry, when the registration fails (fewer than 3 distinct
// or collinear keypoints) or when y is not a rigid copy of b (rms residual
// above 1e-3 of the diameter).
std::vector<PointSet> SymmetricLabellings(const ObjectModel& object, const std::vector<ModelSymmetry>& symmetries,
                                          const PointSet& posed_keypoints);

// The truth among T* and T*·S (S in `symmetries`, model_from_model) whose
// rotation is nearest the estimate's (largest tr(R̂ᵀ R), i.e. smallest
// angle; T* on ties): pose errors measured to it do not count a symmetry of
// the object as an error (eval's rotation and translation errors, the
// self-training log's rotation error).
Pose NearestSymmetricTruth(const Pose& truth, const Pose& estimate, const std::vector<Pose>& symmetries);

}  // namespace c3po
