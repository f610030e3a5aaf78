// The reaction's explicit stability bound: forward Euler on du/dt = J u is stable for the
// eigenvalue lambda of J when |1 + dt lambda| <= 1, i.e. dt <= -2 Re(lambda) / |lambda|^2 for a
// decaying mode (Re(lambda) < 0; growing modes are the kinetics' own instability, not the
// scheme's). The diffusion bound alone misses stiff kinetics (Barkley, Oregonator fronts), so
// an explicit run warns when its dt exceeds the bound of the model's Jacobian at the initial
// state.
#pragma once

#include "app/simulation.hpp"

#include <array>

namespace morphogen {

struct ReactionBound {
  double dt = 0;                       // the bound (infinity: no decaying mode)
  std::array<PetscInt, 3> cell{};      // the cell that sets it
  double lambda_re = 0, lambda_im = 0; // its eigenvalue
};

// Collective: the smallest bound over the owned cells of the current state (per-cell
// parameters included). Exact for 2-species models; infinity for others (not estimated).
ReactionBound reaction_dt_bound(const Simulation& sim);

// Collective: with -integrator explicit, prints one warning line on rank 0 when sim.dt()
// exceeds reaction_dt_bound(sim).
void warn_if_reaction_stiff(const Simulation& sim);

} // namespace morphogen
