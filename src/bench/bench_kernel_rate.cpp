#include "bench/bench_kernel_rate.hpp"

#include "grid/stencil.hpp"
#include "integrators/fused_sweep.hpp"
#include "integrators/kernel_choice.hpp"
#include "integrators/model_kernels.hpp"

#include <petscsys.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace morphogen {

namespace {

// The rows a stencil reads around one row of n cells: 3 x 3 rows (dy, dz in -1..1) of both
// species (row stride n + 16, plane stride 3 rows) and two output rows; values near the
// Gray-Scott spot state so no cell overflows over repeated calls.
struct KernelRows {
  long stride;
  std::vector<double> in, out;
  std::vector<const double*> src;
  double* dst[2];
  explicit KernelRows(int cells) : stride(cells + 16) {
    in.resize(static_cast<size_t>(18 * stride));
    out.resize(static_cast<size_t>(2 * stride));
    for (size_t i = 0; i < in.size(); ++i)
      in[i] = (i % 2 ? 0.25 : 0.75) + 1e-3 * static_cast<double>(i % 97);
  }
  // src[s*nr + q]: the row of stencil row order[q] of species s (RowStencil offsets dy, dz).
  void point(const RowStencil& rows, const int* order) {
    src.assign(static_cast<size_t>(2 * rows.nrows), nullptr);
    for (int s = 0; s < 2; ++s) {
      const double* centre = in.data() + (9 * s + 4) * stride + 8; // dy = dz = 0
      for (int q = 0; q < rows.nrows; ++q) {
        const auto& off = rows.off[static_cast<size_t>(order[q])];
        src[static_cast<size_t>(s * rows.nrows + q)] = centre + (off[0] + 3 * off[1]) * stride;
      }
      dst[s] = out.data() + s * stride + 8;
    }
  }
};

// Seconds of the slowest rank for f(), all ranks starting together.
template <class F> double slowest_seconds(MPI_Comm comm, F&& f) {
  MPI_Barrier(comm);
  const double t0 = MPI_Wtime();
  f();
  double t = MPI_Wtime() - t0, tmax = 0;
  MPI_Allreduce(&t, &tmax, 1, MPI_DOUBLE, MPI_MAX, comm);
  return tmax;
}

double seconds_of_calls(MPI_Comm comm, ExplicitRowFn fn, const ExplicitRow& row, long calls) {
  return slowest_seconds(comm, [&] {
    for (long c = 0; c < calls; ++c)
      fn(row);
  });
}

// The wavefront of a fused pass (integrators/fused_sweep.hpp) over a ring only: level l computes
// its row jw - l r from the 2r + 1 ring rows of level l - 1, for `levels` levels; level 0's ring
// rows are filled once (no memory read or written in the loop). Seconds of the slowest rank
// for `nrows` wavefront rows, best of 5.
double seconds_of_ring(MPI_Comm comm, ExplicitRowFn fn, ExplicitRow row, const RowStencil& rows,
                       int levels, long nrows) {
  const int r = FusedSweep::radius(rows);
  const long ring = 2 * r + 1, stride = (row.n + 2 + 7) / 8 * 8 + 8;
  std::vector<double> buf(static_cast<size_t>((levels + 1) * 2 * ring * stride));
  for (size_t i = 0; i < buf.size(); ++i)
    buf[i] = (i % 2 ? 0.25 : 0.75) + 1e-3 * static_cast<double>(i % 97);
  auto at = [&](int l, int s, long j) {
    return buf.data() + ((l * 2 + s) * ring + j % ring) * stride + 8;
  };
  std::vector<const double*> src(static_cast<size_t>(2 * rows.nrows));
  double* dst[2];
  row.src = src.data();
  row.dst = dst;
  double best = 1e30;
  auto wavefront = [&] {
    for (long jw = levels * r; jw < levels * r + nrows; ++jw)
      for (int l = 1; l <= levels; ++l) {
        const long jl = jw - l * r + ring * levels; // (kept non-negative for the ring slots)
        for (int s = 0; s < 2; ++s) {
          for (int q = 0; q < rows.nrows; ++q)
            src[static_cast<size_t>(s * rows.nrows + q)] =
                at(l - 1, s, jl + rows.off[static_cast<size_t>(q)][0]);
          dst[s] = at(l, s, jl);
        }
        fn(row);
      }
  };
  for (int rep = 0; rep < 5; ++rep)
    best = std::min(best, slowest_seconds(comm, wavefront));
  return best;
}

RowStencil row_stencil(const std::string& stencil, int dim) {
  const double h[3] = {1.0, 1.0, 1.0};
  Stencil st;
  RowStencil rows;
  if (!make_stencil(stencil, dim, h, st) || !to_rows(st, rows))
    throw std::logic_error("bench kernel rate: stencil " + stencil + " has no row form");
  return rows;
}

// The Gray-Scott row's constant inputs (D, floor, parameters, dt) for the timing loops.
struct GrayScottRow {
  double D[2] = {0.2, 0.1}, floor[2] = {-HUGE_VAL, -HUGE_VAL};
  double p[3] = {0.035, 0.065, 1.0}; // F, k, s
};

ExplicitRow gray_scott_row(const GrayScottRow& gs, const RowStencil& rows, int n) {
  ExplicitRow row;
  row.n = n;
  row.w = rows.w.data();
  row.D = gs.D;
  row.floor = gs.floor;
  row.pconst = gs.p;
  row.dt = 0.5;
  return row;
}

} // namespace

RowKernelRate time_row_kernel(MPI_Comm comm, const std::string& stencil, int dim, int n) {
  const RowStencil rows = row_stencil(stencil, dim);
  // The box stencils' weight-class form where the explicit integrator takes it.
  BoxClasses classes;
  const bool by_class = box_classes(rows, classes);
  int order[9] = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  if (by_class) std::copy(classes.perm.begin(), classes.perm.end(), order);
  KernelRows buf(n);
  buf.point(rows, order);
  const GrayScottRow gs;
  ExplicitRow row = gray_scott_row(gs, rows, n);
  row.src = buf.src.data();
  row.wclass = by_class ? classes.w.data() : nullptr;
  row.dst = buf.dst;
  const ModelKernels k = model_kernels<models::GrayScott>();
  const long calls = std::max<long>(1, (1L << 22) / n); // about 4 ms per rep
  int size = 1;
  MPI_Comm_size(comm, &size);
  RowKernelRate r;
  for (int wide = 0; wide < (wide_vectors_available() ? 2 : 1); ++wide) {
    const ExplicitRowFn fn = k.row_kernel(0, rows.nrows, rows.box, wide == 1);
    double best = 1e30;
    for (int rep = 0; rep < 5; ++rep)
      best = std::min(best, seconds_of_calls(comm, fn, row, calls));
    r.ns_per_cell[wide] = best / (static_cast<double>(calls) * n) * 1e9;
  }
  if (!wide_vectors_available()) r.ns_per_cell[1] = r.ns_per_cell[0];
  r.ceiling = size / (std::min(r.ns_per_cell[0], r.ns_per_cell[1]) * 1e-9);
  return r;
}

double time_fused_ring(MPI_Comm comm, const std::string& stencil, int n, int levels) {
  RowStencil rows = row_stencil(stencil, 2);
  BoxClasses classes; // the box stencil's weight-class form, as the fused sweep runs it
  const bool by_class = to_class_order(rows, classes);
  const GrayScottRow gs;
  ExplicitRow row = gray_scott_row(gs, rows, n);
  row.wclass = by_class ? classes.w.data() : nullptr;
  const ModelKernels k = model_kernels<models::GrayScott>();
  const long nrows = std::max<long>(1, (1L << 22) / (static_cast<long>(n) * levels));
  double ns = 1e30;
  for (int wide = 0; wide < (wide_vectors_available() ? 2 : 1); ++wide) {
    const ExplicitRowFn fn = k.row_kernel(0, rows.nrows, rows.box, wide == 1);
    const double sec = seconds_of_ring(comm, fn, row, rows, levels, nrows);
    ns = std::min(ns, sec / (static_cast<double>(nrows) * levels * n) * 1e9);
  }
  return ns;
}

void print_fused_ring_bound(MPI_Comm comm, const std::string& stencil, double roof, int n,
                            int levels) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  const double ns = time_fused_ring(comm, stencil, n, levels);
  const double cups = size / (ns * 1e-9);
  PetscPrintf(comm,
              "explicit_fused_ring stencil=%s row=%d levels=%d ns_per_cell=%.4f "
              "cell_updates_per_s=%.4e roofline_fraction=%.3f (a fused pass's levels with every "
              "row in the ring, the state neither read nor written: what its passes reach at "
              "most)\n",
              stencil.c_str(), n, levels, ns, cups, cups / roof);
}

void print_row_kernel_bounds(MPI_Comm comm, const std::string& stencil, int dim, double roof,
                             int n) {
  const RowKernelRate r = time_row_kernel(comm, stencil, dim, n);
  const double serial = 1.0 / (1.0 / r.ceiling + 1.0 / roof);
  const char* tag = dim == 3 ? "explicit_3d" : "explicit";
  PetscPrintf(comm,
              "%s_row_kernel model=gray_scott stencil=%s row=%d ns_per_cell_256bit=%.3f "
              "ns_per_cell_512bit=%.3f (one core, rows in cache)\n",
              tag, stencil.c_str(), n, r.ns_per_cell[0], r.ns_per_cell[1]);
  PetscPrintf(comm,
              "%s_ceiling stencil=%s cell_updates_per_s=%.4e roofline_fraction=%.3f (all ranks' "
              "kernels, memory out of the way: bounds fused passes%s)\n",
              tag, stencil.c_str(), r.ceiling, r.ceiling / roof,
              dim == 3 ? ""
                       : (1.5 * roof > r.ceiling ? "; their 1.5 target exceeds it"
                                                 : "; their 1.5 target is within it"));
  PetscPrintf(comm,
              "%s_serial_bound stencil=%s cell_updates_per_s=%.4e roofline_fraction=%.3f (one "
              "step out of cache if arithmetic and memory traffic do not overlap: "
              "1/(1/ceiling + 1/roofline))\n",
              tag, stencil.c_str(), serial, serial / roof);
}

} // namespace morphogen
