// Counter-based random numbers: a pure function of (seed, stream, global cell index).
//
// Every random field value is u = hash(seed, fnv1a(field name), global index), so the initial
// state is bitwise identical on 1, 2 or 64 ranks (no per-rank generator state). The mixer is
// SplitMix64's finaliser applied to a Weyl-sequence combination of the three keys; uniform
// deviates take the top 53 bits, Gaussian deviates use Box-Muller on two independent streams.
#pragma once

#include <cmath>
#include <cstdint>
#include <string_view>

namespace morphogen::rng {

constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// FNV-1a hash of a name: turns a field name into a stream id.
constexpr std::uint64_t stream_id(std::string_view name) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (char c : name) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  return h;
}

constexpr std::uint64_t hash(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  std::uint64_t z = mix64(seed + 0x9e3779b97f4a7c15ULL);
  z = mix64(z ^ (stream + 0x632be59bd9b4e019ULL));
  return mix64(z ^ (index * 0x9e3779b97f4a7c15ULL + 0x2545f4914f6cdd1dULL));
}

// Uniform deviate in [0, 1).
constexpr double uniform(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  return static_cast<double>(hash(seed, stream, index) >> 11) * 0x1.0p-53;
}

// Standard normal deviate (Box-Muller on two decorrelated streams of the same cell).
inline double gaussian(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  const double u1 = 1.0 - uniform(seed, stream, index); // (0, 1]
  const double u2 = uniform(seed, mix64(stream ^ 0xd1b54a32d192ed03ULL), index);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

} // namespace morphogen::rng
