// The kernels instantiated from one reaction model: the fused explicit row sweep for each
// stencil row layout and for scalar or per-cell parameters, the general explicit path's update
// (diffusion precomputed) and the split integrator's per-cell reaction substep (the lockstep
// Newton of reaction_lockstep_kernel.hpp). Each model's
// explicit and reaction rows are instantiated in their own translation units
// (integrators/kernels/<model>.cpp and <model>_reaction.cpp, declared `extern template` here),
// so adding a kernel variant does not grow one file's compile time.
#pragma once

#include "integrators/explicit_kernel.hpp"
#include "integrators/reaction_kernel.hpp"
#include "integrators/reaction_lockstep_kernel.hpp"
#include "integrators/split_integrator.hpp"
#include "models/all_models.hpp"

#include <functional>
#include <stdexcept>

namespace morphogen {

using ExplicitRowFn = void (*)(const ExplicitRow&);

// Row layouts of the fused sweep (RowStencil): 5pt (3 star rows), 7pt (5 star rows),
// 9pt (3 box rows), 19pt and 27pt (9 box rows).
enum class RowLayout { Star3 = 0, Star5 = 1, Box3 = 2, Box9 = 3 };
constexpr int kRowLayouts = 4;

// A model built at run time (models/runtime_model.hpp) has no fused kernels (fused = false:
// the explicit integrator takes its general path) and generic pre/reaction rows that call its
// kinetics (integrators/runtime_kernels.hpp).
struct ModelKernels {
  bool fused = true;
  // [wide][field_params][layout]; wide: the same rows compiled with 512-bit vectors
  ExplicitRowFn explicit_row[2][2][kRowLayouts] = {};
  std::function<void(const ExplicitRow&)> explicit_pre[2]; // [field_params]
  ReactionRowFn reaction_row[2];                           // [field_params]

  // The fused kernel of a row stencil; throws std::logic_error for a layout without one
  // (callers check the stencil first: there are no null entries to call).
  ExplicitRowFn row_kernel(bool field_params, int nrows, bool box, bool wide = false) const {
    const int idx = !box && nrows == 3   ? 0
                    : !box && nrows == 5 ? 1
                    : box && nrows == 3  ? 2
                    : box && nrows == 9  ? 3
                                         : -1;
    if (idx < 0 || !fused)
      throw std::logic_error("no fused explicit kernel for this stencil layout");
    return explicit_row[wide ? 1 : 0][field_params ? 1 : 0][idx];
  }
};

// The explicit rows (integrators/kernels/<model>.cpp, no FMA contraction; the Wide copies in
// <model>_wide.cpp, compiled with 512-bit vectors) and the reaction rows
// (integrators/kernels/<model>_reaction.cpp, contracted: see CMakeLists.txt) of model M.
template <class M, bool Wide> void explicit_row_kernels(ModelKernels& k) {
  ExplicitRowFn(&r)[2][kRowLayouts] = k.explicit_row[Wide ? 1 : 0];
  r[0][0] = &explicit_row<M, 3, false, false, Wide>;
  r[0][1] = &explicit_row<M, 5, false, false, Wide>;
  r[0][2] = &explicit_row<M, 3, true, false, Wide>;
  r[0][3] = &explicit_row<M, 9, true, false, Wide>;
  r[1][0] = &explicit_row<M, 3, false, true, Wide>;
  r[1][1] = &explicit_row<M, 5, false, true, Wide>;
  r[1][2] = &explicit_row<M, 3, true, true, Wide>;
  r[1][3] = &explicit_row<M, 9, true, true, Wide>;
}

template <class M> void explicit_kernels(ModelKernels& k) {
  explicit_row_kernels<M, false>(k);
  explicit_row_kernels<M, true>(k);
  k.explicit_pre[0] = &explicit_row_pre<M, false>;
  k.explicit_pre[1] = &explicit_row_pre<M, true>;
}

template <class M> void reaction_kernels(ModelKernels& k) {
  k.reaction_row[0] = &reaction_row_lockstep<M, false>; // 2-3 species: lockstep Newton
  k.reaction_row[1] = &reaction_row_lockstep<M, true>;
}

template <class M> ModelKernels model_kernels() {
  ModelKernels k{};
  explicit_kernels<M>(k);
  reaction_kernels<M>(k);
  return k;
}

extern template void explicit_kernels<models::Turing>(ModelKernels&);
extern template void explicit_row_kernels<models::Turing, false>(ModelKernels&);
extern template void explicit_row_kernels<models::Turing, true>(ModelKernels&);
extern template void reaction_kernels<models::Turing>(ModelKernels&);
extern template void explicit_kernels<models::GrayScott>(ModelKernels&);
extern template void explicit_row_kernels<models::GrayScott, false>(ModelKernels&);
extern template void explicit_row_kernels<models::GrayScott, true>(ModelKernels&);
extern template void reaction_kernels<models::GrayScott>(ModelKernels&);
extern template void explicit_kernels<models::GrayScottSims>(ModelKernels&);
extern template void explicit_row_kernels<models::GrayScottSims, false>(ModelKernels&);
extern template void explicit_row_kernels<models::GrayScottSims, true>(ModelKernels&);
extern template void reaction_kernels<models::GrayScottSims>(ModelKernels&);
extern template void explicit_kernels<models::Brusselator>(ModelKernels&);
extern template void explicit_row_kernels<models::Brusselator, false>(ModelKernels&);
extern template void explicit_row_kernels<models::Brusselator, true>(ModelKernels&);
extern template void reaction_kernels<models::Brusselator>(ModelKernels&);
extern template void explicit_kernels<models::GiererMeinhardt>(ModelKernels&);
extern template void explicit_row_kernels<models::GiererMeinhardt, false>(ModelKernels&);
extern template void explicit_row_kernels<models::GiererMeinhardt, true>(ModelKernels&);
extern template void reaction_kernels<models::GiererMeinhardt>(ModelKernels&);
extern template void explicit_kernels<models::Meinhardt>(ModelKernels&);
extern template void explicit_row_kernels<models::Meinhardt, false>(ModelKernels&);
extern template void explicit_row_kernels<models::Meinhardt, true>(ModelKernels&);
extern template void reaction_kernels<models::Meinhardt>(ModelKernels&);
extern template void explicit_kernels<models::Schnakenberg>(ModelKernels&);
extern template void explicit_row_kernels<models::Schnakenberg, false>(ModelKernels&);
extern template void explicit_row_kernels<models::Schnakenberg, true>(ModelKernels&);
extern template void reaction_kernels<models::Schnakenberg>(ModelKernels&);
extern template void explicit_kernels<models::FitzHughNagumo>(ModelKernels&);
extern template void explicit_row_kernels<models::FitzHughNagumo, false>(ModelKernels&);
extern template void explicit_row_kernels<models::FitzHughNagumo, true>(ModelKernels&);
extern template void reaction_kernels<models::FitzHughNagumo>(ModelKernels&);
extern template void explicit_kernels<models::Barkley>(ModelKernels&);
extern template void explicit_row_kernels<models::Barkley, false>(ModelKernels&);
extern template void explicit_row_kernels<models::Barkley, true>(ModelKernels&);
extern template void reaction_kernels<models::Barkley>(ModelKernels&);
extern template void explicit_kernels<models::BarkleyTurbulent>(ModelKernels&);
extern template void explicit_row_kernels<models::BarkleyTurbulent, false>(ModelKernels&);
extern template void explicit_row_kernels<models::BarkleyTurbulent, true>(ModelKernels&);
extern template void reaction_kernels<models::BarkleyTurbulent>(ModelKernels&);
extern template void explicit_kernels<models::Oregonator>(ModelKernels&);
extern template void explicit_row_kernels<models::Oregonator, false>(ModelKernels&);
extern template void explicit_row_kernels<models::Oregonator, true>(ModelKernels&);
extern template void reaction_kernels<models::Oregonator>(ModelKernels&);

} // namespace morphogen
