#pragma once
// Local non-degeneracy without indicator sets (issue 16; docs/method.md
// "Local non-degeneracy"). At the estimate T̂, a small twist ξ = (r ω, v)
// (model frame, about the centroid c of B̂, r = d/2 so both halves are
// lengths) moves a surface point p with unit normal n off the surface by
// J(p)ᵀξ, J(p) = ((p - c) × n / r, n) (first order). With
//   H_data  = mean over the accepted input points of J(p_j) J(p_j)ᵀ
//             (p_j = nearest B̂ point of T̂⁻¹ x_j, n_j its mesh normal),
//   H_model = mean over the area-uniform sample B̂ of J(p) J(p)ᵀ,
// the evidence is λ_min = min ξᵀH_data ξ / ξᵀH_model ξ over the motions the
// model sees (eigenvectors of H_model above model_floor × its largest;
// sample points on edges/creases, ObjectModel::sample_on_crease, are left
// out on both sides: their normal does not represent the nearby points;
// symmetries of the shape move no surface and are excluded) and its motion.
// Guarantees local (first-order) uniqueness of the fit up to the model's
// (near-)symmetries; says nothing about far-away poses (indicator sets).
#include <Eigen/Core>
#include <vector>

#include "c3po/object/object_model.hpp"
#include "c3po/base/types.hpp"

namespace c3po {

// nd_min_eigenvalue default: measured on rendered depth views (method.md).
constexpr double kDefaultLocalNdMinEigenvalue = 0.02;

struct LocalNonDegeneracyOptions {
  double min_eigenvalue = kDefaultLocalNdMinEigenvalue;  // pass iff λ_min >= this
  double model_floor = 1e-3;   // motions with model information below floor × max are symmetries
  int min_points = 6;          // fewer accepted points: fails (6 unknowns)
  // A single weak motion may be discharged by displacing the pose along it
  // and refitting (global_uniqueness.hpp, CheckWeakMotion): the first-order
  // test cannot see the outline of a face (a box seen on two faces slides
  // along their edge to first order, not finitely).
  bool weak_motion_check = true;
  void Check() const;          // throws std::invalid_argument
};

struct LocalNonDegeneracy {
  bool passed = false;
  double min_eigenvalue = 0.0;        // λ_min (after removing the m most informative points)
  double eigenvalue_all_points = 0.0; // λ_min of the plain generalised eigenproblem
  Eigen::Matrix<double, 6, 1> motion = Eigen::Matrix<double, 6, 1>::Zero();  // unit (r ω, v), model frame
  int observed_points = 0;            // accepted points used
  int model_rank = 0;                 // motions the model sees (6 minus symmetries)
  // Generalised eigenvectors (seen motions) whose λ (each after removing the
  // m most informative points along it) is below min_eigenvalue; the
  // pipeline may discharge a single one by a finite check
  // (global_uniqueness.hpp, CheckWeakMotion).
  int weak_motions = 0;
  double second_eigenvalue = 0.0;     // the second smallest λ (same robust rule); 0 if rank < 2
};

// The model side (H_model, in the scaled twist coordinates above): depends on
// the object only.
Eigen::Matrix<double, 6, 6> ModelInformationMatrix(const ObjectModel& object);

// `nearest_model_point` holds, for every input point, the index of its nearest
// B̂ point under T̂ (ObjectModel::NearestInPosedModel); only points with
// accepted[j] != 0 are used; the `max_outliers` accepted points that
// contribute most along the weakest motion are removed before the final ratio.
LocalNonDegeneracy CheckLocalNonDegeneracy(const ObjectModel& object, const Eigen::VectorXi& nearest_model_point,
                                           const std::vector<char>& accepted, int max_outliers,
                                           const LocalNonDegeneracyOptions& options);

}  // namespace c3po
