// Reduced x-y slice images; see slice_image.hpp and block_mean_kernel.hpp.
#include "io/slice_image.hpp"

#include "io/block_mean_kernel.hpp"
#include "io/slice_gather.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace morphogen::io {

namespace {

// Finite min/max of this rank's cells of slice k, reduced over all ranks ({+inf, -inf}: none).
std::array<double, 2> finite_range(const Grid& grid, const double* a, PetscInt k, bool mine) {
  const Box& ob = grid.owned();
  double r[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  if (mine)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j) {
      const double* row = a + grid.local_index(ob.s[0], j, k);
      for (PetscInt i = 0; i < ob.m[0]; ++i)
        if (std::isfinite(row[i])) {
          r[0] = std::min(r[0], row[i]);
          r[1] = std::min(r[1], -row[i]);
        }
    }
  MPI_Allreduce(MPI_IN_PLACE, r, 2, MPI_DOUBLE, MPI_MIN, grid.comm());
  return {r[0], -r[1]};
}

// This rank's block rectangle {bx0, by0, bw, bh} of slice k (bw = bh = 0: none).
std::array<long long, 4> block_rect(const Grid& grid, const BlockMeanPlan& p, bool mine) {
  const Box& ob = grid.owned();
  if (!mine || ob.m[0] == 0 || ob.m[1] == 0) return {0, 0, 0, 0};
  const long long bx0 = ob.s[0] / p.f, by0 = ob.s[1] / p.f;
  const long long bx1 = (ob.s[0] + ob.m[0] - 1) / p.f, by1 = (ob.s[1] + ob.m[1] - 1) / p.f;
  return {bx0, by0, bx1 - bx0 + 1, by1 - by0 + 1};
}

SliceImage full_resolution(const Grid& grid, const double* a, PetscInt k) {
  SliceImage img;
  img.value = gather_xy_slice(grid, a, k);
  img.width = static_cast<int>(grid.spec().n[0]);
  img.height = static_cast<int>(grid.spec().n[1]);
  if (!img.value.empty()) {
    img.lo = *std::min_element(img.value.begin(), img.value.end());
    img.hi = *std::max_element(img.value.begin(), img.value.end());
  }
  return img;
}

// Every rank's block sums of rect {bx0, by0, bw, bh}, gathered on rank 0 and added into the
// image's p.w x p.h blocks (integer sums: the order does not matter); empty off rank 0. The
// rank's own sums are released once sent and the gathered ones once added (a 4096^2 field's
// 1024^2 image is 25 MB per copy: the run's peak memory if held together).
std::vector<BlockSum> gather_block_sums(MPI_Comm comm, const BlockMeanPlan& p,
                                        const std::array<long long, 4>& rect,
                                        std::vector<BlockSum> sums) {
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  std::vector<long long> rects(rank == 0 ? 4 * static_cast<size_t>(size) : 0);
  MPI_Gather(rect.data(), 4, MPI_LONG_LONG, rects.data(), 4, MPI_LONG_LONG, 0, comm);
  std::vector<int> counts(size, 0), displs(size, 0);
  if (rank == 0)
    for (int q = 0, off = 0; q < size; ++q) {
      counts[q] = static_cast<int>(3 * rects[4 * q + 2] * rects[4 * q + 3]);
      displs[q] = off;
      off += counts[q];
    }
  std::vector<BlockSum> all(rank == 0 ? static_cast<size_t>(displs[size - 1] + counts[size - 1]) / 3
                                      : 0);
  static_assert(sizeof(BlockSum) == 3 * sizeof(std::int64_t));
  MPI_Gatherv(sums.data(), static_cast<int>(3 * sums.size()), MPI_INT64_T, all.data(),
              counts.data(), displs.data(), MPI_INT64_T, 0, comm);
  std::vector<BlockSum>().swap(sums);
  std::vector<BlockSum> total(rank == 0 ? static_cast<size_t>(p.w * p.h) : 0);
  for (int q = 0; q < (rank == 0 ? size : 0); ++q) {
    const long long* r = &rects[4 * static_cast<size_t>(q)];
    const BlockSum* src = all.data() + displs[q] / 3;
    for (long long J = 0; J < r[3]; ++J)
      for (long long I = 0; I < r[2]; ++I) {
        BlockSum& t = total[static_cast<size_t>((r[0] + I) + p.w * (r[1] + J))];
        const BlockSum& s = src[I + r[2] * J];
        t.q += s.q;
        t.count += s.count;
        t.bad += s.bad;
      }
  }
  return total;
}

} // namespace

SliceImage gather_xy_slice_image(const Grid& grid, const double* a, PetscInt k,
                                 long long max_size) {
  const long long nx = grid.spec().n[0], ny = grid.spec().n[1];
  if (block_factor(nx, ny, max_size) == 1) return full_resolution(grid, a, k);
  const Box& ob = grid.owned();
  const bool mine = k >= ob.s[2] && k < ob.s[2] + ob.m[2];
  const auto range = finite_range(grid, a, k, mine);
  const BlockMeanPlan p = block_mean_plan(nx, ny, max_size, range[0], range[1]);
  const auto rect = block_rect(grid, p, mine);
  std::vector<BlockSum> sums(static_cast<size_t>(rect[2] * rect[3]));
  if (mine)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      add_row_to_blocks(p, j, ob.s[0], ob.m[0], a + grid.local_index(ob.s[0], j, k), rect[0],
                        rect[1], rect[2], sums.data());
  const std::vector<BlockSum> total = gather_block_sums(grid.comm(), p, rect, std::move(sums));
  SliceImage img;
  img.factor = p.f;
  img.width = static_cast<int>(p.w);
  img.height = static_cast<int>(p.h);
  img.lo = range[0];
  img.hi = range[1];
  img.value.resize(total.size()); // rank 0 only
  for (size_t b = 0; b < total.size(); ++b)
    img.value[b] = block_mean(p, total[b]);
  return img;
}

} // namespace morphogen::io
