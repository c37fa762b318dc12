#pragma once
// Pose-estimation metrics of the paper (Section VIII).
#include <string>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/geometry/kdtree.hpp"

namespace c3po {

enum class AddSVariant {
  kOneSided,   // mean over the GT-posed sample of the distance to the estimate-posed sample
  kSymmetric,  // one-sided + reverse direction (the paper's final tables)
};
const char* ToString(AddSVariant v);
AddSVariant ParseAddSVariant(const std::string& text);  // "one-sided" | "symmetric"

// ADD-S between the model sample posed by `truth` and by `estimate`. Uses the
// tree over the model-frame sample: the nearest estimate-posed point of T* b is
// the nearest model point of T̂^{-1} T* b.
double AddS(const PointTree& model_sample, const Pose& truth, const Pose& estimate,
            AddSVariant variant = AddSVariant::kOneSided);

// Percentage (0..100) of errors strictly below `threshold`.
double ThresholdScore(const std::vector<double>& errors, double threshold);
// Area under the accuracy-vs-threshold curve on [0, max_threshold], in 0..100.
double AddSAuc(const std::vector<double>& errors, double max_threshold);

// Geodesic angle arccos((tr(R1^T R2) - 1) / 2), radians.
double RotationError(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& R2);
double TranslationError(const Eigen::Vector3d& t1, const Eigen::Vector3d& t2);

double Median(std::vector<double> values);   // NaN for empty input

}  // namespace c3po
