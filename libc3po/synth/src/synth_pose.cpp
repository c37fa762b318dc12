// Pose samplers of the synthetic data (synth.hpp: hard, easy, paper).
#include <cmath>
#include <string>

#include "c3po/base/error.hpp"
#include "c3po/synth/synth.hpp"

namespace c3po {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Uniform in [low, high], or the midpoint of the image when the range is empty.
double UniformOrMiddle(Rng& rng, double low, double high, double middle) {
  const double u = rng.Uniform();   // always drawn: keeps the stream layout fixed
  return low <= high ? low + (high - low) * u : middle;
}

}  // namespace

const char* ToString(CloudKind kind) { return kind == CloudKind::kSim ? "sim" : "depth"; }

const char* ToString(PoseMode mode) {
  switch (mode) {
    case PoseMode::kEasy: return "easy";
    case PoseMode::kHard: return "hard";
    case PoseMode::kPaper: return "paper";
  }
  return "hard";
}

CloudKind ParseCloudKind(const std::string& text) {
  if (text == "sim") return CloudKind::kSim;
  if (text == "depth") return CloudKind::kDepth;
  throw InputError("--kind: expected sim or depth, got '" + text + "'");
}

PoseMode ParsePoseMode(const std::string& text) {
  if (text == "easy") return PoseMode::kEasy;
  if (text == "hard") return PoseMode::kHard;
  if (text == "paper") return PoseMode::kPaper;
  throw InputError("--pose: expected easy, hard or paper, got '" + text + "'");
}

void PoseSamplerOptions::Check() const {
  const bool use_default = distance_min == 0.0 && distance_max == 0.0;
  if (!use_default && !(distance_min > 0.0 && distance_min <= distance_max &&
                        std::isfinite(distance_max))) {
    throw InputError("--distance: expected 0 < A <= B (metres, depth of the object centre)");
  }
  if (!(easy_max_angle >= 0.0 && easy_max_angle <= kPi)) {
    throw InputError("easy pose: the maximum angle must be in [0, pi]");
  }
  if (!(std::abs(reference_elevation) < kPi / 2.0) || !std::isfinite(reference_azimuth)) {
    throw InputError("easy pose: the reference elevation must be in (-90, 90) degrees");
  }
}

std::pair<double, double> DefaultDistanceRange(double diameter, const CameraIntrinsics& camera) {
  const double d0 = camera.fy * diameter / (0.4 * camera.height);
  return {0.5 * d0, 1.5 * d0};
}

Eigen::Matrix3d ReferenceRotation(const PoseSamplerOptions& options) {
  const double az = options.reference_azimuth;
  const double el = options.reference_elevation;
  // Direction from the object to the camera, model frame.
  const Eigen::Vector3d to_camera(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                  std::sin(el));
  const Eigen::Vector3d forward = -to_camera;   // camera z
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d down = -(up - up.dot(forward) * forward).normalized();   // camera y
  const Eigen::Vector3d right = down.cross(forward);                            // camera x
  Eigen::Matrix3d camera_from_model;
  camera_from_model.row(0) = right.transpose();
  camera_from_model.row(1) = down.transpose();
  camera_from_model.row(2) = forward.transpose();
  return camera_from_model;
}

Pose SamplePose(const PoseSamplerOptions& options, const CameraIntrinsics& camera,
                std::pair<double, double> distance, const Eigen::Vector3d& model_centre,
                double diameter, CloudKind kind, Rng& rng) {
  Pose pose;
  pose.R = options.mode == PoseMode::kEasy
               ? Eigen::Matrix3d(rng.RotationUpTo(options.easy_max_angle) *
                                 ReferenceRotation(options))
               : rng.Rotation();
  Eigen::Vector3d centre;
  if (options.mode == PoseMode::kPaper) {
    centre = Eigen::Vector3d(rng.Uniform(), rng.Uniform(), rng.Uniform());
    if (kind == CloudKind::kDepth) centre += Eigen::Vector3d(-0.5, -0.5, distance.second);
  } else {
    const double z = distance.first + (distance.second - distance.first) * rng.Uniform();
    // Keep the projected bounding sphere (radius d/2) inside the image.
    const double ru = camera.fx * 0.5 * diameter / z;
    const double rv = camera.fy * 0.5 * diameter / z;
    const double u = UniformOrMiddle(rng, ru - 0.5, camera.width - 0.5 - ru,
                                     0.5 * (camera.width - 1));
    const double v = UniformOrMiddle(rng, rv - 0.5, camera.height - 0.5 - rv,
                                     0.5 * (camera.height - 1));
    centre = z * camera.Ray(u, v);
  }
  pose.t = centre - pose.R * model_centre;
  return pose;
}

}  // namespace c3po
