// Temporal blocking of the explicit integrator (-explicit_fuse_steps k): N steps taken in
// passes of up to k fused steps (Simulation::advance) give bitwise the same state as N single
// steps (Simulation::step), for k = 2, 3, 8, N not a multiple of k, passes of mixed lengths,
// the 5- and 9-point stencils, Turing (scalar and per-cell parameters) and Gray-Scott, and a halo
// wider than a neighbour's extent (k = 8 on a small grid), owned rows read in place (wide rows).
// Compared with memcmp on rank 0; the
// verdict is reduced over all ranks. Unsupported configurations fall back to one step per pass.
#include "../mpi_expect.hpp"
#include "../sim_fixture.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

// N steps in passes of the given lengths (cycled), each at most the simulation's fuse_steps().
std::vector<std::vector<double>> run_passes(OptionList opts, int k, int steps,
                                            const std::vector<int>& passes) {
  opts.push_back({"explicit_fuse_steps", std::to_string(k)});
  auto sim = make_sim(PETSC_COMM_WORLD, opts);
  EXPECT_EQ(sim->fuse_steps(), k);
  for (int n = 0, p = 0; n < steps; ++p) {
    const int len = std::min({passes[p % passes.size()], steps - n, k});
    sim->advance(len);
    n += len;
  }
  EXPECT_EQ(sim->step_index(), steps);
  std::vector<std::vector<double>> out;
  for (auto& v : sim->state())
    out.push_back(gather_all(sim->grid(), v));
  return out;
}

bool same_as_single_steps(const OptionList& opts, int k, int steps, std::vector<int> passes) {
  const auto ref = run_passes(opts, 1, steps, {1});
  if (passes.empty()) passes = {k};
  const auto fused = run_passes(opts, k, steps, passes);
  bool ok = ref.size() == fused.size();
  for (size_t s = 0; ok && s < ref.size(); ++s) {
    const bool same = ref[s].size() == fused[s].size() &&
                      std::memcmp(ref[s].data(), fused[s].data(), ref[s].size() * 8) == 0;
    EXPECT_TRUE(same) << "species " << s << " differs with k = " << k;
    ok = ok && same;
    if (!ref[s].empty()) { // the run must have evolved a non-uniform field
      const auto [mn, mx] = std::minmax_element(ref[s].begin(), ref[s].end());
      EXPECT_GT(*mx - *mn, 1e-6);
    }
  }
  return all_ranks(ok);
}

const OptionList kTuring = {{"grid_n", "45,38"},
                            {"params_alpha", "12"},
                            {"params_beta", "16"},
                            {"init_a", "4 +- 1%"},
                            {"dt", "0.5"}};

OptionList gray_scott(const char* n, const char* stencil) {
  return {{"model", "gray_scott"},
          {"grid_n", n},
          {"grid_L", "2.5"},
          {"stencil", stencil},
          {"init_a", "0.25 +- 20%"},
          {"init_b", "0.5 +- 20%"},
          {"dt", "1"}};
}

} // namespace

TEST(FusedSteps, Turing5ptK2AndK3) {
  EXPECT_TRUE(same_as_single_steps(kTuring, 2, 61, {}));
  EXPECT_TRUE(same_as_single_steps(kTuring, 3, 61, {}));
}

TEST(FusedSteps, TuringGaussianFieldParams) { // per-cell parameters, as input/turing_spots.yaml
  OptionList o = kTuring;
  o[1] = {"params_alpha", "12 +- 0.1% gauss"};
  o[2] = {"params_beta", "16 +- 0.1% gauss"};
  EXPECT_TRUE(same_as_single_steps(o, 4, 45, {4, 3}));
}

TEST(FusedSteps, Turing9ptMixedPasses) {
  OptionList o = kTuring;
  o.push_back({"stencil", "9pt"});
  EXPECT_TRUE(same_as_single_steps(o, 3, 50, {3, 1, 2, 3, 2}));
}

TEST(FusedSteps, GrayScott9ptK4) {
  EXPECT_TRUE(same_as_single_steps(gray_scott("40,40", "9pt"), 4, 43, {}));
}

// Owned rows of at least FusedSweep::kInPlaceMin cells (here 512 .. 2048 on 1, 2 or 4 ranks) are
// read in place by the first fused step, in three calls per row (strips, owned middle, strips);
// rows split into tiles (-explicit_fuse_tile) give the same bits.
TEST(FusedSteps, WideRowsReadInPlace) {
  for (const char* st : {"9pt", "5pt"}) {
    OptionList g = gray_scott("2048,24", st);
    g[2] = {"grid_L", "51.2,0.6"}; // equal spacings
    EXPECT_TRUE(same_as_single_steps(g, st[0] == '9' ? 4 : 8, 23, {4, 3, 8, 5}));
  }
  for (const char* tile : {"50", "7"}) { // several tiles per row, also narrower than k
    OptionList g = gray_scott("2048,24", "9pt");
    g[2] = {"grid_L", "51.2,0.6"};
    g.push_back({"explicit_fuse_tile", tile});
    EXPECT_TRUE(same_as_single_steps(g, 8, 19, {8, 3}));
  }
  OptionList o = kTuring;
  o[0] = {"grid_n", "2048,24"};
  o[1] = {"params_alpha", "12 +- 0.1% gauss"};
  EXPECT_TRUE(same_as_single_steps(o, 3, 20, {}));
  o.push_back({"explicit_fuse_tile", "40"}); // per-cell parameters read per tile
  EXPECT_TRUE(same_as_single_steps(o, 3, 20, {}));
}

// In place (-explicit_in_place yes, the default where a rank's state is large): a pass writes the
// state it reads; the columns left of each tile are saved first. Wide rows in one and in many
// tiles (narrower than k too), narrow rows, per-cell parameters, k = 2 (the shortest pass that
// may run in place).
TEST(FusedSteps, InPlacePasses) {
  for (const char* tile : {"0", "50", "7"}) {
    OptionList g = gray_scott("2048,24", "9pt");
    g[2] = {"grid_L", "51.2,0.6"};
    g.push_back({"explicit_fuse_tile", tile});
    g.push_back({"explicit_in_place", "yes"});
    EXPECT_TRUE(same_as_single_steps(g, 8, 19, {8, 3, 2}));
  }
  OptionList o = kTuring;
  o[0] = {"grid_n", "1100,20"};
  o[1] = {"params_alpha", "12 +- 0.1% gauss"};
  o.push_back({"explicit_in_place", "yes"});
  o.push_back({"explicit_fuse_tile", "130"});
  EXPECT_TRUE(same_as_single_steps(o, 2, 21, {}));
  OptionList narrow = gray_scott("40,40", "9pt");
  narrow.push_back({"explicit_in_place", "yes"});
  narrow.push_back({"explicit_fuse_tile", "9"});
  EXPECT_TRUE(same_as_single_steps(narrow, 4, 43, {}));
  OptionList tiny = gray_scott("12,12", "5pt");
  tiny.push_back({"explicit_in_place", "yes"});
  EXPECT_TRUE(same_as_single_steps(tiny, 8, 29, {8, 5}));
}

// -explicit_fuse_steps 0 (the default): 8 where fused steps apply and the state averages at
// least 8 MiB per rank (2048 x 1024 cells of 2 species: 32 MiB, on 1, 2 or 4 ranks), else 1.
TEST(FusedSteps, AutomaticDepth) {
  auto depth = [](OptionList o) {
    o.push_back({"explicit_fuse_steps", "0"});
    return make_sim(PETSC_COMM_WORLD, o)->fuse_steps();
  };
  OptionList big = gray_scott("2048,1024", "9pt");
  big[2] = {"grid_L", "128,64"}; // the spacing of gray_scott("40,40")
  EXPECT_EQ(depth(big), 8);
  OptionList neumann = big;
  neumann.push_back({"grid_bc", "neumann"});
  EXPECT_EQ(depth(neumann), 1);
  EXPECT_EQ(depth(gray_scott("256,256", "9pt")), 1);
}

TEST(FusedSteps, HaloWiderThanNeighbours) { // W = 8 cells, owned extents 6..12
  EXPECT_TRUE(same_as_single_steps(gray_scott("12,12", "5pt"), 8, 29, {8, 5}));
}

TEST(FusedSteps, UnsupportedFallsBackToOne) {
  OptionList o = kTuring;
  o.push_back({"grid_bc", "neumann"});
  o.push_back({"explicit_fuse_steps", "4"});
  auto sim = make_sim(PETSC_COMM_WORLD, o);
  EXPECT_EQ(sim->fuse_steps(), 1);
}
