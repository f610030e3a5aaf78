// The parameter sets of a Turing screen (`morphogen screen`, sweep/screen_main.hpp): set i of
// 0..total()-1 as a pure function of i, so any rank computes any set and the sets do not depend
// on the rank count.
//
//   grid    points[j] values per axis j, lo_j + (hi_j - lo_j) * m / (points[j] - 1) (m = 0 ..
//           points[j] - 1; one point: lo_j); the FIRST axis varies fastest (as in `morphogen
//           sweep`): i = m_0 + points[0] * (m_1 + points[1] * (m_2 + ...)).
//   random  total sets, v_j = lo_j + (hi_j - lo_j) * U(seed, stream_j, i), U uniform in [0, 1)
//           from core/hash_rng.hpp, stream_j = stream_id("screen_" + name_j).
//   lhs     Latin hypercube of `total` sets: on axis j set i lies in stratum pi_j(i) of total
//           equal strata, v_j = lo_j + (hi_j - lo_j) * (pi_j(i) + U) / total, where pi_j is a
//           pseudo-random permutation of 0..total-1 (a 4-round Feistel network on the next even
//           power of two, cycle-walked into range, keyed by seed and stream_j): every stratum
//           of every axis holds exactly one set.
// Pure: no MPI, PETSc or allocation per set.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace morphogen::sweep {

enum class Sampling { Grid, Random, Lhs };

struct ScreenSampler {
  Sampling sampling = Sampling::Grid;
  std::vector<std::string> names; // the varied quantities (their streams)
  std::vector<double> lo, hi;
  std::vector<long long> points; // grid: per axis
  long long count = 0;           // random, lhs: the number of sets
  std::uint64_t seed = 1;

  long long total() const; // the number of sets
  // The values of set i (0 <= i < total()), one per axis, into out.
  void values(long long i, double* out) const;
};

// pi(i) of the Feistel permutation of 0..n-1 keyed by (seed, stream) (exposed for the tests).
long long permute(long long i, long long n, std::uint64_t seed, std::uint64_t stream);

} // namespace morphogen::sweep
