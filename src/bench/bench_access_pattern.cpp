#include "bench/bench_access_pattern.hpp"

#include "bench/bench_stream_copy.hpp"
#include "core/prefetch.hpp"

#include <petscsys.h>

#include <algorithm>
#include <cstring>
#include <vector>

namespace morphogen {

namespace {

constexpr long kRow = 4096, kGhosted = kRow + 2;
constexpr double kW = 0.1;

enum class Taps { Point, X, FivePoint };

// One row of both species: out_s(i) = u(i) + kW (taps - n u(i)); rows at stride kGhosted.
template <Taps T>
void row_update(const double* __restrict__ a, const double* __restrict__ b, double* __restrict__ oa,
                double* __restrict__ ob) {
#pragma GCC ivdep
  for (long i = 0; i < kRow; ++i) {
    if constexpr (T == Taps::Point) {
      oa[i] = a[i] + kW * a[i];
      ob[i] = b[i] + kW * b[i];
    } else if constexpr (T == Taps::X) {
      oa[i] = a[i] + kW * (a[i - 1] + a[i + 1] - 2 * a[i]);
      ob[i] = b[i] + kW * (b[i - 1] + b[i + 1] - 2 * b[i]);
    } else {
      oa[i] = a[i] + kW * (a[i - 1] + a[i + 1] + a[i - kGhosted] + a[i + kGhosted] - 4 * a[i]);
      ob[i] = b[i] + kW * (b[i - 1] + b[i + 1] + b[i - kGhosted] + b[i + kGhosted] - 4 * b[i]);
    }
  }
}

struct State {
  std::vector<double> a, b;
  State(long rows, double a0, double b0) : a(rows * kGhosted, a0), b(rows * kGhosted, b0) {
    for (long j = 0; j < rows; ++j) // a gentle profile (no constant rows)
      for (long i = 0; i < kGhosted; ++i) {
        a[j * kGhosted + i] += 1e-3 * static_cast<double>((i * 7 + j * 3) % 11);
        b[j * kGhosted + i] -= 1e-3 * static_cast<double>((i * 5 + j) % 13);
      }
  }
  double* row(std::vector<double>& v, long j) { return v.data() + j * kGhosted + 1; }
};

// Interior rows 1 .. rows - 2 in place. Lag 0: the new row goes back at once (taps of its own row
// only); lag 1: row j - 1 goes back after row j is computed (5-point taps read it).
// The ring's row back into the state: memcpy, or streaming stores (bench_stream_copy.hpp).
template <bool Stream> void commit(double* dst, const double* src) {
  if constexpr (Stream)
    stream_copy(dst, src, kRow);
  else
    std::memcpy(dst, src, kRow * sizeof(double));
}

template <Taps T, bool Prefetch, bool Stream = false>
void ring_sweep(State& s, long rows, std::vector<double>& ring) {
  constexpr long lag = T == Taps::FivePoint ? 1 : 0;
  for (long j = 1; j < rows - 1; ++j) {
    double *ra = s.row(s.a, j), *rb = s.row(s.b, j);
    if (Prefetch && j + 3 < rows) {
      prefetch_doubles(ra + 3 * kGhosted, kRow);
      prefetch_doubles(rb + 3 * kGhosted, kRow);
    }
    double* d = ring.data() + (j & 1) * 2 * kRow;
    row_update<T>(ra, rb, d, d + kRow);
    if (j - lag >= 1) {
      const double* p = ring.data() + ((j - lag) & 1) * 2 * kRow;
      commit<Stream>(s.row(s.a, j - lag), p);
      commit<Stream>(s.row(s.b, j - lag), p + kRow);
    }
  }
  if (lag == 1) {
    const double* p = ring.data() + ((rows - 2) & 1) * 2 * kRow;
    commit<Stream>(s.row(s.a, rows - 2), p);
    commit<Stream>(s.row(s.b, rows - 2), p + kRow);
  }
  if (Stream) stream_fence();
}

void in_place_pointwise(State& s, long rows) {
  for (long j = 1; j < rows - 1; ++j)
    row_update<Taps::Point>(s.row(s.a, j), s.row(s.b, j), s.row(s.a, j), s.row(s.b, j));
}

// in_place_pointwise that also stores each row's old values into a two-row buffer (what an
// in-place sweep that saves the rows its neighbours still need, instead of a ring, would store).
void in_place_save_old(State& s, long rows, std::vector<double>& save) {
  for (long j = 1; j < rows - 1; ++j) {
    double* __restrict__ a = s.row(s.a, j);
    double* __restrict__ b = s.row(s.b, j);
    double* __restrict__ sa = save.data() + (j & 1) * 2 * kRow;
    double* __restrict__ sb = sa + kRow;
#pragma GCC ivdep
    for (long i = 0; i < kRow; ++i) {
      const double x = a[i], y = b[i];
      sa[i] = x;
      sb[i] = y;
      a[i] = x + kW * x;
      b[i] = y + kW * y;
    }
  }
}

void out_of_place(State& s, State& o, long rows) {
  for (long j = 1; j < rows - 1; ++j)
    row_update<Taps::FivePoint>(s.row(s.a, j), s.row(s.b, j), o.row(o.a, j), o.row(o.b, j));
}

// One 5-point sweep in place through the ring (committed by memcpy and by streaming stores)
// against the same sweep out of place: identical interior values (the same expression per
// cell), on every rank.
bool ring_matches_out_of_place(MPI_Comm comm, long rows) {
  State s(rows, 1.0, 2.0), t(rows, 1.0, 2.0), o(rows, 1.0, 2.0), ref(rows, 1.0, 2.0);
  std::vector<double> ring(4 * kRow);
  ring_sweep<Taps::FivePoint, true>(s, rows, ring);
  ring_sweep<Taps::FivePoint, false, true>(t, rows, ring);
  out_of_place(ref, o, rows);
  int same = 1;
  for (long j = 1; j < rows - 1; ++j)
    for (State* x : {&s, &t})
      same &= std::memcmp(x->row(x->a, j), o.row(o.a, j), kRow * sizeof(double)) == 0 &&
              std::memcmp(x->row(x->b, j), o.row(o.b, j), kRow * sizeof(double)) == 0;
  int all = 0;
  MPI_Allreduce(&same, &all, 1, MPI_INT, MPI_MIN, comm);
  return all == 1;
}

} // namespace

void bench_access_pattern(MPI_Comm comm, int rows_in, double roof) {
  const long rows = std::max(rows_in, 4);
  int size = 1;
  MPI_Comm_size(comm, &size);
  State s(rows, 1.0, 2.0), o(rows, 0.0, 0.0);
  std::vector<double> ring(4 * kRow);
  const double cells = static_cast<double>(rows - 2) * kRow;
  auto report = [&](const char* name, double sec) {
    const double cups = cells * size / sec;
    PetscPrintf(comm,
                "access_pattern name=%s rows_per_rank=%ldx%ld ns_per_cell_per_rank=%.3f "
                "cell_updates_per_s=%.4e fraction=%.3f\n",
                name, rows, kRow, 1e9 * sec / cells, cups, cups / roof);
  };
  auto time = [&](auto&& f) { return slowest_best_seconds(comm, f, 5); };
  report("in_place_pointwise", time([&] { in_place_pointwise(s, rows); }));
  report("in_place_save_old", time([&] { in_place_save_old(s, rows, ring); }));
  report("ring_pointwise", time([&] { ring_sweep<Taps::Point, false>(s, rows, ring); }));
  report("ring_pointwise_stream",
         time([&] { ring_sweep<Taps::Point, false, true>(s, rows, ring); }));
  report("ring_xtaps", time([&] { ring_sweep<Taps::X, false>(s, rows, ring); }));
  report("ring_5pt", time([&] { ring_sweep<Taps::FivePoint, false>(s, rows, ring); }));
  report("ring_5pt_prefetch", time([&] { ring_sweep<Taps::FivePoint, true>(s, rows, ring); }));
  report("ring_5pt_stream", time([&] { ring_sweep<Taps::FivePoint, false, true>(s, rows, ring); }));
  report("ring_5pt_prefetch_stream",
         time([&] { ring_sweep<Taps::FivePoint, true, true>(s, rows, ring); }));
  report("out_of_place_5pt", time([&] { out_of_place(s, o, rows); }));
  PetscPrintf(comm, "access_pattern streaming_stores=%s\n", stream_copy_kind());
  PetscPrintf(comm, "access_pattern check ring_5pt_equals_out_of_place=%s\n",
              ring_matches_out_of_place(comm, std::min<long>(rows, 64)) ? "yes" : "NO");
}

} // namespace morphogen
