// The fused explicit row kernels as the integrator runs them (integrators/model_kernels.hpp:
// each model's table, compiled as the library is) give every cell the same bits wherever it
// lies in the row passed to them: for every compiled model, every row layout (5pt, 7pt, the box
// stencils by weight class and by taps: 9pt, 9-row), every parameter form of the table (which
// parameters are per-cell rows, the rest scalars), a row of
// 83 cells is swept whole and as every sub-row [i0, i0 + n) with i0 < 17 (so each cell is once
// in a vector body and once in a loop remainder, for 256- and 512-bit vectors). A rank's rows
// and a fused pass's tiles are such sub-rows, so this is what keeps explicit results
// independent of the decomposition and of -explicit_fuse_steps bit for bit. Both compiles of
// the table (256- and 512-bit vectors, -explicit_vector_width) are swept, every entry is set,
// and the wide compile gives the narrow one's bits on every sub-row. Each form also gives the
// bits of the all-rows kernel fed its scalars as rows of one value (a scalar kept in a register
// is the same number as a row of it). Software prefetch (ExplicitRow::prefetch_ahead, issued
// between the box-class kernel's blocks and chunks) changes no bit either: sub-rows of even
// length prefetch.
#include "../model_typed_tests.hpp"
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <tuple>
#include <vector>

#include "integrators/kernel_choice.hpp"
#include "integrators/model_kernels.hpp"
#include "models/all_models.hpp"

namespace {

using namespace morphogen;

MG_MODEL_TYPED_TEST_SUITE(ExplicitRowPosition);

constexpr int kN = 83;     // cells in the row (a prime: no vector width divides it)
constexpr int kAhead = 24; // cells ahead that a prefetching call prefetches (the rows hold them)

// Rows of one layout for species s: NR rows of kN + 2 values (x = -1 .. kN), around the
// species' initial value, every cell different.
struct Rows {
  int nr;
  std::vector<std::vector<double>> data; // [s * nr + r]
  std::vector<std::vector<double>> params;
  Rows(int ns, int nr_, int np, const double* init, const double* pdef) : nr(nr_) {
    for (int s = 0; s < ns; ++s)
      for (int r = 0; r < nr; ++r) {
        std::vector<double> v(kN + 2 + kAhead);
        for (int i = 0; i < kN + 2; ++i)
          v[i] = init[s] * (1.0 + 0.3 * std::sin(0.77 * i + 1.3 * r + 0.4 * s)) + 0.01 * r;
        data.push_back(v);
      }
    for (int q = 0; q < np; ++q) {
      std::vector<double> v(kN + 2);
      for (int i = 0; i < kN + 2; ++i)
        v[i] = pdef[q] * (1.0 + 0.05 * std::sin(0.3 * i + q));
      params.push_back(v);
    }
  }
};

// Sweeps cells [i0, i0 + n) of the rows into out (kN values per species).
template <class M>
void sweep(ExplicitRowFn fn, const Rows& rows, const double* w, const double* wclass,
           const double* pdef, bool field, int i0, int n, std::vector<std::vector<double>>& out,
           long ahead = 0) {
  constexpr int NS = M::nspecies;
  std::vector<const double*> src, prow;
  std::vector<double*> dst;
  for (const auto& r : rows.data)
    src.push_back(r.data() + 1 + i0);
  for (const auto& p : rows.params)
    prow.push_back(p.data() + 1 + i0);
  for (int s = 0; s < NS; ++s)
    dst.push_back(out[s].data() + i0);
  double D[NS], floor[NS];
  for (int s = 0; s < NS; ++s) {
    D[s] = 0.1 + 0.05 * s;
    floor[s] = -HUGE_VAL;
  }
  ExplicitRow a;
  a.n = n;
  a.src = src.data();
  a.w = w;
  a.wclass = wclass;
  a.D = D;
  a.floor = floor;
  a.prow = field ? prow.data() : nullptr; // a kernel of scalars reads no row
  a.pconst = pdef;
  a.dt = 0.05;
  a.dst = dst.data();
  a.prefetch_ahead = ahead;
  fn(a);
}

// The kernel that reads every parameter as a row, instantiated here (not from the table).
template <class M> ExplicitRowFn all_rows_kernel(int nr, bool box) {
  if (nr == 3)
    return box ? &explicit_row<M, 3, true, kAllParamRows>
               : &explicit_row<M, 3, false, kAllParamRows>;
  if (nr == 5) return &explicit_row<M, 5, false, kAllParamRows>;
  return &explicit_row<M, 9, true, kAllParamRows>;
}

TYPED_TEST(ExplicitRowPosition, EveryCellTheSameBitsWhereverItLiesInTheRow) {
  using M = TypeParam;
  constexpr int NS = M::nspecies, NP = M::nparams;
  ModelKernels k{};
  explicit_kernels<M>(k);
  double init[NS], pdef[NP > 0 ? NP : 1] = {};
  for (int s = 0; s < NS; ++s)
    init[s] = M::species[s].init != 0.0 ? M::species[s].init : 0.5;
  for (int q = 0; q < NP; ++q)
    pdef[q] = M::params[q].def;
  struct Layout {
    int nr;
    bool box, classes;
  };
  for (const Layout& L : {Layout{3, false, false}, Layout{5, false, false}, Layout{3, true, false},
                          Layout{3, true, true}, Layout{9, true, false}, Layout{9, true, true}})
    for (unsigned mask = 0; mask < kParamMasks; ++mask) {
      SCOPED_TRACE(std::to_string(L.nr) + (L.box ? " box" : " star") +
                   (L.classes ? " by class" : "") + " parameter mask " + std::to_string(mask));
      const bool field = mask != 0;
      Rows rows(NS, L.nr, NP, init, pdef);
      for (int q = 0; q < NP; ++q) // the parameters this form reads as scalars: rows of pdef[q]
        if (!(NP <= kParamMaskBits ? (mask >> q & 1u) != 0 : field))
          std::fill(rows.params[q].begin(), rows.params[q].end(), pdef[q]);
      std::vector<double> w(3 * static_cast<size_t>(L.nr));
      for (size_t t = 0; t < w.size(); ++t)
        w[t] = 0.05 + 0.01 * static_cast<double>(t % 5);
      const double wclass[4] = {-2.0, 0.3, 0.05, 0.01};
      const double* wc = L.classes ? wclass : nullptr;
      const ExplicitRowFn narrow = k.row_kernel(mask, L.nr, L.box, false);
      const ExplicitRowFn wide = k.row_kernel(mask, L.nr, L.box, true);
      ASSERT_NE(narrow, nullptr);
      ASSERT_NE(wide, nullptr);
      // Two compiles where the build has 512-bit vectors; the same code otherwise.
      if (wide_vectors_available()) {
        EXPECT_NE(narrow, wide);
      }
      std::vector<std::vector<double>> whole(NS, std::vector<double>(kN));
      sweep<M>(narrow, rows, w.data(), wc, pdef, field, 0, kN, whole);
      std::vector<std::vector<double>> all_rows(NS, std::vector<double>(kN));
      sweep<M>(all_rows_kernel<M>(L.nr, L.box), rows, w.data(), wc, pdef, true, 0, kN, all_rows);
      for (int s = 0; s < NS; ++s)
        EXPECT_EQ(std::memcmp(whole[s].data(), all_rows[s].data(), sizeof(double) * kN), 0)
            << "species " << s << ": the parameter form changes the bits";
      long differ = 0, differ_wide = 0;
      for (const ExplicitRowFn fn : {narrow, wide})
        for (int i0 = 0; i0 < 17; ++i0)
          for (int n = 1; i0 + n <= kN; n += (fn == wide ? 1 : 3)) {
            std::vector<std::vector<double>> part(NS, std::vector<double>(kN));
            sweep<M>(fn, rows, w.data(), wc, pdef, field, i0, n, part, n % 2 == 0 ? kAhead : 0);
            for (int s = 0; s < NS; ++s)
              for (int i = i0; i < i0 + n; ++i)
                (fn == wide ? differ_wide : differ) +=
                    std::memcmp(&part[s][i], &whole[s][i], sizeof(double)) != 0 ? 1 : 0;
          }
      EXPECT_EQ(differ, 0) << "cells whose bits depend on their place in the row";
      EXPECT_EQ(differ_wide, 0) << "cells of the 512-bit compile that differ from the 256-bit one";
    }
}

} // namespace
