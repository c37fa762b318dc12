// The bundled objects (annotations/*.obj, *.json): procedural meshes with
// named keypoints on their vertices, indicator sets and certificate thresholds.
// Model frame of every object: metres, z up, the object stands on z = 0,
// x points to its front (handle of the mug, chuck of the drill, front of the
// chair), y to its left.
#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "c3po/io/mesh_io.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/object/procedural.hpp"

namespace c3po {
namespace {

constexpr double kPi = 3.14159265358979323846;

double Degrees(double degrees) { return degrees * kPi / 180.0; }

// Accumulates closed parts and keypoints chosen among the parts' vertices.
class ObjectBuilder {
 public:
  explicit ObjectBuilder(std::string name) { object_.spec.name = std::move(name); }

  // Adds a closed part (rounded to float precision); returns its index.
  int AddPart(const Mesh& part) {
    const ClosednessReport report = CheckClosed(RoundToFloat(part));
    if (!report.closed()) throw std::logic_error(object_.spec.name + ": a part is not closed");
    object_.part_begin.push_back(static_cast<int>(object_.mesh.triangles.cols()));
    part_vertex_begin_.push_back(static_cast<int>(object_.mesh.vertices.cols()));
    AppendMesh(&object_.mesh, RoundToFloat(part));
    return static_cast<int>(object_.part_begin.size()) - 1;
  }

  // Keypoint = the vertex of `part` nearest to `target` (so it lies exactly on
  // the surface); returns its index.
  int AddKeypoint(const std::string& name, int part, const Eigen::Vector3d& target) {
    const int begin = part_vertex_begin_.at(static_cast<std::size_t>(part));
    const int end = part + 1 < static_cast<int>(part_vertex_begin_.size())
                        ? part_vertex_begin_[static_cast<std::size_t>(part) + 1]
                        : static_cast<int>(object_.mesh.vertices.cols());
    int best = begin;
    double best_distance = std::numeric_limits<double>::infinity();
    for (int v = begin; v < end; ++v) {
      const double distance = (object_.mesh.vertices.col(v) - target).squaredNorm();
      if (distance < best_distance) {
        best_distance = distance;
        best = v;
      }
    }
    keypoints_.push_back(object_.mesh.vertices.col(best));
    object_.spec.keypoint_names.push_back(name);
    return static_cast<int>(keypoints_.size()) - 1;
  }

  void AddIndicatorSet(std::vector<int> set) {
    object_.spec.indicator_sets.push_back(std::move(set));
  }

  // Certificate thresholds as fractions of the diameter d, rounded to 1 mm:
  // eps_oc ~ 4 % d (input points near the posed model: sample spacing of B̂
  // plus 1 mm depth noise), delta_nd ~ 3 % d (a keypoint counts as seen when an
  // input point is this close: above the spacing of a 1000-point cloud).
  BundledObject Finish(double eps_fraction = 0.04, double delta_fraction = 0.03) {
    object_.spec.keypoints.resize(3, static_cast<Eigen::Index>(keypoints_.size()));
    for (std::size_t i = 0; i < keypoints_.size(); ++i) {
      object_.spec.keypoints.col(static_cast<Eigen::Index>(i)) = keypoints_[i];
    }
    const double d = object_.mesh.Diameter();
    const auto round_mm = [](double x) { return std::max(0.001, std::round(x * 1000.0) / 1000.0); };
    object_.spec.eps_oc = round_mm(eps_fraction * d);
    object_.spec.delta_nd = round_mm(delta_fraction * d);
    object_.spec.units = "m";
    return object_;
  }

 private:
  BundledObject object_;
  std::vector<int> part_vertex_begin_;
  std::vector<Eigen::Vector3d> keypoints_;
};

// A profile along z between z0 and z1 at radius r, with a point every `step`.
void AppendWall(double r, double z0, double z1, double step, std::vector<Eigen::Vector2d>* out) {
  const int n = std::max(1, static_cast<int>(std::ceil(std::abs(z1 - z0) / step)));
  for (int i = 0; i <= n; ++i) out->emplace_back(r, z0 + (z1 - z0) * i / n);
}

// Rotation taking +z to +x (a revolution about z becomes one about x).
Pose AlongX(double y, double z) {
  Pose pose;
  pose.R = Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  pose.t = Eigen::Vector3d(0.0, y, z);
  return pose;
}

// Mug: a cup with 5 mm walls (a closed surface of revolution: outer wall, rim,
// inner wall, inner bottom) and a torus-segment handle on +x whose ends sit
// inside the wall. The body is symmetric about z: only the handle fixes the
// rotation, so each handle keypoint is an indicator set (the paper's choice).
BundledObject MakeMug() {
  constexpr double kRadius = 0.042, kHeight = 0.095, kWall = 0.005, kBase = 0.007;
  ObjectBuilder builder("mug");
  std::vector<Eigen::Vector2d> profile{{0.0, 0.0}};
  AppendWall(kRadius, 0.0, kHeight, 0.01, &profile);
  AppendWall(kRadius - kWall, kHeight, kBase, 0.01, &profile);
  profile.emplace_back(0.0, kBase);
  const int body = builder.AddPart(MakeRevolution(profile, 64));

  // Arc from -102 to +102 degrees in 6-degree steps; its ends lie 2.5 mm inside
  // the outer wall: cx + R cos(102 deg) = kRadius - 2.5 mm.
  constexpr double kArc = 0.032, kTube = 0.0065, kCentreZ = 0.052;
  const double end_angle = Degrees(102.0);
  const double centre_x = kRadius - 0.0025 - kArc * std::cos(end_angle);
  const Eigen::Vector3d arc_centre(centre_x, 0.0, kCentreZ);
  const int handle =
      builder.AddPart(MakeArcTube(arc_centre, kArc, -end_angle, end_angle, kTube, 34, 16));

  const char* sides[4] = {"handle_side", "left", "back", "right"};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d dir(std::cos(k * kPi / 2.0), std::sin(k * kPi / 2.0), 0.0);
    builder.AddKeypoint(std::string("rim_") + sides[k], body,
                        kRadius * dir + Eigen::Vector3d(0, 0, kHeight));
  }
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d dir(std::cos(k * kPi / 2.0), std::sin(k * kPi / 2.0), 0.0);
    builder.AddKeypoint(std::string("base_") + sides[k], body, kRadius * dir);
  }
  const auto handle_outer = [&](double degrees) {
    const Eigen::Vector3d radial(std::cos(Degrees(degrees)), 0.0, std::sin(Degrees(degrees)));
    return Eigen::Vector3d(arc_centre + (kArc + kTube) * radial);
  };
  const int top = builder.AddKeypoint("handle_top", handle, handle_outer(60.0));
  const int middle = builder.AddKeypoint("handle_middle", handle, handle_outer(0.0));
  const int bottom = builder.AddKeypoint("handle_bottom", handle, handle_outer(-60.0));
  builder.AddIndicatorSet({top});
  builder.AddIndicatorSet({middle});
  builder.AddIndicatorSet({bottom});
  return builder.Finish();
}

// Box: a cracker-box-like cuboid, 8 named corners. Indicator sets: for each
// corner its set with its 3 edge neighbours = the three faces meeting at that
// corner are seen (one face alone leaves the box ambiguous).
BundledObject MakeBox() {
  const Eigen::Vector3d size(0.16, 0.08, 0.22);
  ObjectBuilder builder("box");
  const Eigen::Vector3d lo(-size.x() / 2, -size.y() / 2, 0.0);
  const Eigen::Vector3d hi(size.x() / 2, size.y() / 2, size.z());
  const int part = builder.AddPart(MakeCuboid(lo, hi, 0.015));
  // Corner index bits: 1 = +x (front), 2 = +y (left), 4 = +z (top).
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(),
                                 (c & 4) ? hi.z() : lo.z());
    const std::string name = std::string((c & 1) ? "front" : "back") + "_" +
                             ((c & 2) ? "left" : "right") + "_" + ((c & 4) ? "top" : "bottom");
    builder.AddKeypoint(name, part, corner);
  }
  for (int c = 0; c < 8; ++c) builder.AddIndicatorSet({c, c ^ 1, c ^ 2, c ^ 4});
  return builder.Finish();
}

// Drill: battery base, grip, trigger, and one surface of revolution
// along +x for barrel, chuck and bit. The barrel-chuck-bit body is symmetric
// about the x axis; the base and the grip break the symmetry, so each base and
// grip keypoint is an indicator set (the paper uses the base keypoints of the
// YCB power drill). Overlaps are kept small (the grip enters the base by 3 mm,
// the barrel by 3-7 mm, the trigger the grip by 3 mm): few faces lie inside.
BundledObject MakeDrill() {
  ObjectBuilder builder("drill");
  const int base = builder.AddPart(
      MakeCuboid({-0.085, -0.042, 0.0}, {0.035, 0.042, 0.055}, 0.015));
  const int grip = builder.AddPart(MakeCuboid({-0.055, -0.016, 0.052}, {-0.015, 0.016, 0.168}, 0.015));
  const int trigger =
      builder.AddPart(MakeCuboid({-0.018, -0.008, 0.128}, {0.002, 0.008, 0.165}, 0.015));
  constexpr double kAxisZ = 0.195;
  // Profile in (radius, x) before AlongX maps the axis to +x: rounded back,
  // barrel wall, chuck, bit with a conical tip.
  std::vector<Eigen::Vector2d> profile{{0.0, -0.100}, {0.020, -0.100}, {0.030, -0.095}};
  AppendWall(0.034, -0.085, 0.050, 0.015, &profile);
  profile.insert(profile.end(), {{0.024, 0.050}, {0.024, 0.085}, {0.018, 0.105},
                                 {0.004, 0.105}, {0.004, 0.150}, {0.0, 0.165}});
  const int body = builder.AddPart(TransformMesh(MakeRevolution(profile, 48), AlongX(0, kAxisZ)));

  builder.AddKeypoint("bit_tip", body, {0.165, 0.0, kAxisZ});
  builder.AddKeypoint("chuck_front_top", body, {0.105, 0.0, kAxisZ + 0.018});
  builder.AddKeypoint("barrel_front_top", body, {0.050, 0.0, kAxisZ + 0.034});
  builder.AddKeypoint("barrel_back_top", body, {-0.085, 0.0, kAxisZ + 0.034});
  builder.AddKeypoint("barrel_back_centre", body, {-0.100, 0.0, kAxisZ});
  builder.AddKeypoint("trigger_front_bottom", trigger, {0.002, 0.0, 0.128});
  const int grip_top = builder.AddKeypoint("grip_back_top", grip, {-0.055, 0.0, 0.135});
  const int grip_low = builder.AddKeypoint("grip_back_low", grip, {-0.055, 0.0, 0.085});
  std::vector<int> base_keypoints;
  const char* names[6] = {"base_front_left_bottom", "base_front_right_bottom",
                          "base_back_left_bottom",  "base_back_right_bottom",
                          "base_front_left_top",    "base_front_right_top"};
  const Eigen::Vector3d corners[6] = {{0.035, 0.042, 0.0},  {0.035, -0.042, 0.0},
                                      {-0.085, 0.042, 0.0}, {-0.085, -0.042, 0.0},
                                      {0.035, 0.042, 0.055}, {0.035, -0.042, 0.055}};
  for (int k = 0; k < 6; ++k) base_keypoints.push_back(builder.AddKeypoint(names[k], base, corners[k]));
  for (int k : base_keypoints) builder.AddIndicatorSet({k});
  builder.AddIndicatorSet({grip_top});
  builder.AddIndicatorSet({grip_low});
  return builder.Finish();
}

// Chair: seat, backrest behind the seat, four legs entering the seat. Seen
// from below (seat and legs only) it is ambiguous under a half turn; the
// backrest fixes the pose, so its keypoints are the indicator sets.
BundledObject MakeChair() {
  ObjectBuilder builder("chair");
  const int seat = builder.AddPart(MakeCuboid({-0.22, -0.22, 0.42}, {0.22, 0.22, 0.46}, 0.03));
  // Backrest and legs enter the seat by 5 mm only (few faces inside the solid).
  const int back = builder.AddPart(MakeCuboid({-0.25, -0.19, 0.455}, {-0.215, 0.19, 0.92}, 0.03));
  std::vector<int> legs;
  for (int k = 0; k < 4; ++k) {
    const double sx = (k & 1) ? 1.0 : -1.0;
    const double sy = (k & 2) ? 1.0 : -1.0;
    const Eigen::Vector3d lo(sx > 0 ? 0.175 : -0.21, sy > 0 ? 0.175 : -0.21, 0.0);
    legs.push_back(builder.AddPart(MakeCuboid(lo, lo + Eigen::Vector3d(0.035, 0.035, 0.425), 0.03)));
  }
  builder.AddKeypoint("seat_front_left", seat, {0.22, 0.22, 0.46});
  builder.AddKeypoint("seat_front_right", seat, {0.22, -0.22, 0.46});
  builder.AddKeypoint("seat_back_left", seat, {-0.22, 0.22, 0.46});
  builder.AddKeypoint("seat_back_right", seat, {-0.22, -0.22, 0.46});
  builder.AddKeypoint("seat_front_middle", seat, {0.22, 0.0, 0.44});
  const int top_left = builder.AddKeypoint("back_top_left", back, {-0.215, 0.19, 0.92});
  const int top_right = builder.AddKeypoint("back_top_right", back, {-0.215, -0.19, 0.92});
  const int rear = builder.AddKeypoint("back_rear_middle", back, {-0.25, 0.0, 0.68});
  const char* feet[4] = {"foot_back_right", "foot_front_right", "foot_back_left", "foot_front_left"};
  for (int k = 0; k < 4; ++k) {
    const double x = (k & 1) ? 0.21 : -0.21;
    const double y = (k & 2) ? 0.21 : -0.21;
    builder.AddKeypoint(feet[k], legs[static_cast<std::size_t>(k)], {x, y, 0.0});
  }
  builder.AddIndicatorSet({top_left});
  builder.AddIndicatorSet({top_right});
  builder.AddIndicatorSet({rear});
  return builder.Finish();
}

}  // namespace

std::vector<std::string> BundledObjectNames() { return {"mug", "box", "drill", "chair"}; }

BundledObject MakeBundledObject(const std::string& name) {
  if (name == "mug") return MakeMug();
  if (name == "box") return MakeBox();
  if (name == "drill") return MakeDrill();
  if (name == "chair") return MakeChair();
  throw std::invalid_argument("MakeBundledObject: unknown object '" + name + "'");
}

void WriteBundledObject(const BundledObject& object, const std::string& dir) {
  const std::filesystem::path folder = std::filesystem::absolute(dir);
  const std::string mesh_path = (folder / (object.spec.name + ".obj")).string();
  WriteObj(object.mesh, mesh_path);
  ObjectSpec spec = object.spec;
  spec.mesh_path = mesh_path;
  WriteObjectSpec(spec, (folder / (object.spec.name + ".json")).string());
}

}  // namespace c3po
