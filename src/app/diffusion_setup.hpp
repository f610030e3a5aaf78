// Per-species diffusion from the options database:
//
//   -diffusion iso|tensor|polar|shaped, -diffusion_S ...  (all species / species S; default iso;
//                       polar and shaped: app/state_diffusion_setup.hpp)
//   -D_S VALUE          D_s: a number, or any value (expression, 'v +- a%', png(...)) for a
//                       diffusion map; the tensor is multiplied by it. D_s and the tensor
//                       values may use t (then an IsotropicField or tensor operator whose
//                       coefficients are re-evaluated per step: operators/timed_diffusion.hpp;
//                       not with polar|shaped)
//   -tensor_scheme second_order|first_order
//   tensor of species S, keys -tensor_S_NAME, else the shared -tensor_NAME:
//     2-D  theta, l1, l2  (sigma = R(theta)^T diag(l1, l2) R(theta): l1 along (cos, sin) theta)
//          or xx, xy, yy  (components)
//     3-D  theta, phi, l1, l2, l3: l1 along e1 = (cos theta sin phi, sin theta sin phi, cos phi),
//          l2 along e2 = (-sin theta, cos theta, 0), l3 along e1 x e2 (phi defaults to pi/2)
//          or xx, xy, xz, yy, yz, zz
//   every one a value (number or expression of x, y, z, ...), angles in radians.
// The tensor must be positive definite at every cell; the error names the keys, the cell and
// the values.
#pragma once

#include "core/options.hpp"
#include "grid/halo.hpp"
#include "models/model.hpp"
#include "operators/diffusion_operator.hpp"
#include "operators/state_diffusion.hpp"
#include "operators/timed_diffusion.hpp"

#include <cstdint>
#include <memory>
#include <string>

namespace morphogen {

// -diffusion_S resolved for species `name`: true when its operator reads the ghost corners
// (tensor, shaped; polar and shaped: app/state_diffusion_setup.hpp).
bool read_tensor_choice(Options& opt, const std::string& name);

struct DiffusionSetup {
  std::unique_ptr<DiffusionOperator> op;
  // Solution-dependent coefficients (-diffusion_S polar|shaped: app/state_diffusion_setup.hpp),
  // else null.
  std::unique_ptr<CoefficientRule> rule;
  // Coefficients using t (-D_S or a tensor value with t): fills the op's arrays at a time
  // (operators/timed_diffusion.hpp), else null; components: their count.
  TimedDiffusionTerm::Fill timed;
  int components = 0;
  double D_mean = 0; // spatial mean of D_s (times the mean tensor's trace / dim)
};

// Build species `si`'s operator. `tensor` from read_tensor_choice. Collective.
DiffusionSetup read_diffusion(Options& opt, const Grid& grid, const Halo& halo,
                              const Stencil& stencil, const SpeciesInfo& si, bool tensor,
                              std::uint64_t seed, const std::string& base_dir);

} // namespace morphogen
