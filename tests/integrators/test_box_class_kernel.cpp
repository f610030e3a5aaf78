// The explicit kernel's weight-class path for the 3-D box stencils (19pt, 27pt;
// explicit_row_box_classes, used when ExplicitRow::wclass is set) against
//   1. an exact reference: with the reaction off (Gray-Scott s = 0) and u a quadratic plus
//      xyz (the stencils are exact on it), out = u + dt D lap u with lap u = 2 + 4 - 1 = 5,
//      to 1e-13 of |u| (round-off only);
//   2. the general 27-tap row form (wclass null, rows in to_rows order, summed tap by tap),
//      with the reaction on and per-cell parameters: the same sum in another order, to
//      1e-14 of max |u| (a few ulp);
// and checks that the class path gives the same bits whatever part of a row a call covers
// (a row split in x between ranks, and the kBoxChunk chunks inside a call): rows of
// 2 kBoxChunk + 13 cells computed whole and in pieces must agree exactly.
#include "grid/stencil.hpp"
#include "integrators/explicit_kernel.hpp"
#include "models/gray_scott.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

using namespace morphogen;

namespace {

using GS = models::GrayScott;
constexpr int kN = 2 * kBoxChunk + 13; // cells in the test row (three chunks)

// A 3-D ghosted block of kN x 1 x 1 owned cells with its ghost frame (3 x 3 rows of kN + 2).
struct Block {
  double h = 0.5;
  std::vector<double> u[2];
  long idx(int i, int dy, int dz) const { return (i + 1) + (kN + 2L) * ((dy + 1) + 3 * (dz + 1)); }
  template <class F> explicit Block(F f) {
    for (int s = 0; s < 2; ++s) {
      u[s].assign((kN + 2) * 9, 0.0);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int i = -1; i <= kN; ++i)
            u[s][idx(i, dy, dz)] = f(s, i * h, dy * h, dz * h);
    }
  }
};

struct BoxRows {
  RowStencil rows;
  BoxClasses classes;
  explicit BoxRows(const char* name, double h) {
    const double hh[3] = {h, h, h};
    Stencil st;
    EXPECT_TRUE(make_stencil(name, 3, hh, st));
    EXPECT_TRUE(to_rows(st, rows));
    EXPECT_TRUE(box_classes(rows, classes));
  }
};

// Cells [i0, i0 + len) of the block's middle row through explicit_row<GS, 9, true, PR>: by
// class (rows in classes.perm order) or by the general row form.
template <ParamRows PR>
void run_row(const Block& b, const BoxRows& st, bool by_class, const double* p, int i0, int len,
             std::vector<double> (&out)[2]) {
  const double* src[18];
  double* dst[2];
  const double D[2] = {0.3, 0.7}, floor[2] = {-INFINITY, -INFINITY};
  static std::vector<double> prows[3];
  const double* prow[3];
  for (int q = 0; q < 3; ++q) {
    prows[q].resize(kN);
    for (int i = 0; i < kN; ++i)
      prows[q][i] = p[q] * (1 + 0.1 * std::sin(0.3 * i + q));
    prow[q] = prows[q].data() + i0;
  }
  for (int s = 0; s < 2; ++s) {
    for (int r = 0; r < 9; ++r) {
      const int q = by_class ? st.classes.perm[r] : r;
      src[9 * s + r] = b.u[s].data() + b.idx(i0, st.rows.off[q][0], st.rows.off[q][1]);
    }
    out[s].resize(kN);
    dst[s] = out[s].data() + i0;
  }
  ExplicitRow a;
  a.n = len;
  a.src = src;
  a.w = st.rows.w.data();
  a.D = D;
  a.floor = floor;
  a.prow = prow;
  a.pconst = p;
  a.dt = 0.01;
  a.dst = dst;
  a.wclass = by_class ? st.classes.w.data() : nullptr;
  explicit_row<GS, 9, true, PR>(a);
}

double wave(int s, double x, double y, double z) {
  return 0.5 + 0.3 * std::sin(1.7 * x + 0.9 * y - 1.3 * z + s) + 0.1 * std::cos(5.1 * x * y);
}

} // namespace

TEST(BoxClassKernel, ExactOnAQuadraticWithTheReactionOff) {
  const Block b([](int s, double x, double y, double z) {
    return (1 + s) * (x * x + 2 * y * y - 0.5 * z * z + x * y * z + 3 * y * z - x) + 2;
  });
  const double p[3] = {0.04, 0.06, 0.0}; // s = 0: no reaction
  for (const char* name : {"19pt", "27pt"}) {
    const BoxRows st(name, b.h);
    std::vector<double> out[2];
    run_row<kScalarParams>(b, st, true, p, 0, kN, out);
    for (int s = 0; s < 2; ++s)
      for (int i = 0; i < kN; ++i) {
        const double u = b.u[s][b.idx(i, 0, 0)];
        const double expect = u + 0.01 * (s ? 0.7 : 0.3) * (1 + s) * 5.0;
        ASSERT_NEAR(out[s][i], expect, 1e-13 * std::fabs(u)) << name << " s " << s << " i " << i;
      }
  }
}

TEST(BoxClassKernel, MatchesTheGeneralRowFormWithReactionAndFieldParams) {
  const Block b(wave);
  const double p[3] = {0.04, 0.06, 1.0};
  for (const char* name : {"19pt", "27pt"}) {
    const BoxRows st(name, b.h);
    std::vector<double> cls[2], gen[2], clsf[2], genf[2];
    run_row<kScalarParams>(b, st, true, p, 0, kN, cls);
    run_row<kScalarParams>(b, st, false, p, 0, kN, gen);
    run_row<kAllParamRows>(b, st, true, p, 0, kN, clsf);
    run_row<kAllParamRows>(b, st, false, p, 0, kN, genf);
    double diff = 0, difff = 0, scale = 0, change = 0;
    for (int s = 0; s < 2; ++s)
      for (int i = 0; i < kN; ++i) {
        diff = std::max(diff, std::fabs(cls[s][i] - gen[s][i]));
        difff = std::max(difff, std::fabs(clsf[s][i] - genf[s][i]));
        scale = std::max(scale, std::fabs(gen[s][i]));
        change = std::max(change, std::fabs(gen[s][i] - b.u[s][b.idx(i, 0, 0)]));
      }
    EXPECT_LE(diff, 1e-14 * scale) << name;
    EXPECT_LE(difff, 1e-14 * scale) << name << " (per-cell parameters)";
    EXPECT_GT(change, 1e-3) << "the step must change the state for the comparison to mean much";
  }
}

TEST(BoxClassKernel, SameBitsWhateverPartOfTheRowACallCovers) {
  const Block b(wave);
  const double p[3] = {0.04, 0.06, 1.0};
  // Splits of the row as ranks (or the chunks of one call) would cut it.
  const std::vector<std::vector<int>> splits = {
      {0, kN}, {0, 1, kN}, {0, 100, kN}, {0, kBoxChunk, kN}, {0, 7, kBoxChunk + 9, kN - 3, kN}};
  for (const char* name : {"19pt", "27pt"}) {
    const BoxRows st(name, b.h);
    std::vector<double> whole[2];
    run_row<kScalarParams>(b, st, true, p, 0, kN, whole);
    for (const auto& cut : splits) {
      std::vector<double> pieces[2];
      for (size_t c = 0; c + 1 < cut.size(); ++c)
        run_row<kScalarParams>(b, st, true, p, cut[c], cut[c + 1] - cut[c], pieces);
      for (int s = 0; s < 2; ++s)
        for (int i = 0; i < kN; ++i)
          ASSERT_EQ(whole[s][i], pieces[s][i])
              << name << " s " << s << " i " << i << " pieces " << cut.size() - 1;
    }
  }
}

// box_row_diffusion (lane shifts on GCC, blocks of 4 or 8 lanes with an overlapping last block)
// against box_row_diffusion_cells (three profiles per cell, the same expressions): the same
// bits for every length, start and read limit xmax (tight: x0 + len; loose: the row's end).
template <bool Corners, bool Wide> void expect_same_diffusion(const Block& b, const BoxRows& st) {
  const double* rows[9];
  for (int r = 0; r < 9; ++r) {
    const int q = st.classes.perm[r];
    rows[r] = b.u[1].data() + b.idx(0, st.rows.off[q][0], st.rows.off[q][1]);
  }
  const double* w = st.classes.w.data();
  std::vector<double> vec(kN), ref(kN);
  for (int x0 : {0, 1, 5, 64})
    for (int len = 1; x0 + len <= kN && len <= 70; ++len)
      for (int xmax : {x0 + len, kN}) {
        box_row_diffusion<Corners, Wide>(rows, w, x0, len, xmax, vec.data());
        box_row_diffusion_cells<Corners>(rows, w, x0, len, ref.data());
        for (int t = 0; t < len; ++t)
          ASSERT_EQ(vec[t], ref[t]) << "x0 " << x0 << " len " << len << " xmax " << xmax << " t "
                                    << t << " wide " << Wide << " corners " << Corners;
      }
}

TEST(BoxClassKernel, LaneShiftsGiveTheBitsOfTheCellByCellProfiles) {
  const Block b(wave);
  for (const char* name : {"19pt", "27pt"}) {
    const BoxRows st(name, b.h);
    expect_same_diffusion<true, false>(b, st);
    expect_same_diffusion<true, true>(b, st);
    expect_same_diffusion<false, false>(b, st);
    expect_same_diffusion<false, true>(b, st);
  }
}
