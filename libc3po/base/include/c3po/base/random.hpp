#pragma once
// Deterministic, platform-independent random numbers (xoshiro256**, seeded by
// splitmix64). std:: distributions are implementation-defined, so we do not use
// them: the same seed gives the same data everywhere.
#include <cstdint>

#include "c3po/base/types.hpp"

namespace c3po {

class Rng {
 public:
  explicit Rng(std::uint64_t seed);
  // Independent stream for item `index` of a run seeded with `seed`; lets
  // parallel loops stay deterministic regardless of scheduling.
  static Rng ForItem(std::uint64_t seed, std::uint64_t index);

  std::uint64_t Next();
  double Uniform();                       // [0, 1)
  double Uniform(double low, double high);
  int UniformInt(int count);              // [0, count)
  double Normal();                        // standard normal (Box-Muller)
  Eigen::Vector3d UnitVector();           // uniform on the sphere
  Eigen::Matrix3d Rotation();             // uniform on SO(3) (Shoemake quaternion)
  // Rotation by an angle uniform in [0, max_angle] about a uniform random axis.
  Eigen::Matrix3d RotationUpTo(double max_angle);

 private:
  std::uint64_t s_[4];
};

}  // namespace c3po
