#include "c3po/method/detector.hpp"

#include "c3po/base/parallel.hpp"

namespace c3po {

std::vector<PointSet> Detector::DetectBatch(const std::vector<PointSet>& clouds) const {
  std::vector<PointSet> keypoints(clouds.size());
  ParallelFor(0, static_cast<int>(clouds.size()),
              [&](int i) { keypoints[i] = Detect(clouds[i]); });
  return keypoints;
}

}  // namespace c3po
