// 2-D incompressible stable fluids (Stam 1999; the stable-ARD paper section 5 and Figs. 5-6) on
// the run's DMDA: velocity (u, v) at cell centres, one step of dt (in `substeps` parts) is
//   1. self-advection   u* = u^n(X), X the semi-Lagrangian departure point (rk2 back-trace,
//                        advection_kernel.hpp) read through a wide halo sized from max|u| dt/h;
//   2. viscosity        (I - dt nu L) u** = u* per component (KSP, prefix fluid_visc_: CG with
//                        Jacobi), walls by the ghost rule u_ghost = 2 g - u_c;
//   3. projection       A p = -div(u_f) on the face velocities u_f (fluid_kernel.hpp), KSP
//                        prefix fluid_: CG with GAMG (any -fluid_ksp_*/-fluid_pc_* overrides),
//                        then u_f -= G p (discretely divergence-free up to the KSP residual)
//                        and the cell velocities by the mean face gradient (approximate
//                        projection).
// Boundaries (fluid::Kind): cavity (no-slip walls, lid speed U on the top wall y = L), channel
// (inflow U from the left, outflow on the right, free-slip bottom and top) or periodic (needs a
// periodic grid). Cells of the solid mask are obstacles: zero velocity, no-slip faces.
// Explicit parts use global indices only (bitwise rank-independent); the solves agree across
// rank counts to their tolerance.
#pragma once

#include "grid/halo.hpp"
#include "grid/wide_halo.hpp"
#include "operators/advection_kernel.hpp"
#include "operators/fluid_kernel.hpp"
#include "operators/velocity_source.hpp"

#include "operators/spectral_solver.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace morphogen {

struct FluidSettings {
  fluid::Kind kind = fluid::Kind::Cavity;
  double viscosity = 0.01; // nu
  double lid = 1.0;        // cavity: speed of the top wall
  double inflow = 1.0;     // channel: inflow speed on the left
  int substeps = 1;
  advect::Interp interp = advect::Interp::Linear; // self-advection interpolation
  std::string option_text = "-fluid cavity";      // for messages
};

class FluidSolver : public VelocitySource {
public:
  // solid: one value per owned cell (x fastest), > 0.5 marks an obstacle cell. Collective.
  FluidSolver(const Grid& grid, FluidSettings settings, const std::vector<double>& solid);
  ~FluidSolver() override;
  FluidSolver(const FluidSolver&) = delete;
  FluidSolver& operator=(const FluidSolver&) = delete;

  const FluidSettings& settings() const { return set_; }
  // Advance the velocity over dt (settings().substeps parts). Collective.
  void step(double dt);
  // Set the velocity at the owned cells from f(x, y) -> (u, v) at the cell centres.
  void set_velocity(const std::function<void(double, double, double&, double&)>& f);
  // Project the current velocity (step 3 alone). Collective.
  void project();

  // ||div u_f||_2 after the last projection over ||div u_f||_2 before it (fluid cells).
  double divergence_ratio() const { return div_ratio_; }
  PetscInt poisson_iterations() const { return poisson_its_; }
  PetscInt total_poisson_iterations() const { return total_poisson_its_; }
  bool solid(PetscInt i, PetscInt j) const;

  Vec component(int d) const override { return u_[d]; }
  // True when the pressure / the viscosity is solved exactly by FFT/DCT/DST
  // (operators/spectral_solver.hpp).
  bool spectral_pressure() const { return spectral_pois_ != nullptr; }
  bool spectral_viscosity() const { return spectral_visc_[0] && spectral_visc_[1]; }
  // "cavity", "channel" or "periodic".
  std::string kind_name() const;
  // The state a restart needs for a bitwise continuation, as ghosted local Vecs (owned cells
  // current): velocity_x, velocity_y and fluid_pressure (the last projection's pressure, the
  // initial guess of the next pressure solve). Written into checkpoints; after a restart has
  // overwritten their owned cells, call state_restored(). Collective.
  std::vector<std::pair<std::string, Vec>> state() const;
  void state_restored();
  // Grid sequencing: this flow from that of a grid half as fine per axis (same domain):
  // velocity and pressure prolonged cell-centred, solids zeroed, then projected. Collective.
  void prolong_from(FluidSolver& coarse);
  double speed_bound() const override;
  std::string option_text() const override { return set_.option_text; }
  std::string describe() const override;

private:
  void substep(double h);
  void advect_velocity(double h);
  void diffuse(double h);
  void assemble_viscous(double h);
  void assemble_poisson();
  void configure_ksp(KSP* ksp, const char* prefix, bool poisson);
  // The face on side s (-1, +1) of axis d of owned cell (i, j).
  const fluid::Face& face(PetscInt i, PetscInt j, int d, int s) const;
  // The faces of the owned cells, fixed for the run: face(i, j, d, s) of owned cell o is
  // face_table_[face_code_[4 o + 2 d + (s > 0)]] (open, solid, or one of the 4 boundary faces).
  void build_face_codes();
  const fluid::Face& face_of(PetscInt o, int d, int s) const {
    return face_table_[face_code_[static_cast<size_t>(4 * o + 2 * d + (s > 0 ? 1 : 0))]];
  }
  PetscInt neighbour(PetscInt i, int d, int s, bool& outside) const;
  void refresh(Vec local) const;
  // Owned cells of a ghosted local array into a global Vec (to_local: the other way).
  void copy_owned(Vec local, Vec global, bool to_local) const;
  void zero_solid(Vec local) const;

  const Grid& grid_;
  FluidSettings set_;
  Halo halo_;
  VecH u_[2], solid_, p_, p_local_, rhs_, x_;
  std::vector<double> solidv_; // the ghosted solid mask (1: obstacle)
  std::vector<std::uint8_t> face_code_;
  fluid::Face face_table_[6];
  std::unique_ptr<WideHalo> wide_;
  advect::WideGeom geom_;
  std::vector<double> wu_[2];
  MatH A_visc_[2], A_pois_;
  VecH b_visc_[2];
  KSPH ksp_visc_[2], ksp_pois_;
  double visc_h_ = -1.0;        // substep of the assembled viscous matrices
  MatNullSpace null_ = nullptr; // constants on the fluid cells (closed domains)
  double div_ratio_ = 0.0;
  PetscInt poisson_its_ = 0, total_poisson_its_ = 0;
  // The pressure solve by FFT/DCT where A is a constant stencil (no obstacle, no outflow face)
  // and no -fluid_ksp_*/-fluid_pc_* option is given; else null (KSP).
  std::unique_ptr<SpectralSolver> spectral_pois_, spectral_visc_[2];
  void choose_pressure_solver();
  std::unique_ptr<SpectralSolver> spectral_for(Mat A, const std::string& prefix);
  void solve_pressure_ksp();
};

// KSPSolve of one of the fluid's solves; a PETSc refusal at the solver's setup (e.g. -fluid_pc_type
// mg without -fluid_pc_mg_galerkin) is a one-line UserError naming `what` and the options prefix.
void fluid_ksp_solve(KSP ksp, Vec b, Vec x, const std::string& what, const std::string& prefix);

} // namespace morphogen
