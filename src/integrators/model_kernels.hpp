// The kernels instantiated from one reaction model: the fused explicit row sweep for each
// stencil row layout and each form of the parameters (which of them are per-cell rows: every
// subset of the first kParamMaskBits parameters; a model with more parameters has two forms,
// all scalars or all rows), the general explicit path's update
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
#include <utility>

namespace morphogen {

using ExplicitRowFn = void (*)(const ExplicitRow&);

// Row layouts of the fused sweep (RowStencil): 5pt (3 star rows), 7pt (5 star rows),
// 9pt (3 box rows), 19pt and 27pt (9 box rows).
enum class RowLayout { Star3 = 0, Star5 = 1, Box3 = 2, Box9 = 3 };
constexpr int kRowLayouts = 4;

// Fused row kernels per parameter form: bit q of the index says parameter q is a row.
constexpr int kParamMaskBits = 3;
constexpr unsigned kParamMasks = 1u << kParamMaskBits;

// A model built at run time (models/runtime_model.hpp) has no fused kernels (fused = false:
// the explicit integrator takes its general path) and generic pre/reaction rows that call its
// kinetics (integrators/runtime_kernels.hpp).
struct ModelKernels {
  bool fused = true;
  // [wide][parameter mask][layout]; wide: the same rows compiled with 512-bit vectors
  ExplicitRowFn explicit_row[2][kParamMasks][kRowLayouts] = {};
  std::function<void(const ExplicitRow&)> explicit_pre[2]; // [field_params]
  ReactionRowFn reaction_row[2];                           // [field_params]

  // The fused kernel of a row stencil for the parameters whose bits field_mask sets (bit q:
  // parameter q varies per cell, ParamSet::field_mask; 0: all scalars); throws
  // std::logic_error for a layout without one (callers check the stencil first: there are no
  // null entries to call).
  ExplicitRowFn row_kernel(unsigned field_mask, int nrows, bool box, bool wide = false) const {
    const int idx = !box && nrows == 3   ? 0
                    : !box && nrows == 5 ? 1
                    : box && nrows == 3  ? 2
                    : box && nrows == 9  ? 3
                                         : -1;
    if (idx < 0 || !fused)
      throw std::logic_error("no fused explicit kernel for this stencil layout");
    const unsigned m = field_mask < kParamMasks ? field_mask : kParamMasks - 1;
    return explicit_row[wide ? 1 : 0][m][idx];
  }
};

// The parameter form of table entry Mask for model M: the mask itself where the model has at
// most kParamMaskBits parameters (bits beyond them dropped: one instantiation per form), else
// all scalars (0) or all rows.
template <class M, unsigned Mask> constexpr ParamRows param_form() {
  if constexpr (M::nparams <= kParamMaskBits)
    return ParamRows{Mask & ((1u << M::nparams) - 1u)};
  else
    return Mask == 0 ? kScalarParams : kAllParamRows;
}

// The explicit rows (integrators/kernels/<model>.cpp, no FMA contraction; the Wide copies in
// <model>_wide.cpp, compiled with 512-bit vectors) and the reaction rows
// (integrators/kernels/<model>_reaction.cpp, contracted: see CMakeLists.txt) of model M.
template <class M, bool Wide, unsigned Mask>
void explicit_row_layouts(ExplicitRowFn (&r)[kRowLayouts]) {
  constexpr ParamRows PR = param_form<M, Mask>();
  r[0] = &explicit_row<M, 3, false, PR, Wide>;
  r[1] = &explicit_row<M, 5, false, PR, Wide>;
  r[2] = &explicit_row<M, 3, true, PR, Wide>;
  r[3] = &explicit_row<M, 9, true, PR, Wide>;
}

template <class M, bool Wide> void explicit_row_kernels(ModelKernels& k) {
  ExplicitRowFn(&r)[kParamMasks][kRowLayouts] = k.explicit_row[Wide ? 1 : 0];
  [&r]<unsigned... Mask>(std::integer_sequence<unsigned, Mask...>) {
    (explicit_row_layouts<M, Wide, Mask>(r[Mask]), ...);
  }
  (std::make_integer_sequence<unsigned, kParamMasks>{});
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
