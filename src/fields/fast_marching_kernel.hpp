// First-order fast marching on a 2-D cell grid, with extension velocities (Sethian 1999;
// Adalsteinsson & Sethian 1999, "fast extension velocities"), as stable-ARD section 6 uses to
// carry stroke orientations from the stroke cells to every other cell.
//
// Distance T solves |grad T| = 1 with the upwind first-order scheme on an nx x ny grid of
// spacings hx, hy (row-major, cell (i, j) at i + nx j):
//   ((T - a)/hx)^2 + ((T - b)/hy)^2 = 1,  a, b = the smaller accepted neighbour along x, y;
// where the quadratic has no root >= max(a, b) (or only one axis has an accepted neighbour)
// T = min(a + hx, b + hy). Extended quantities F (ncomp values per cell) solve
// grad F . grad T = 0 with the same upwind neighbours:
//   F = (wa Fa + wb Fb) / (wa + wb),  wa = (T - a)/hx^2, wb = (T - b)/hy^2   (only terms with T >
//   a, b).
// Error: first order, |T - exact| grows like O(h log(r/h)) near a point source and O(h) for
// smooth fronts; the tests measure it (tests/fields/kernel_test_fast_marching.cpp).
// Periodic axes wrap the neighbours. Seed cells (state = kFmmKnown on entry) keep their T and F.
// Pure kernel: no allocation (the caller passes the heap's workspace, FmmHeap),
// no PETSc, MPI or exceptions; the result depends only on the inputs (ties broken by cell index),
// so every rank that runs it gets the same bits.
#pragma once

#include <cmath>
#include <cstdint>

namespace morphogen {

inline constexpr std::uint8_t kFmmFar = 0, kFmmTrial = 1, kFmmKnown = 2;

struct FmmGrid {
  int nx, ny;
  double hx, hy;
  bool periodic_x, periodic_y;
};

// The workspace: heap[n] (cell indices ordered by T), key[n] (their T, kept beside them so the
// sifts read contiguous memory rather than T at scattered cells) and pos[n] (heap slot of a
// cell, or -1).
struct FmmHeap {
  int* heap;
  double* key;
  int* pos;
  int size;
  static bool less(double ka, int a, double kb, int b) { return ka < kb || (ka == kb && a < b); }
  void place(int slot, int cell, double k) {
    heap[slot] = cell;
    key[slot] = k;
    pos[cell] = slot;
  }
  void up(int slot, int c, double k) {
    while (slot > 0) {
      const int parent = (slot - 1) / 2;
      if (!less(k, c, key[parent], heap[parent])) break;
      place(slot, heap[parent], key[parent]);
      slot = parent;
    }
    place(slot, c, k);
  }
  void down(int slot, int c, double k) {
    for (;;) {
      int child = 2 * slot + 1;
      if (child >= size) break;
      if (child + 1 < size && less(key[child + 1], heap[child + 1], key[child], heap[child]))
        ++child;
      if (!less(key[child], heap[child], k, c)) break;
      place(slot, heap[child], key[child]);
      slot = child;
    }
    place(slot, c, k);
  }
  // Insert cell with key k, or lower its key to k.
  void push_or_decrease(int cell, double k) {
    if (pos[cell] < 0) {
      ++size;
      up(size - 1, cell, k);
    } else {
      up(pos[cell], cell, k);
    }
  }
  int pop() {
    const int top = heap[0];
    pos[top] = -1;
    --size;
    if (size > 0) down(0, heap[size], key[size]);
    return top;
  }
};

// Neighbour of cell (i, j) along axis `axis` on side s (-1, +1), or -1 outside a wall.
inline int fmm_neighbour(const FmmGrid& g, int i, int j, int axis, int s) {
  if (axis == 0) {
    int ii = i + s;
    if (ii < 0 || ii >= g.nx) {
      if (!g.periodic_x) return -1;
      ii = (ii + g.nx) % g.nx;
    }
    return ii + g.nx * j;
  }
  int jj = j + s;
  if (jj < 0 || jj >= g.ny) {
    if (!g.periodic_y) return -1;
    jj = (jj + g.ny) % g.ny;
  }
  return i + g.nx * jj;
}

// The accepted neighbour with the smaller T along one axis, or -1.
inline int fmm_upwind(const FmmGrid& g, const double* T, const std::uint8_t* state, int i, int j,
                      int axis) {
  int best = -1;
  for (int s = -1; s <= 1; s += 2) {
    const int q = fmm_neighbour(g, i, j, axis, s);
    if (q >= 0 && state[q] == kFmmKnown && (best < 0 || T[q] < T[best])) best = q;
  }
  return best;
}

// Upwind update of cell (i, j) from its accepted neighbours: the new T and extended F[ncomp].
inline double fmm_update(const FmmGrid& g, const double* T, const std::uint8_t* state,
                         const double* F, int ncomp, int i, int j, double* Fout) {
  const int qa = fmm_upwind(g, T, state, i, j, 0), qb = fmm_upwind(g, T, state, i, j, 1);
  const double ia = 1.0 / (g.hx * g.hx), ib = 1.0 / (g.hy * g.hy);
  double t;
  if (qa >= 0 && qb >= 0) {
    const double a = T[qa], b = T[qb];
    const double A = ia + ib, B = -2.0 * (a * ia + b * ib), C = a * a * ia + b * b * ib - 1.0;
    const double disc = B * B - 4.0 * A * C;
    t = disc >= 0 ? (-B + std::sqrt(disc)) / (2.0 * A) : -1.0;
    if (!(t >= a && t >= b)) t = std::fmin(a + g.hx, b + g.hy);
  } else {
    t = qa >= 0 ? T[qa] + g.hx : T[qb] + g.hy;
  }
  const double wa = qa >= 0 && t > T[qa] ? (t - T[qa]) * ia : 0.0;
  const double wb = qb >= 0 && t > T[qb] ? (t - T[qb]) * ib : 0.0;
  const double w = wa + wb;
  for (int c = 0; c < ncomp; ++c) {
    const double fa = qa >= 0 ? F[ncomp * qa + c] : 0.0, fb = qb >= 0 ? F[ncomp * qb + c] : 0.0;
    Fout[c] = w > 0 ? (wa * fa + wb * fb) / w : (qa >= 0 ? fa : fb);
  }
  return t;
}

// Update the non-accepted neighbours of the just-accepted cell p.
inline void fmm_relax_neighbours(const FmmGrid& g, double* T, std::uint8_t* state, double* F,
                                 int ncomp, FmmHeap& h, int p) {
  const int pi = p % g.nx, pj = p / g.nx;
  double f[8];
  for (int axis = 0; axis < 2; ++axis)
    for (int s = -1; s <= 1; s += 2) {
      const int q = fmm_neighbour(g, pi, pj, axis, s);
      if (q < 0 || state[q] == kFmmKnown) continue;
      const double t = fmm_update(g, T, state, F, ncomp, q % g.nx, q / g.nx, f);
      if (state[q] == kFmmTrial && !(t < T[q])) continue;
      T[q] = t;
      for (int c = 0; c < ncomp; ++c)
        F[ncomp * q + c] = f[c];
      state[q] = kFmmTrial;
      h.push_or_decrease(q, t);
    }
}

// March from the seed cells (state[c] == kFmmKnown, T and F set there) over the whole grid.
// T: n cells (values of non-seed cells are overwritten); F: ncomp (<= 8) values per cell;
// heap, pos: workspaces of n ints, key: of n doubles. Cells not reachable from a seed keep
// T = +inf, F = 0.
inline void fast_marching(const FmmGrid& g, double* T, std::uint8_t* state, double* F, int ncomp,
                          int* heap, double* key, int* pos) {
  const int n = g.nx * g.ny;
  for (int c = 0; c < n; ++c) {
    pos[c] = -1;
    if (state[c] == kFmmKnown) continue;
    state[c] = kFmmFar;
    T[c] = INFINITY;
    for (int k = 0; k < ncomp; ++k)
      F[ncomp * c + k] = 0.0;
  }
  FmmHeap h{heap, key, pos, 0};
  for (int c = 0; c < n; ++c)
    if (state[c] == kFmmKnown) fmm_relax_neighbours(g, T, state, F, ncomp, h, c);
  while (h.size > 0) {
    const int p = h.pop();
    state[p] = kFmmKnown;
    fmm_relax_neighbours(g, T, state, F, ncomp, h, p);
  }
}

} // namespace morphogen
