// Parameter sets of a Turing screen: see screen_sampling.hpp.
#include "sweep/screen_sampling.hpp"

#include "core/hash_rng.hpp"

namespace morphogen::sweep {

namespace {

// rng::stream_id("screen_" + name), without building the string.
std::uint64_t stream_of(const std::string& name) {
  std::uint64_t h = rng::stream_id("screen_");
  for (char c : name) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  return h;
}

} // namespace

long long permute(long long i, long long n, std::uint64_t seed, std::uint64_t stream) {
  int bits = 2;
  while (bits < 62 && (1LL << bits) < n)
    ++bits;
  const int half = (bits + 1) / 2;
  const std::uint64_t mask = (std::uint64_t{1} << half) - 1;
  std::uint64_t x = static_cast<std::uint64_t>(i);
  do { // cycle walking: the domain is at most 4 n, so about 4 tries at worst on average
    std::uint64_t left = x >> half, right = x & mask;
    for (std::uint64_t round = 0; round < 4; ++round) {
      const std::uint64_t f = rng::hash(seed, stream + round, right) & mask;
      const std::uint64_t next = left ^ f;
      left = right;
      right = next;
    }
    x = (left << half) | right;
  } while (x >= static_cast<std::uint64_t>(n));
  return static_cast<long long>(x);
}

long long ScreenSampler::total() const {
  if (sampling != Sampling::Grid) return count;
  long long n = 1;
  for (long long p : points)
    n *= p;
  return n;
}

void ScreenSampler::values(long long i, double* out) const {
  const size_t na = names.size();
  for (size_t j = 0; j < na; ++j) {
    const std::uint64_t stream = stream_of(names[j]);
    const std::uint64_t u = static_cast<std::uint64_t>(i);
    if (sampling == Sampling::Grid) {
      const long long n = points[j], m = i % n;
      i /= n;
      out[j] = n == 1 ? lo[j]
               : m == n - 1
                   ? hi[j]
                   : lo[j] + (hi[j] - lo[j]) * static_cast<double>(m) / static_cast<double>(n - 1);
    } else if (sampling == Sampling::Random) {
      out[j] = lo[j] + (hi[j] - lo[j]) * rng::uniform(seed, stream, u);
    } else {
      const double stratum = static_cast<double>(permute(i, count, seed, stream));
      const double jitter = rng::uniform(seed, rng::mix64(stream ^ 0x5851f42d4c957f2dULL), u);
      out[j] = lo[j] + (hi[j] - lo[j]) * (stratum + jitter) / static_cast<double>(count);
    }
  }
}

} // namespace morphogen::sweep
