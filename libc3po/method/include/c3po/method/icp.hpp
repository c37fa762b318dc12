#pragma once
// Point-to-point ICP of an object against a scene cloud (the "KeyPo + ICP"
// baseline of the evaluation, and the refinement step of the svd detector).
//
// Each iteration pairs every scene point x with its nearest model-sample point
// p in the object's model frame (a query of R^T (x - t) against the object's
// k-d tree, no per-iteration rebuild), keeps the inlier pairs, and solves
// T = argmin sum ||x - T p||^2 in closed form (paper eq. 8, RegisterPoints).
#include <limits>
#include <string>

#include "c3po/base/types.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct IcpOptions {
  int max_iterations = 30;
  // Pairs farther apart than this (object units) are ignored; inf = keep all.
  double max_correspondence_distance = std::numeric_limits<double>::infinity();
  // Converged when one update moves t by less than this (object units) and
  // rotates by less than convergence_rotation (radians).
  double convergence_translation = 1e-7;
  double convergence_rotation = 1e-7;
  // Trimmed ICP: each iteration drops this fraction of the pairs with the
  // largest distances (0 = plain ICP). In [0, 0.9].
  double trim_fraction = 0.0;
  // Throws std::invalid_argument on a value out of range.
  void Check() const;
};

struct IcpResult {
  Pose scene_from_model;     // the initial pose when nothing could be done
  int iterations = 0;        // pose updates performed
  bool converged = false;    // stopped by the convergence test
  // RMS distance of every (finite) scene point to the posed model sample, at
  // the initial and at the final pose: the evidence of the fit.
  double rms_before = 0.0;
  double rms_after = 0.0;
  int inliers = 0;           // pairs used by the last update
  int scene_points = 0;      // finite scene points considered
  // Empty unless ICP stopped on a degenerate case (fewer than 3 finite scene
  // points, too few inlier pairs, collinear pairs, non-finite initial pose).
  std::string failure;
  bool ok() const { return failure.empty(); }
};

// Refines `initial` (scene_from_model). Non-finite scene points are ignored.
// Never throws on degenerate data (see IcpResult::failure); throws
// std::invalid_argument when `options` fail Check().
IcpResult RefineIcp(const ObjectModel& model, const PointSet& scene, const Pose& initial,
                    const IcpOptions& options = {});

}  // namespace c3po
