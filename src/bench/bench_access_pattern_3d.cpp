// The 3-D patterns of the access-pattern section (bench_access_pattern.hpp): the 7-point in-place
// sweep of the explicit fast path without its arithmetic, in blocks of y rows with the new rows
// through a ring (committed a block's plane later) and each block's last rows saved for the next
// block, as ExplicitIntegrator::sweep does, against the same sweep out of place.
#include "bench/bench_access_pattern.hpp"

#include "core/prefetch.hpp"

#include <petscsys.h>

#include <algorithm>
#include <cstring>
#include <vector>

namespace morphogen {

namespace {

constexpr double kW = 0.1;

// Two species of nz owned planes (plus a ghost plane each side) of ny owned rows (plus a ghost
// row each side) of nx cells (plus a ghost cell each side).
struct Box3 {
  long nx, ny, nz, gx, gxy;
  std::vector<double> u[2];
  Box3(long x, long y, long z) : nx(x), ny(y), nz(z), gx(x + 2), gxy((x + 2) * (y + 2)) {
    for (int s = 0; s < 2; ++s) {
      u[s].resize(static_cast<size_t>(gxy * (z + 2)));
      for (size_t c = 0; c < u[s].size(); ++c)
        u[s][c] = 1.0 + s + 1e-3 * static_cast<double>((c * (5 + 2 * s)) % 17);
    }
  }
  // Owned cell (0, j, k) of species s (j, k may be -1 or n: ghosts).
  double* at(int s, long j, long k) { return u[s].data() + (k + 1) * gxy + (j + 1) * gx + 1; }
};

// One row of both species (one loop, as the explicit tap kernel): out_s = c_s + kW (sum of the 6
// neighbours - 6 c_s), the row below (j - 1) read from below_s (the saved edge row at a block's
// first row).
void row7(const double* __restrict__ a, const double* __restrict__ b,
          const double* __restrict__ a_below, const double* __restrict__ b_below, long gx, long gxy,
          long n, double* __restrict__ oa, double* __restrict__ ob) {
#pragma GCC ivdep
  for (long i = 0; i < n; ++i) {
    oa[i] = a[i] + kW * (a[i - 1] + a[i + 1] + a_below[i] + a[i + gx] + a[i - gxy] + a[i + gxy] -
                         6 * a[i]);
    ob[i] = b[i] + kW * (b[i - 1] + b[i + 1] + b_below[i] + b[i + gx] + b[i - gxy] + b[i + gxy] -
                         6 * b[i]);
  }
}

// One row of both species reading the 9 rows that a 19- or 27-point stencil reads (rows[s][q]:
// (j + dy, k + dz) for dz, dy in -1, 0, 1, q = 3 (dz + 1) + dy + 1; rows[s][4] the row itself),
// each at cell i, and the row's own x neighbours: the rows a box stencil touches, without its
// taps.
void row9(const double* const (&rows)[2][9], long n, double* __restrict__ oa,
          double* __restrict__ ob) {
  const double* __restrict__ a[9];
  const double* __restrict__ b[9];
  for (int q = 0; q < 9; ++q) {
    a[q] = rows[0][q];
    b[q] = rows[1][q];
  }
#pragma GCC ivdep
  for (long i = 0; i < n; ++i) {
    oa[i] = a[4][i] + kW * (a[0][i] + a[1][i] + a[2][i] + a[3][i] + a[5][i] + a[6][i] + a[7][i] +
                            a[8][i] + a[4][i - 1] + a[4][i + 1] - 10 * a[4][i]);
    ob[i] = b[4][i] + kW * (b[0][i] + b[1][i] + b[2][i] + b[3][i] + b[5][i] + b[6][i] + b[7][i] +
                            b[8][i] + b[4][i - 1] + b[4][i + 1] - 10 * b[4][i]);
  }
}

// Rows per y block: three planes of both species in about 256 KiB (ExplicitIntegrator's
// block_rows), or all rows.
long block_rows(const Box3& b, bool blocked) {
  if (!blocked) return b.ny;
  return std::min(b.ny, std::max<long>(4, 256 * 1024 / (3 * 2 * b.gx * 8) - 2));
}

struct Ring3 {
  std::vector<double> ring, edge[2];
};

// Box = false: the 7-point taps (row7); true: the 9 rows of the box stencils (row9).
template <bool Box> void sweep_in_place(Box3& b, Ring3& r, bool blocked, bool prefetch) {
  const long bh = block_rows(b, blocked), depth = bh + 2, n = b.nx;
  r.ring.resize(static_cast<size_t>(2 * depth * n));
  for (auto& e : r.edge)
    e.resize(static_cast<size_t>(2 * b.nz * n));
  auto slot = [&](int s, long t) { return r.ring.data() + (s * depth + t % depth) * n; };
  auto edge = [&](int q, int s, long k) { return r.edge[q].data() + (s * b.nz + k) * n; };
  for (long jb = 0; jb < b.ny; jb += bh) {
    const long jend = std::min(jb + bh, b.ny), h = jend - jb, lag = h + 1;
    auto commit = [&](long t) {
      const long k = t / h, j = jb + t % h;
      for (int s = 0; s < 2; ++s) {
        if (jend < b.ny && j == jend - 1) std::memcpy(edge(1, s, k), b.at(s, j, k), n * 8);
        std::memcpy(b.at(s, j, k), slot(s, t), n * 8);
      }
    };
    for (long k = 0; k < b.nz; ++k)
      for (long j = jb; j < jend; ++j) {
        const long t = k * h + (j - jb);
        double *a = b.at(0, j, k), *c = b.at(1, j, k);
        // the row read first two rows after this row's leading row ((k + 1, j), box: (k + 1, j +
        // 1))
        const long lead = b.gxy + (Box ? b.gx : 0);
        const long ahead = j + 2 < jend ? lead + 2 * b.gx : lead + b.gxy + (2 - h) * b.gx;
        if (prefetch && k + 3 < b.nz) {
          prefetch_doubles(a + ahead, n);
          prefetch_doubles(c + ahead, n);
        }
        const bool edge_row = jb > 0 && j == jb;
        if constexpr (Box) {
          const double* rows[2][9];
          for (int s = 0; s < 2; ++s)
            for (int dz = -1; dz <= 1; ++dz)
              for (int dy = -1; dy <= 1; ++dy) {
                const bool saved = edge_row && dy < 0 && k + dz >= 0 && k + dz < b.nz;
                rows[s][3 * (dz + 1) + dy + 1] =
                    saved ? edge(0, s, k + dz) : b.at(s, j + dy, k + dz);
              }
          row9(rows, n, slot(0, t), slot(1, t));
        } else {
          row7(a, c, edge_row ? edge(0, 0, k) : a - b.gx, edge_row ? edge(0, 1, k) : c - b.gx, b.gx,
               b.gxy, n, slot(0, t), slot(1, t));
        }
        if (t >= lag) commit(t - lag);
      }
    for (long t = std::max<long>(0, h * b.nz - lag); t < h * b.nz; ++t)
      commit(t);
    std::swap(r.edge[0], r.edge[1]);
  }
}

template <bool Box> void sweep_out_of_place(Box3& b, Box3& o) {
  for (long k = 0; k < b.nz; ++k)
    for (long j = 0; j < b.ny; ++j) {
      const double *a = b.at(0, j, k), *c = b.at(1, j, k);
      if constexpr (Box) {
        const double* rows[2][9];
        for (int s = 0; s < 2; ++s)
          for (int q = 0; q < 9; ++q)
            rows[s][q] = b.at(s, j + q % 3 - 1, k + q / 3 - 1);
        row9(rows, b.nx, o.at(0, j, k), o.at(1, j, k));
      } else {
        row7(a, c, a - b.gx, c - b.gx, b.gx, b.gxy, b.nx, o.at(0, j, k), o.at(1, j, k));
      }
    }
}

// The blocked in-place sweeps (7-point and box rows) against the out-of-place ones on a box of
// three y blocks (4, 4 and 2 rows): identical owned values on every rank.
template <bool Box> bool blocked_matches(Box3& b, Box3& ref, Box3& o) {
  Ring3 r;
  sweep_in_place<Box>(b, r, true, true);
  sweep_out_of_place<Box>(ref, o);
  bool same = true;
  for (long k = 0; k < b.nz; ++k)
    for (long j = 0; j < b.ny; ++j)
      for (int s = 0; s < 2; ++s)
        same = same && std::memcmp(b.at(s, j, k), o.at(s, j, k), b.nx * 8) == 0;
  return same;
}

bool blocked_matches_out_of_place(MPI_Comm comm) {
  Box3 b(1024, 10, 5), ref(1024, 10, 5), o(1024, 10, 5), b9(1024, 10, 5), ref9(1024, 10, 5);
  int same = blocked_matches<false>(b, ref, o) && blocked_matches<true>(b9, ref9, o) ? 1 : 0;
  int all = 0;
  MPI_Allreduce(&same, &all, 1, MPI_INT, MPI_MIN, comm);
  return all == 1;
}

} // namespace

void bench_access_pattern_3d(MPI_Comm comm, int side, double roof) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  const long n = std::max(side, 8), nz = std::max<long>(4, n / size);
  Box3 b(n, n, nz), o(n, n, nz);
  Ring3 r;
  const double cells = static_cast<double>(n) * n * nz;
  auto report = [&](const char* name, double sec) {
    const double cups = cells * size / sec;
    PetscPrintf(comm,
                "access_pattern name=%s cells_per_rank=%ldx%ldx%ld ns_per_cell_per_rank=%.3f "
                "cell_updates_per_s=%.4e fraction=%.3f\n",
                name, n, n, nz, 1e9 * sec / cells, cups, cups / roof);
  };
  auto time = [&](auto&& f) { return slowest_best_seconds(comm, f, 5); };
  report("3d_ring_7pt_blocked", time([&] { sweep_in_place<false>(b, r, true, false); }));
  report("3d_ring_7pt_blocked_prefetch", time([&] { sweep_in_place<false>(b, r, true, true); }));
  report("3d_ring_7pt_unblocked", time([&] { sweep_in_place<false>(b, r, false, false); }));
  report("3d_out_of_place_7pt", time([&] { sweep_out_of_place<false>(b, o); }));
  report("3d_ring_9row_blocked_prefetch", time([&] { sweep_in_place<true>(b, r, true, true); }));
  PetscPrintf(comm, "access_pattern check 3d_ring_blocked_equals_out_of_place=%s\n",
              blocked_matches_out_of_place(comm) ? "yes" : "NO");
}

} // namespace morphogen
