// The explicit kernel's weight-class path for the box stencils (2-D 9pt, 3-D 19pt, 27pt;
// explicit_row_box_classes, used when ExplicitRow::wclass is set) against
//   1. an exact reference: with the reaction off (Gray-Scott s = 0) and u a quadratic plus
//      xyz (the stencils are exact on it), out = u + dt D lap u with lap u = 2 + 4 - 1 = 5
//      (2-D, the plane z = 0: 2 + 4 = 6), to 1e-13 of |u| (round-off only);
//   2. the general tap row form (wclass null, rows in to_rows order, summed tap by tap),
//      with the reaction on and per-cell parameters: the same sum in another order, to
//      1e-14 of max |u| (a few ulp);
// and checks that the class path gives the same bits whatever part of a row a call covers
// (a row split in x between ranks, the kBoxChunk chunks inside a call, and the first chunk
// up to the rows' aligned start where all rows share one alignment): rows of 2 kBoxChunk + 13
// cells computed whole and in pieces must agree exactly, with rows of kN + 2 values and with
// rows padded to whole cache lines.
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

// A 3-D ghosted block of kN x 1 x 1 owned cells with its ghost frame (3 x 3 rows of kN + 2
// values, `pitch` >= kN + 2 apart; both species in one buffer from a 64-byte boundary, so that
// with a pitch of whole lines all rows share one alignment).
struct Block {
  struct Species {
    double* p = nullptr;
    double& operator[](long i) const { return p[i]; }
    double* data() const { return p; }
  };
  double h = 0.5;
  long pitch;
  std::vector<double> store;
  Species u[2];
  long idx(int i, int dy, int dz) const { return (i + 1) + pitch * ((dy + 1) + 3 * (dz + 1)); }
  template <class F> explicit Block(F f, long row_pitch = kN + 2) : pitch(row_pitch) {
    store.assign(static_cast<size_t>(2 * 9 * pitch + 8), 0.0);
    double* base = store.data();
    while (reinterpret_cast<unsigned long>(base) % 64 != 0)
      ++base;
    for (int s = 0; s < 2; ++s) {
      u[s].p = base + s * 9 * pitch;
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int i = -1; i <= kN; ++i)
            u[s][idx(i, dy, dz)] = f(s, i * h, dy * h, dz * h);
    }
  }
};

const char* const kStencils[] = {"9pt", "19pt", "27pt"};
constexpr long kPadded = (kN + 2 + 7) / 8 * 8; // rows of whole 64-byte lines

struct BoxRows {
  RowStencil rows;
  BoxClasses classes;
  explicit BoxRows(const char* name, double h) {
    const double hh[3] = {h, h, h};
    Stencil st;
    EXPECT_TRUE(make_stencil(name, std::string(name) == "9pt" ? 2 : 3, hh, st));
    EXPECT_TRUE(to_rows(st, rows));
    EXPECT_TRUE(box_classes(rows, classes));
  }
};

// The Gray-Scott row of `len` cells (D 0.3 and 0.7, dt 0.01) with the stencil's taps and, by
// class, its class weights.
ExplicitRow gray_scott_row(const BoxRows& st, bool by_class, int len, const double* const* src,
                           double* const* dst, const double* floor, const double* p) {
  static const double D[2] = {0.3, 0.7};
  ExplicitRow a;
  a.n = len;
  a.src = src;
  a.w = st.rows.w.data();
  a.D = D;
  a.floor = floor;
  a.pconst = p;
  a.dt = 0.01;
  a.dst = dst;
  a.wclass = by_class ? st.classes.w.data() : nullptr;
  return a;
}

// Cells [i0, i0 + len) of the block's middle row through explicit_row<GS, NR, true, PR> (NR the
// stencil's rows: 3 or 9): by class (rows in classes.perm order) or by the general row form.
template <ParamRows PR, bool Wide = false>
void run_row(const Block& b, const BoxRows& st, bool by_class, const double* p, int i0, int len,
             std::vector<double> (&out)[2]) {
  const double* src[18];
  double* dst[2];
  const double floor[2] = {-INFINITY, -INFINITY};
  static std::vector<double> prows[3];
  const double* prow[3];
  for (int q = 0; q < 3; ++q) {
    prows[q].resize(kN);
    for (int i = 0; i < kN; ++i)
      prows[q][i] = p[q] * (1 + 0.1 * std::sin(0.3 * i + q));
    prow[q] = prows[q].data() + i0;
  }
  const int nr = st.rows.nrows;
  for (int s = 0; s < 2; ++s) {
    for (int r = 0; r < nr; ++r) {
      const int q = by_class ? st.classes.perm[r] : r;
      src[nr * s + r] = b.u[s].data() + b.idx(i0, st.rows.off[q][0], st.rows.off[q][1]);
    }
    out[s].resize(kN);
    dst[s] = out[s].data() + i0;
  }
  ExplicitRow a = gray_scott_row(st, by_class, len, src, dst, floor, p);
  a.prow = prow;
  if (nr == 3)
    explicit_row<GS, 3, true, PR, Wide>(a);
  else
    explicit_row<GS, 9, true, PR, Wide>(a);
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
  for (const char* name : kStencils) {
    const BoxRows st(name, b.h);
    const double lap = st.rows.nrows == 3 ? 6.0 : 5.0;
    std::vector<double> out[2];
    run_row<kScalarParams>(b, st, true, p, 0, kN, out);
    for (int s = 0; s < 2; ++s)
      for (int i = 0; i < kN; ++i) {
        const double u = b.u[s][b.idx(i, 0, 0)];
        const double expect = u + 0.01 * (s ? 0.7 : 0.3) * (1 + s) * lap;
        ASSERT_NEAR(out[s][i], expect, 1e-13 * std::fabs(u)) << name << " s " << s << " i " << i;
      }
  }
}

TEST(BoxClassKernel, MatchesTheGeneralRowFormWithReactionAndFieldParams) {
  const Block b(wave);
  const double p[3] = {0.04, 0.06, 1.0};
  for (const char* name : kStencils) {
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
  const double p[3] = {0.04, 0.06, 1.0};
  // Splits of the row as ranks (or the chunks of one call) would cut it.
  const std::vector<std::vector<int>> splits = {{0, kN},
                                                {0, 1, kN},
                                                {0, 100, kN},
                                                {0, kBoxChunk, kN},
                                                {0, 7, kBoxChunk + 9, kN - 3, kN},
                                                {0, 2, 5, 11, 12, 30, 47, kN}};
  // Both lane widths: the blocks of 4 or 8 cells (reaction in the lanes) against the chunks
  // (and the cells before an aligned start) wherever a cut moves a cell from one to the other.
  auto row = [&](bool wide, const Block& b, const BoxRows& st, int i0, int len,
                 std::vector<double>(&out)[2]) {
    if (wide)
      run_row<kScalarParams, true>(b, st, true, p, i0, len, out);
    else
      run_row<kScalarParams, false>(b, st, true, p, i0, len, out);
  };
  for (const bool wide : {false, true})
    for (const long pitch : {kN + 2L, kPadded})
      for (const char* name : kStencils) {
        const Block b(wave, pitch);
        const BoxRows st(name, b.h);
        std::vector<double> whole[2];
        row(wide, b, st, 0, kN, whole);
        for (const auto& cut : splits) {
          std::vector<double> pieces[2];
          for (size_t c = 0; c + 1 < cut.size(); ++c)
            row(wide, b, st, cut[c], cut[c + 1] - cut[c], pieces);
          for (int s = 0; s < 2; ++s)
            for (int i = 0; i < kN; ++i)
              ASSERT_EQ(whole[s][i], pieces[s][i])
                  << name << " s " << s << " i " << i << " pieces " << cut.size() - 1 << " pitch "
                  << pitch << " wide " << wide;
        }
      }
}

// box_row_diffusion (lane shifts on GCC, blocks of 4 or 8 lanes with an overlapping last block)
// against box_row_diffusion_cells (three profiles per cell, the same expressions): the same
// bits for every length, start and read limit xmax (tight: x0 + len; loose: the row's end).
template <int NR, bool Corners, bool Wide>
void expect_same_diffusion(const Block& b, const BoxRows& st) {
  const double* rows[NR];
  for (int r = 0; r < NR; ++r) {
    const int q = st.classes.perm[r];
    rows[r] = b.u[1].data() + b.idx(0, st.rows.off[q][0], st.rows.off[q][1]);
  }
  const double* w = st.classes.w.data();
  std::vector<double> vec(kN), ref(kN);
  for (int x0 : {0, 1, 5, 64})
    for (int len = 1; x0 + len <= kN && len <= 70; ++len)
      for (int xmax : {x0 + len, kN}) {
        box_row_diffusion<NR, Corners, Wide>(rows, w, x0, len, xmax, vec.data());
        box_row_diffusion_cells<NR, Corners>(rows, w, x0, len, ref.data());
        for (int t = 0; t < len; ++t)
          ASSERT_EQ(vec[t], ref[t]) << "x0 " << x0 << " len " << len << " xmax " << xmax << " t "
                                    << t << " wide " << Wide << " corners " << Corners;
      }
}

TEST(BoxClassKernel, LaneShiftsGiveTheBitsOfTheCellByCellProfiles) {
  const Block b(wave);
  for (const char* name : {"19pt", "27pt"}) {
    const BoxRows st(name, b.h);
    expect_same_diffusion<9, true, false>(b, st);
    expect_same_diffusion<9, true, true>(b, st);
    expect_same_diffusion<9, false, false>(b, st);
    expect_same_diffusion<9, false, true>(b, st);
  }
  const BoxRows st("9pt", b.h);
  expect_same_diffusion<3, false, false>(b, st);
  expect_same_diffusion<3, false, true>(b, st);
}

// The first x from which every row's vectors (loads from x - 1) are aligned, where the rows
// share one alignment; 0 where they do not, or where it would lie beyond the row.
TEST(BoxClassKernel, AlignedStartOfRowsSharingOneAlignment) {
  alignas(64) static double buf[4 * 64];
  for (int shift = 0; shift < 8; ++shift) {
    const double* rows[3] = {buf + 8 + shift, buf + 72 + shift, buf + 136 + shift};
    const int x = box_row_aligned_start<true>(rows, 3, 100);
    EXPECT_EQ(x, (9 - shift) % 8) << "shift " << shift;
    EXPECT_EQ(reinterpret_cast<unsigned long>(rows[0] + x - 1) % 64, 0u);
    EXPECT_EQ(box_row_aligned_start<false>(rows, 3, 100), (5 - shift % 4) % 4) << shift;
    EXPECT_EQ(box_row_aligned_start<true>(rows, 3, x), 0) << "beyond a row of x cells";
    const double* mixed[3] = {rows[0], rows[1] + 1, rows[2]};
    EXPECT_EQ(box_row_aligned_start<true>(mixed, 3, 100), 0);
  }
}

// One call over consecutive rows (ExplicitRow::rows, the explicit integrator's form for scalar
// parameters) gives the bits of one call per row: the block's 9 rows as a 2-D grid of pitch
// apart, 9pt by class, the 7 rows with both neighbours, each pitch.
TEST(BoxClassKernel, ACallOverSeveralRowsGivesTheBitsOfOneCallPerRow) {
  const double p[3] = {0.04, 0.06, 1.0}, floor[2] = {0.0, 0.0};
  for (const long pitch : {kN + 2L, kPadded}) {
    const Block b(wave, pitch);
    const BoxRows st("9pt", b.h);
    std::vector<double> multi[2], single[2];
    auto sweep = [&](int row0, int nrows, std::vector<double>(&out)[2]) {
      const double* src[6];
      double* dst[2];
      for (int s = 0; s < 2; ++s) {
        out[s].resize(static_cast<size_t>(7 * kN));
        for (int r = 0; r < 3; ++r) // the grid row row0 + dy of class-order row r
          src[3 * s + r] = b.u[s].data() + 1 + (row0 + st.rows.off[st.classes.perm[r]][0]) * pitch;
        dst[s] = out[s].data() + (row0 - 1) * kN;
      }
      ExplicitRow a = gray_scott_row(st, true, kN, src, dst, floor, p);
      a.rows = nrows;
      a.src_stride = pitch;
      a.dst_stride = kN;
      explicit_row<GS, 3, true, kScalarParams, true>(a);
    };
    sweep(1, 7, multi);
    for (int row = 1; row <= 7; ++row)
      sweep(row, 1, single);
    for (int s = 0; s < 2; ++s)
      for (size_t i = 0; i < multi[s].size(); ++i)
        ASSERT_EQ(multi[s][i], single[s][i]) << "s " << s << " cell " << i << " pitch " << pitch;
  }
}
