// A configured run: grid, model, fields, integrator and output settings, all read from the
// options database (decks are loaded into it first). Construction validates everything and
// throws UserError before any output is written.
#pragma once

#include "app/model_registry.hpp"
#include "core/options.hpp"
#include "fields/dirichlet_values.hpp"
#include "fields/param_set.hpp"
#include "fields/source_terms.hpp"
#include "fields/timed_params.hpp"
#include "grid/halo.hpp"
#include "integrators/diffusion_solver.hpp"
#include "integrators/explicit_integrator.hpp"
#include "integrators/split_integrator.hpp"
#include "integrators/ts_integrator.hpp"
#include "operators/advection_stage.hpp"
#include "operators/fluid_solver.hpp"
#include "operators/pointwise_terms.hpp"
#include "operators/state_diffusion.hpp"
#include "operators/term_list.hpp"
#include "operators/timed_diffusion.hpp"

#include <memory>
#include <string>
#include <vector>

namespace morphogen {

struct OutputSettings {
  std::string dir;
  PetscInt png_every = 0; // 0: only the final image
  std::vector<int> png_species;
  std::vector<std::array<double, 2>> png_range; // lo > hi means automatic (min/max per image)
  PetscInt progress_every = 0;
  PetscInt nan_check_every = 100;
  // VTKHDF snapshots <name>_<step>.vtkhdf with <name>.vtkhdf.series and <name>.xmf indexes.
  std::string name = "morphogen";
  PetscInt snapshot_every = 0; // 0: only the final state
  double snapshot_every_time = 0;
  bool snapshot_single = true; // float32
  // Checkpoints checkpoint_<step>.vtkhdf (float64 + /morphogen restart attributes).
  PetscInt checkpoint_every = 0;
  double checkpoint_every_time = 0;
  double checkpoint_every_walltime = 0; // minutes
  double max_walltime = 0;              // minutes: checkpoint and exit 3 before this
  PetscInt checkpoint_keep = 2;
  bool checkpoint_final = true;
  bool summary = true; // summary.json: pattern class, metrics and stability at the end
};

class Simulation;

// Coarse-to-fine grid sequencing: level `index` of `count` runs on the -grid_n grid coarsened
// by 2^(count - 1 - index) per axis and starts from the state of `coarser` (interpolated).
struct SequenceLevel {
  int index = 0, count = 1;
  Simulation* coarser = nullptr;
};

class Simulation {
public:
  // base_dir: where relative file names in values (png("...")) are looked up first.
  Simulation(MPI_Comm comm, Options& opt, const std::string& base_dir,
             const SequenceLevel& level = {});

  const ModelEntry& model() const { return *model_; }
  const Grid& grid() const { return *grid_; }
  const std::vector<std::string>& species() const { return species_; }
  // D_s of constant isotropic species; for maps and tensors the spatial mean isotropic part.
  const std::vector<double>& diffusion() const { return D_; }
  // The species' diffusion operators (one per species).
  std::vector<const DiffusionOperator*> operators() const;
  bool all_constant_diffusion() const;
  std::vector<VecH>& state() { return u_; }
  const OutputSettings& output() const { return out_; }
  double dt() const { return dt_; }
  // Explicit stability bound (of the finest level when grid sequencing).
  double stable_dt() const { return stable_dt_; }
  PetscInt steps() const { return steps_; }
  void set_steps(PetscInt n) { steps_ = n; }
  double time() const { return t_; }
  PetscInt step_index() const { return step_; }
  const Stencil& stencil() const { return stencil_; }
  std::uint64_t seed() const { return seed_; }
  int level() const { return level_index_; }
  const ParamSet& params() const { return params_; }
  // Set the clock after loading a checkpoint into state() (then call refresh_ghosts()).
  void set_clock(double t, PetscInt step) {
    t_ = t;
    step_ = step;
  }

  // Advance one step with the configured integrator.
  void step();
  // Steps advance() may take in one pass (-explicit_fuse_steps where it applies, else 1).
  PetscInt fuse_steps() const { return fuse_; }
  // The fixed depth of a fused pass (explicit -explicit_fuse_steps), 1 where passes have none
  // (one step, or split passes that run until the next observation).
  PetscInt pass_depth() const { return split_ ? 1 : fuse_; }
  // Advance n <= fuse_steps() steps, bitwise the same as n calls of step() (no output between).
  void advance(PetscInt n);
  // The run's terms and constraints (what the integrators consume).
  const TermList& terms() const { return terms_; }
  bool split() const { return split_; }
  const DiffusionSolver* diffusion_solver() const { return diffusion_.get(); }
  const SplitIntegrator* split_integrator() const { return split_integrator_.get(); }
  // The advection stage run after each step (-advect), or null.
  const AdvectionStage* advection() const { return advection_.get(); }
  // The stable-fluids solver run before the advection stage each step (-fluid), or null.
  FluidSolver* fluid() const { return fluid_.get(); }
  // The explicit fast path's row kernel compile on this rank ("512-bit (least pass ...)"; see
  // -explicit_vector_width), or "" where the run does not use it.
  std::string explicit_vector_width() const;
  // Make ghosts current (after initialisation or before reading neighbours).
  void refresh_ghosts() { integrator_->update_ghosts(u_); }
  // Collective: throws UserError naming species, cell, step and time if any value is NaN/Inf.
  void check_finite() const;

private:
  void read_fuse(Options& opt);
  void read_vector_width(Options& opt);
  ExplicitIntegrator::RowFn fused_row_kernel(bool wide) const;
  void read_split_fuse();
  std::string fuse_blocker(std::string why) const;
  static constexpr PetscInt kMaxFusedSplitSteps = 1 << 20; // a pass ends at any observation
  PetscInt fuse_ = 1; // steps per pass of the explicit integrator (temporal blocking)
  void read_grid(Options& opt, const SequenceLevel& level);
  void start_from(Simulation& coarser);
  void read_diffusion_kinds(Options& opt, const std::string& stencil);
  void check_surface_needs_tensor(const Options& opt) const;
  void read_model(Options& opt, const std::string& base_dir);
  void read_params(Options& opt, const std::string& base_dir);
  void read_pins(Options& opt, const std::string& base_dir);
  void pin_matrices();
  void read_time(Options& opt);
  void read_output(Options& opt);
  void read_snapshot_options(Options& opt);
  void build_terms();
  void read_ts(Options& opt);
  void read_split(Options& opt);
  void keep_timed_patterns();
  void check_timed_stability() const;

  MPI_Comm comm_;
  std::string base_dir_;
  std::shared_ptr<const ModelEntry> model_; // registry entry or a model built at run time
  GridSpec spec_;
  std::unique_ptr<Grid> grid_;
  std::unique_ptr<Halo> halo_;
  Stencil stencil_;
  std::vector<std::string> species_;
  std::vector<double> D_, floor_;
  ParamSet params_;
  std::unique_ptr<TimedParams> timed_; // parameters using t
  std::vector<FaceValues> dirichlet_;
  std::unique_ptr<DirichletValues> boundary_; // fills dirichlet_ (re-evaluated when using t)
  std::vector<VecH> u_;
  std::vector<bool> tensor_;                         // per species: -diffusion_S tensor
  std::vector<std::vector<PinnedCells::Cell>> pins_; // per species: this rank's pinned cells
  bool any_pins_ = false;
  std::vector<std::unique_ptr<DiffusionOperator>> ops_;
  std::vector<std::unique_ptr<CoefficientRule>> rules_; // per species: polar/shaped, else null
  std::vector<TimedDiffusionTerm::Fill> timed_coef_;    // per species: D using t, else null
  std::vector<int> timed_nc_;                           // their component counts
  bool force_dt_ = false;
  std::unique_ptr<OperatorMatrices> matrices_; // split and TS; before the integrators using it
  std::unique_ptr<SourceTerms> sources_;
  TermList terms_; // after the operators, parameters and sources its terms refer to
  std::unique_ptr<ExplicitIntegrator> integrator_;
  std::unique_ptr<DiffusionSolver> diffusion_;
  std::unique_ptr<SplitIntegrator> split_integrator_;
  std::unique_ptr<TsIntegrator> ts_integrator_;
  Integrator* stepper_ = nullptr;             // the integrator step() uses
  std::unique_ptr<FluidSolver> fluid_;        // before the advection stage (-fluid)
  std::unique_ptr<AdvectionStage> advection_; // after every integrator's step (-advect)
  bool split_ = false, ts_ = false, ts_implicit_diffusion_ = true;
  std::string ts_solver_ = "auto"; // -ts_diffusion_solver
  bool split_fuse_ = false;        // -split_fuse_reaction: fused Strang passes (advance())
  PetscInt level_factor_ = 1;      // coarsening factor of this sequencing level (1: finest)
  int level_index_ = 0;
  std::uint64_t seed_ = 1;
  double dt_ = 0, stable_dt_ = 0, t_ = 0;
  PetscInt steps_ = 0, step_ = 0;
  OutputSettings out_;
};

} // namespace morphogen
