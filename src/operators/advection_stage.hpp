// Advection -(u . grad) A of chosen species by semi-Lagrangian back-tracing (stable-ARD paper
// eqs. 18-20): a stage run after each integrator step (reaction and diffusion give the
// intermediate state A~, eq. 19; the stage sets A^{n+1}(x_c) = A~(X) with X the departure
// point, see advection_kernel.hpp). Unconditionally stable: any dt whose back-trace fits the
// halo is accepted.
//
// Parallel: the advected species are read through a wide halo (grid/wide_halo.hpp) of W cells,
// W = ceil(C) + 1 (linear) or + 2 (cubic) with C = max_d max|u_d| dt / h_d, created once (or
// -advection_halo W), at most kMaxHalo. A dt (or, for a velocity using t, a later velocity)
// whose back-trace would need more than the halo is refused with a one-line UserError. Every
// cell's departure point and interpolation use global indices only: results are bitwise the
// same on any rank count.
//
// The velocity is evaluated on the wide box once (steady) or once per step at the step's
// midpoint t + dt/2 (velocity using t); departure points of a steady velocity are computed once
// per dt and reused. A velocity read from files (fields/velocity_file.hpp) is taken like an
// expression: once (one file) or per step at t + dt/2 (a series, linear in t between frames),
// each rank's owned cells spread through the wide halo; the halo is sized from the largest
// speed over all frames. A velocity computed by the run (VelocitySource: the stable-fluids solver)
// is instead spread from its owned cells through the same wide halo at every step (its state
// at the end of the fluid's step), its reach checked and its departure points recomputed.
#pragma once

#include "fields/velocity_field.hpp"
#include "fields/velocity_file.hpp"
#include "grid/wide_halo.hpp"
#include "operators/advection_kernel.hpp"
#include "operators/velocity_source.hpp"

#include <memory>
#include <string>
#include <vector>

namespace morphogen {

struct AdvectionSettings {
  static constexpr int kMaxHalo = 64; // cells: bounds the wide halo's memory and traffic
  std::vector<int> species;           // indices of the advected species
  std::vector<std::string> names;     // their names (messages, banner)
  advect::Interp interp = advect::Interp::Linear;
  advect::Backtrace backtrace = advect::Backtrace::Rk2;
  int halo = 0; // halo width in cells; 0: sized from the velocity at the start
};

class AdvectionStage {
public:
  // Collective; throws UserError when dt's back-trace does not fit the halo.
  AdvectionStage(const Grid& grid, std::unique_ptr<VelocityField> velocity,
                 AdvectionSettings settings, double dt);
  // The velocity read from files (halo sized from their largest speed). Collective.
  AdvectionStage(const Grid& grid, std::unique_ptr<VelocityFile> file, AdvectionSettings settings,
                 double dt);
  // The velocity of `source` (which outlives the stage), read at every apply(). Collective.
  AdvectionStage(const Grid& grid, const VelocitySource& source, AdvectionSettings settings,
                 double dt);

  const AdvectionSettings& settings() const { return set_; }
  int halo() const { return wide_->width(); }
  // Largest Courant number max_d max|u_d| dt / h_d at the last check.
  double courant() const { return courant_; }
  // Transport the advected species of u (ghosted local arrays whose owned cells are current)
  // over [t, t + dt]; owned cells are updated, ghosts are left stale. Collective.
  void apply(std::vector<VecH>& u, double t, double dt);
  // Velocity component d at the owned cells (owned layout, x fastest) at the last evaluated time.
  void owned_velocity(int d, double* out) const;
  // One line for the run banner.
  std::string describe() const;

private:
  void setup(const std::array<double, 3>& umax, double dt);
  void load_velocity(double t);
  void check_reach(double dt, double t);
  void spread_owned(const std::vector<double>& owned, double* wide);
  void compute_departures(double dt);
  void transport(Vec v);

  const Grid& grid_;
  std::unique_ptr<VelocityField> velocity_; // expressions (null with a source or a file)
  std::unique_ptr<VelocityFile> file_;      // files (null otherwise)
  const VelocitySource* source_ = nullptr;  // a velocity computed by the run
  AdvectionSettings set_;
  std::unique_ptr<WideHalo> wide_;
  advect::WideGeom geom_;
  std::array<std::vector<double>, 3> u_; // velocity on the wide box
  std::vector<double> w_;                // a species on the wide box
  std::vector<double> owned_, local_;    // a file velocity component: owned, ghosted layout
  std::vector<double> dep_;              // departure point of each owned cell (3 per cell)
  double dep_dt_ = -1.0;                 // dt of dep_ (< 0: stale)
  double checked_dt_ = -1.0;             // dt whose reach was checked (steady velocity)
  double courant_ = 0;
};

} // namespace morphogen
