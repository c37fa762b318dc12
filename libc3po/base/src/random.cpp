#include "c3po/base/random.hpp"

#include <cmath>

namespace c3po {
namespace {

std::uint64_t SplitMix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

std::uint64_t RotateLeft(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

}  // namespace

Rng::Rng(std::uint64_t seed) {
  std::uint64_t state = seed;
  for (auto& word : s_) word = SplitMix64(state);
}

Rng Rng::ForItem(std::uint64_t seed, std::uint64_t index) {
  std::uint64_t state = seed ^ 0x5851F42D4C957F2DULL;
  const std::uint64_t mixed = SplitMix64(state) ^ (index * 0xD1B54A32D192ED03ULL);
  return Rng(mixed);
}

// xoshiro256** (Blackman and Vigna).
std::uint64_t Rng::Next() {
  const std::uint64_t result = RotateLeft(s_[1] * 5, 7) * 9;
  const std::uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = RotateLeft(s_[3], 45);
  return result;
}

double Rng::Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }

double Rng::Uniform(double low, double high) { return low + (high - low) * Uniform(); }

int Rng::UniformInt(int count) {
  if (count <= 0) return 0;
  // Lemire's multiply-shift; the bias for count << 2^32 is negligible.
  return static_cast<int>(((Next() >> 32) * static_cast<std::uint64_t>(count)) >> 32);
}

double Rng::Normal() {
  double u1 = Uniform();
  while (u1 <= 0.0) u1 = Uniform();
  const double u2 = Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

Eigen::Vector3d Rng::UnitVector() {
  const double z = Uniform(-1.0, 1.0);
  const double phi = Uniform(0.0, 2.0 * M_PI);
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Uniform random unit quaternion (Shoemake, Graphics Gems III).
Eigen::Matrix3d Rng::Rotation() {
  const double u1 = Uniform(), u2 = Uniform(), u3 = Uniform();
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const Eigen::Quaterniond q(b * std::cos(2 * M_PI * u3), a * std::sin(2 * M_PI * u2),
                             a * std::cos(2 * M_PI * u2), b * std::sin(2 * M_PI * u3));
  return q.normalized().toRotationMatrix();
}

Eigen::Matrix3d Rng::RotationUpTo(double max_angle) {
  const Eigen::Vector3d axis = UnitVector();
  const double angle = Uniform(0.0, max_angle);
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

}  // namespace c3po
