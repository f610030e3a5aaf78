// The reaction's explicit stability bound: forward Euler on du/dt = J u is stable for the
// eigenvalue lambda of J when |1 + dt lambda| <= 1, i.e. dt <= -2 Re(lambda) / |lambda|^2 for a
// decaying mode (Re(lambda) < 0; growing modes are the kinetics' own instability, not the
// scheme's). The diffusion bound alone misses stiff kinetics (Barkley, Oregonator fronts), so
// an explicit run warns when its dt exceeds the bound of the model's Jacobian at the initial
// state.
#pragma once

#include "app/simulation.hpp"

#include <array>
#include <functional>
#include <limits>

namespace morphogen {

// The forward-Euler bound of one Jacobian.
struct EigenBound {
  double dt;                           // min -2 Re / |lambda|^2 over Re(lambda) < 0 (inf: none)
  double lambda_re = 0, lambda_im = 0; // the eigenvalue that sets it (lambda_im >= 0)
};

// The bound of the n x n Jacobian J (row-major, J[r*n+c] = dR_r/du_c), 1 <= n <= 64. n = 2 uses
// the closed form unless `general`; every other n (and n = 2 with `general`) takes the
// eigenvalues from LAPACK's dgeev (analysis::eigenvalues). Non-finite J or a failed QR: inf.
EigenBound euler_bound(int n, const double* J, bool general = false);

// The smallest bound over cells 0..cells-1. key(c, v) writes the nkey values that determine
// cell c's Jacobian (its state and parameters), jac(c, J) the Jacobian (n*n values). The keys
// are deduplicated (bitwise) and the Jacobian and its bound are evaluated once per distinct key,
// up to max_eigen distinct keys. Beyond that (a perturbed parameter or state makes every cell
// distinct): n <= 2 evaluate every cell (closed forms, exact); larger n every s-th cell,
// s = ceil(cells / max_eigen) (a sample: a stiffer cell between the samples can be missed, and
// the sample depends on the decomposition). max_eigen 0: max(1024, 2^19 / max(n, 2)^3)
// (n = 3: 19,418; measured at 1024^2 cells on one rank, every cell distinct: ~25 ms).
struct CellsBound {
  EigenBound bound{std::numeric_limits<double>::infinity()};
  long long cell = -1;     // the cell that sets it (-1: none)
  long long distinct = 0;  // distinct keys found (at most max_eigen + 1)
  long long evaluated = 0; // Jacobians evaluated
  long long stride = 1;    // > 1: only every stride-th cell was evaluated
};
CellsBound min_euler_bound(int n, long long cells, int nkey,
                           const std::function<void(long long cell, double* key)>& key,
                           const std::function<void(long long cell, double* J)>& jac,
                           long long max_eigen = 0);

struct ReactionBound {
  double dt = 0;                       // the bound (infinity: no decaying mode)
  std::array<PetscInt, 3> cell{};      // the cell that sets it
  double lambda_re = 0, lambda_im = 0; // its eigenvalue
  long long stride = 1;                // > 1 on some rank: a sample of every stride-th cell
};

// Collective: the smallest bound over the owned cells of the current state (per-cell
// parameters included), for any number of species (min_euler_bound per rank; stride is the
// largest over the ranks).
ReactionBound reaction_dt_bound(const Simulation& sim);

// Collective: with -integrator explicit, prints one warning line on rank 0 when sim.dt()
// exceeds reaction_dt_bound(sim).
void warn_if_reaction_stiff(const Simulation& sim);

} // namespace morphogen
