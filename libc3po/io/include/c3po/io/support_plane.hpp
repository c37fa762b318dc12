#pragma once
// The support plane of a frame (the table the objects stand on) and the mask
// points that lie on it (issue 16). Real masks bleed onto the table around an
// object's base: on the YCB-Video frames the wood block's mask covers a strip
// of table 26 x 53 px past the block, ~4 % of its points 3-7 cm off the model
// even at the ground-truth pose (docs/camera_inputs.md). Those points are
// within the depth noise of the table's plane; dropping mask points on the
// background's dominant plane removes them, as tabletop pipelines do (PCL's
// plane segmentation before clustering).
//
// The plane is fitted to the background (valid depth pixels outside the
// object's mask), sampled on a grid of ~20 000 cells, without random
// sampling: every block of 8 x 8 cells (32 x 32 px on a 640 x 480 image)
// whose back-projected samples are flat (RMS residual <= distance / 2) gives
// a hypothesis (least-squares plane),
// the hypothesis with the most background samples within `distance` wins and
// is refitted to those inliers. A plane is accepted only when it holds at
// least `min_image_fraction` of the whole image's samples: a frame without a
// dominant plane drops nothing, and neither does one whose only background is
// another object (its face is a plane, but not one the target stands on, and
// extended it would cut through the target). Deterministic: same frame,
// same plane.
#include <optional>

#include "c3po/geometry/camera.hpp"
#include "c3po/io/segment.hpp"

namespace c3po {

struct SupportPlaneFit {
  Plane plane;                      // oriented: the camera centre is on its positive side (offset < 0)
  int image_samples = 0;            // grid cells of the whole image
  int background_samples = 0;       // of them, background pixels with depth
  int inlier_samples = 0;           // of those, within `distance` of the plane
};

// The dominant plane of the background (pixels outside `object_mask`), or
// nothing when no plane holds min_image_fraction of the image's samples.
// `distance` in metres (> 0); `object_mask` has the depth image's size.
std::optional<SupportPlaneFit> FitSupportPlane(const DepthImage& depth, const Mask& object_mask,
                                               const PinholeCamera& camera, double distance,
                                               double min_image_fraction = 0.2);

}  // namespace c3po
