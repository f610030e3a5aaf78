// A run's right-hand side as a list of terms over the species fields:
//
//   du_s/dt = sum_k T_k,s(u, x, t),   then the constraints (clamp floor, pinned cells)
//
// Each term states what it reads (halo: width and star or box), a collective stable-dt
// estimate for an explicit step, whether it is linear in the state (then the implicit
// integrators assemble it: operators/operator_matrices.hpp), and adds its rates on the owned
// cells. Integrators consume the list (integrators/integrator.hpp); the explicit integrator
// keeps its fused sweeps for diffusion + reaction and evaluates every other term through
// add_rates.
//
// Arrays: species s at cell c is state.u[s][state.stride * c], with c the grid's ghosted local
// index (Grid::local_index); rates are in the owned layout (Grid::owned_index) with their own
// stride. A stride of 1 is one Vec per species; a stride of nspecies is an interlaced
// multi-component Vec (the TS integrator's DM).
#pragma once

#include "grid/grid.hpp"

#include <limits>
#include <string>
#include <vector>

namespace morphogen {

struct HaloNeed {
  int width = 0;    // ghost layers read (0: pointwise)
  bool box = false; // ghost corners read (cross terms)
};

struct StateArrays {
  std::vector<const double*> u; // per species, ghosted local layout
  PetscInt stride = 1;
  double at(size_t s, PetscInt c) const { return u[s][stride * c]; }
};

struct RateArrays {
  std::vector<double*> r; // per species, owned layout (accumulated into)
  PetscInt stride = 1;
  double& at(size_t s, PetscInt o) const { return r[s][stride * o]; }
};

class Term {
public:
  enum class Kind { Diffusion, Reaction, Source, Other };
  virtual ~Term() = default;

  virtual Kind kind() const = 0;
  // What the term is, for messages and -help ("diffusion of a (tensor, second order)").
  virtual std::string describe() const = 0;
  virtual HaloNeed halo() const { return {}; }
  // Largest stable forward-Euler step for this term alone (inf: no limit). Collective.
  virtual double stable_dt() const { return std::numeric_limits<double>::infinity(); }
  // True when the term is linear in the state (an implicit integrator may assemble it).
  virtual bool linear() const { return false; }
  // True when the rates depend on t (time-dependent sources or parameters).
  virtual bool uses_time() const { return false; }
  // Solution-dependent coefficients (polar a(theta), gradient-shaped tensors): recompute them
  // from the species state u (ghosted local vectors, owned cells current; ghosts not needed).
  // The explicit integrator calls it every step, the split and TS integrators at the start of
  // each step (lagged). Returns true when the term changed (its matrix must be re-assembled).
  // Collective.
  virtual bool refresh(const std::vector<VecH>& /*u*/) const { return false; }
  // True when the term's coefficients depend on t (a diffusion coefficient or tensor using t).
  virtual bool timed_coefficients() const { return false; }
  // Time-dependent coefficients: evaluate them at t (the explicit integrator at the step's
  // start, the split integrator at the diffusion substep's midpoint, TS at its stage times).
  // Returns true when they changed (the matrix must be re-assembled). Collective.
  virtual bool set_time(double /*t*/) const { return false; }
  // rates += T(state, t) on this rank's owned cells (state ghosts current when halo().width > 0).
  virtual void add_rates(const StateArrays& state, double t, const RateArrays& rates) const = 0;
};

// A constraint acting on the state after a step or substep (clamp floor, pinned cells).
class Constraint {
public:
  virtual ~Constraint() = default;
  virtual std::string describe() const = 0;
  // Project the owned cells of the ghosted local state vectors; returns the values changed.
  virtual PetscInt apply(std::vector<VecH>& u) const = 0;
};

} // namespace morphogen
