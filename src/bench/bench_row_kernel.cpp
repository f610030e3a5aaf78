#include "bench/bench_row_kernel.hpp"

#include "grid/stencil.hpp"
#include "integrators/kernel_choice.hpp"
#include "integrators/model_kernels.hpp"

#include <petscsys.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace morphogen {

namespace {

// Rows j-1, j, j+1 of both species (row stride n + 16) and two output
// rows; values near the Gray-Scott spot state so no cell overflows over repeated calls.
struct KernelRows {
  int n;
  long stride;
  std::vector<double> in, out;
  const double* src[6];
  double* dst[2];
  explicit KernelRows(int cells) : n(cells), stride(cells + 16) {
    in.resize(static_cast<size_t>(6 * stride));
    out.resize(static_cast<size_t>(2 * stride));
    for (size_t i = 0; i < in.size(); ++i)
      in[i] = (i % 2 ? 0.25 : 0.75) + 1e-3 * static_cast<double>(i % 97);
  }
  // src[s*3 + r]: row r of species s in RowStencil order (offsets 0, -1, +1 in y).
  void point(const RowStencil& rows) {
    for (int s = 0; s < 2; ++s) {
      const double* base = in.data() + (3 * s + 1) * stride + 8;
      for (int r = 0; r < rows.nrows; ++r)
        src[s * rows.nrows + r] = base + rows.off[r][0] * stride;
      dst[s] = out.data() + s * stride + 8;
    }
  }
};

double seconds_of_calls(MPI_Comm comm, ExplicitRowFn fn, const ExplicitRow& row, long calls) {
  MPI_Barrier(comm);
  const double t0 = MPI_Wtime();
  for (long c = 0; c < calls; ++c)
    fn(row);
  double t = MPI_Wtime() - t0, tmax = 0;
  MPI_Allreduce(&t, &tmax, 1, MPI_DOUBLE, MPI_MAX, comm);
  return tmax;
}

} // namespace

RowKernelRate time_row_kernel(MPI_Comm comm, const std::string& stencil, int n) {
  const double h[3] = {1.0, 1.0, 1.0};
  Stencil st;
  RowStencil rows;
  if (!make_stencil(stencil, 2, h, st) || !to_rows(st, rows) || rows.nrows != 3)
    throw std::logic_error("time_row_kernel: stencil " + stencil + " has no 3-row form");
  KernelRows buf(n);
  buf.point(rows);
  const double D[2] = {0.2, 0.1}, floor[2] = {-HUGE_VAL, -HUGE_VAL};
  const double p[3] = {0.035, 0.065, 1.0}; // F, k, s
  ExplicitRow row;
  row.n = n;
  row.src = buf.src;
  row.w = rows.w.data();
  row.D = D;
  row.floor = floor;
  row.pconst = p;
  row.dt = 0.5;
  row.dst = buf.dst;
  const ModelKernels k = model_kernels<models::GrayScott>();
  const long calls = std::max<long>(1, (1L << 22) / n); // about 4 ms per rep
  int size = 1;
  MPI_Comm_size(comm, &size);
  RowKernelRate r;
  for (int wide = 0; wide < (wide_vectors_available() ? 2 : 1); ++wide) {
    const ExplicitRowFn fn = k.row_kernel(false, rows.nrows, rows.box, wide == 1);
    double best = 1e30;
    for (int rep = 0; rep < 5; ++rep)
      best = std::min(best, seconds_of_calls(comm, fn, row, calls));
    r.ns_per_cell[wide] = best / (static_cast<double>(calls) * n) * 1e9;
  }
  if (!wide_vectors_available()) r.ns_per_cell[1] = r.ns_per_cell[0];
  r.ceiling = size / (std::min(r.ns_per_cell[0], r.ns_per_cell[1]) * 1e-9);
  return r;
}

void print_row_kernel_bounds(MPI_Comm comm, const std::string& stencil, double roof) {
  const int n = 512; // 2 species x 3 rows x 4 KiB in, 8 KiB out: in L1
  const RowKernelRate r = time_row_kernel(comm, stencil, n);
  const double serial = 1.0 / (1.0 / r.ceiling + 1.0 / roof);
  PetscPrintf(comm,
              "explicit_row_kernel model=gray_scott stencil=%s row=%d ns_per_cell_256bit=%.3f "
              "ns_per_cell_512bit=%.3f (one core, rows in cache)\n",
              stencil.c_str(), n, r.ns_per_cell[0], r.ns_per_cell[1]);
  PetscPrintf(comm,
              "explicit_ceiling cell_updates_per_s=%.4e roofline_fraction=%.3f (all ranks' "
              "kernels, memory out of the way: bounds fused passes; their 1.5 target %s it)\n",
              r.ceiling, r.ceiling / roof, 1.5 * roof > r.ceiling ? "exceeds" : "is within");
  PetscPrintf(comm,
              "explicit_serial_bound cell_updates_per_s=%.4e roofline_fraction=%.3f (one step "
              "out of cache if arithmetic and memory traffic do not overlap: "
              "1/(1/ceiling + 1/roofline))\n",
              serial, serial / roof);
}

} // namespace morphogen
