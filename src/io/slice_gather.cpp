#include "io/slice_gather.hpp"

namespace morphogen::io {

std::vector<double> gather_xy_slice(const Grid& grid, const double* ghosted, PetscInt k, int root) {
  MPI_Comm comm = grid.comm();
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  const Box& ob = grid.owned();
  const bool mine = k >= ob.s[2] && k < ob.s[2] + ob.m[2];
  int rect[4] = {0, 0, 0, 0};
  std::vector<double> buf; // this rank's rectangle (not on the root: it writes its own directly)
  if (mine) {
    rect[0] = static_cast<int>(ob.s[0]);
    rect[1] = static_cast<int>(ob.s[1]);
    rect[2] = static_cast<int>(ob.m[0]);
    rect[3] = static_cast<int>(ob.m[1]);
  }
  if (mine && rank != root) {
    buf.reserve(static_cast<size_t>(ob.m[0] * ob.m[1]));
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
        buf.push_back(ghosted[grid.local_index(i, j, k)]);
  }
  std::vector<int> rects(rank == root ? 4 * size : 0);
  MPI_Gather(rect, 4, MPI_INT, rects.data(), 4, MPI_INT, root, comm);
  std::vector<int> counts(size, 0), displs(size, 0);
  if (rank == root)
    for (int p = 0, off = 0; p < size; ++p) { // the root sends nothing
      counts[p] = p == root ? 0 : rects[4 * p + 2] * rects[4 * p + 3];
      displs[p] = off;
      off += counts[p];
    }
  const int total = rank == root ? displs[size - 1] + counts[size - 1] : 0;
  std::vector<double> all(static_cast<size_t>(total));
  MPI_Gatherv(buf.data(), static_cast<int>(buf.size()), MPI_DOUBLE, all.data(), counts.data(),
              displs.data(), MPI_DOUBLE, root, comm);
  if (rank != root) return {};
  const PetscInt nx = grid.spec().n[0];
  std::vector<double> out(static_cast<size_t>(nx * grid.spec().n[1]), 0.0);
  if (mine)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
        out[i + nx * j] = ghosted[grid.local_index(i, j, k)];
  for (int p = 0; p < size; ++p) {
    if (p == root) continue;
    const int* r = &rects[4 * p];
    const double* src = all.data() + displs[p];
    for (int j = 0; j < r[3]; ++j)
      for (int i = 0; i < r[2]; ++i)
        out[(r[0] + i) + nx * (r[1] + j)] = src[i + r[2] * j];
  }
  return out;
}

} // namespace morphogen::io
