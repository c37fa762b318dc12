#include "c3po/eval/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "c3po/base/error.hpp"

namespace c3po {

const char* ToString(AddSVariant v) {
  return v == AddSVariant::kOneSided ? "one-sided" : "symmetric";
}

AddSVariant ParseAddSVariant(const std::string& text) {
  if (text == "one-sided") return AddSVariant::kOneSided;
  if (text == "symmetric") return AddSVariant::kSymmetric;
  throw InputError("--adds", "'" + text + "' must be one-sided or symmetric");
}

namespace {

// mean_{b in B̂} min_{b' in B̂} ||A b - B b'|| = mean ||B^{-1} A b - nearest||.
double MeanPosedDistance(const PointTree& model_sample, const Pose& from, const Pose& to) {
  const PointSet moved = (to.Inverse() * from) * model_sample.points();
  Eigen::VectorXd squared;
  model_sample.NearestBatch(moved, nullptr, &squared);
  return squared.size() ? squared.cwiseSqrt().mean() : 0.0;
}

}  // namespace

double AddS(const PointTree& model_sample, const Pose& truth, const Pose& estimate,
            AddSVariant variant) {
  const double forward = MeanPosedDistance(model_sample, truth, estimate);
  if (variant == AddSVariant::kOneSided) return forward;
  return forward + MeanPosedDistance(model_sample, estimate, truth);
}

double ThresholdScore(const std::vector<double>& errors, double threshold) {
  if (errors.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto below = std::count_if(errors.begin(), errors.end(),
                                   [threshold](double e) { return e < threshold; });
  return 100.0 * static_cast<double>(below) / static_cast<double>(errors.size());
}

// AUC = (100 / m) ∫_0^m F(t) dt with F(t) = fraction of errors below t; each
// error contributes ∫_0^m [e < t] dt = max(0, m - e) exactly.
double AddSAuc(const std::vector<double>& errors, double max_threshold) {
  if (errors.empty()) return std::numeric_limits<double>::quiet_NaN();
  if (!(max_threshold > 0)) throw std::invalid_argument("AddSAuc: max_threshold must be > 0");
  double sum = 0.0;
  for (double e : errors) sum += std::isfinite(e) ? std::max(0.0, max_threshold - e) : 0.0;
  return 100.0 * sum / (max_threshold * static_cast<double>(errors.size()));
}

double RotationError(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& R2) {
  // Equal to arccos((tr(R1^T R2) - 1) / 2), computed with atan2 so that small
  // angles keep their precision.
  const Eigen::Matrix3d relative = R1.transpose() * R2;
  const Eigen::Vector3d axis_sine(relative(2, 1) - relative(1, 2), relative(0, 2) - relative(2, 0),
                                  relative(1, 0) - relative(0, 1));
  return std::atan2(0.5 * axis_sine.norm(), 0.5 * (relative.trace() - 1.0));
}

double TranslationError(const Eigen::Vector3d& t1, const Eigen::Vector3d& t2) {
  return (t1 - t2).norm();
}

double Median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + mid));
}

}  // namespace c3po
