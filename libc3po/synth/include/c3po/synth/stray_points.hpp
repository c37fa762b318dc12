#pragma once
// Stray points for measuring outlier-robust certificates (issue 16): what a
// real depth segment adds to the object's points.
#include "c3po/base/random.hpp"
#include "c3po/base/types.hpp"

namespace c3po {

// Returns `cloud` with `count` stray points inserted at random positions:
// half background points uniform in the cloud's bounding box grown by
// diameter/2 on every side, half flying pixels (a random cloud point pushed
// away from the camera at the origin along its ray by U[0.02, 0.5] * diameter).
// `is_stray` (optional) receives one flag per output point.
PointSet AddStrayPoints(const PointSet& cloud, int count, double diameter, Rng& rng,
                        std::vector<char>* is_stray = nullptr);

}  // namespace c3po
