#include "app/simulation.hpp"

#include "app/device_types.hpp"
#include "app/diffusion_setup.hpp"
#include "app/fft_options.hpp"
#include "app/float_options.hpp"
#include "app/model_setup.hpp"
#include "core/collective_error.hpp"
#include "core/log_events.hpp"
#include "core/user_error.hpp"
#include "fields/field_fill.hpp"
#include "grid/prolong.hpp"
#include "operators/advection_setup.hpp"
#include "operators/fluid_setup.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace morphogen {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMaxReal = std::numeric_limits<double>::max(); // finite upper bound
// The largest dt as a multiple of the explicit diffusion bound that the implicit integrators take:
// far past it, 1 + dt D rho(L) / 2 has lost the 1 (the cell's own value) to rounding.
constexpr double kMaxDiffusionNumber = 1e12;

// Per species: why its diffusion matrix is re-assembled during the run ("" if it is not), for
// the split solver's choice of KSP over the spectral solve.
std::vector<std::string> varying_diffusion(const TermList& terms,
                                           const std::vector<std::string>& species) {
  std::vector<std::string> why(species.size());
  const auto diff = terms.diffusion(static_cast<int>(species.size()));
  for (size_t s = 0; s < species.size(); ++s)
    if (dynamic_cast<const StateDiffusionTerm*>(diff[s]))
      why[s] = "its coefficients follow the state (-diffusion_" + species[s] + " polar/shaped)";
    else if (diff[s]->timed_coefficients())
      why[s] = "its coefficients use t (-D_" + species[s] + " or -tensor_*)";
  return why;
}
} // namespace

Simulation::Simulation(MPI_Comm comm, Options& opt, const std::string& base_dir,
                       const SequenceLevel& level)
    : comm_(comm), base_dir_(base_dir) {
  LogScope log_scope(log_events().setup);
  read_grid(opt, level);
  read_fft_planning(opt);
  read_float_env(opt);
  read_model(opt, base_dir);
  read_time(opt);
  fluid_ = read_fluid(opt, *grid_, seed_, base_dir);
  advection_ = read_advection(opt, *grid_, species_, seed_, base_dir, dt_, fluid_.get());
  read_fuse(opt);
  read_output(opt);
  if (level.coarser) start_from(*level.coarser);
}

void Simulation::start_from(Simulation& coarser) {
  coarser.refresh_ghosts();
  for (size_t s = 0; s < u_.size(); ++s) {
    const PetscScalar* c;
    PetscScalar* f;
    MG_PETSC(VecGetArrayRead(coarser.u_[s], &c));
    MG_PETSC(VecGetArray(u_[s], &f));
    prolong_cell_centred(*coarser.grid_, c, *grid_, f);
    MG_PETSC(VecRestoreArray(u_[s], &f));
    MG_PETSC(VecRestoreArrayRead(coarser.u_[s], &c));
  }
  if (fluid_ && coarser.fluid_) fluid_->prolong_from(*coarser.fluid_);
  t_ = coarser.t_;
  step_ = coarser.step_;
  refresh_ghosts();
}

void Simulation::read_grid(Options& opt, const SequenceLevel& level) {
  const auto n = opt.list("grid_n", {"256", "256"}, 2, 3,
                          "cells per axis: nx,ny (2-D) or nx,ny,nz (3-D); with "
                          "-sequence_levels, the finest level's");
  spec_.dim = static_cast<int>(n.size());
  for (int d = 0; d < spec_.dim; ++d) {
    spec_.n[d] = Options::parse_int("grid_n", n[d]);
    if (spec_.n[d] < 3 || spec_.n[d] > (1 << 24))
      throw UserError("-grid_n " + n[d] + ": cells per axis must be in [3, 16777216]");
  }
  const PetscInt factor = PetscInt(1) << (level.count - 1 - level.index);
  if (factor > 1)
    for (int d = 0; d < spec_.dim; ++d) {
      if (spec_.n[d] % factor != 0 || spec_.n[d] / factor < 3)
        throw UserError("-grid_n " + n[d] + ": with -sequence_levels " +
                        std::to_string(level.count) + " every axis must be a multiple of " +
                        std::to_string(factor) + " with at least " + std::to_string(3 * factor) +
                        " cells");
    }
  std::vector<std::string> Ldef;
  for (int d = 0; d < spec_.dim; ++d)
    Ldef.push_back(std::to_string(spec_.n[d]));
  const auto L = opt.list("grid_L", Ldef, 1, 3,
                          "domain length per axis (one value for all axes); spacing h = L/n");
  for (int d = 0; d < spec_.dim; ++d) {
    const std::string& s = L.size() == 1 ? L[0] : L[d];
    if (L.size() != 1 && static_cast<int>(L.size()) != spec_.dim)
      throw UserError("-grid_L: expected 1 or " + std::to_string(spec_.dim) + " values, got " +
                      std::to_string(L.size()));
    spec_.L[d] = Options::parse_real("grid_L", s);
    if (!(spec_.L[d] > 0) || !std::isfinite(spec_.L[d]))
      throw UserError("-grid_L " + s + ": domain length must be > 0");
  }
  for (int d = 0; d < spec_.dim; ++d)
    spec_.n[d] /= factor;
  level_factor_ = factor;
  level_index_ = level.index;
  if (level.coarser) {
    spec_.ranges = level.coarser->grid().ownership_ranges();
    for (auto& r : spec_.ranges)
      for (auto& c : r)
        c *= 2;
  }
  const auto bc = opt.list("grid_bc", {"periodic"}, 1, 3,
                           "boundary per axis, one value for all axes or one per axis "
                           "(periodic, neumann, dirichlet)");
  if (bc.size() != 1 && static_cast<int>(bc.size()) != spec_.dim)
    throw UserError("-grid_bc: expected 1 or " + std::to_string(spec_.dim) + " values, got " +
                    std::to_string(bc.size()));
  for (int d = 0; d < spec_.dim; ++d) {
    const std::string& b = bc.size() == 1 ? bc[0] : bc[d];
    if (b == "periodic")
      spec_.bc[d] = Boundary::Periodic;
    else if (b == "neumann" || b == "zero_flux")
      spec_.bc[d] = Boundary::Neumann;
    else if (b == "dirichlet")
      spec_.bc[d] = Boundary::Dirichlet;
    else
      throw UserError("-grid_bc " + b + ": unknown boundary, allowed periodic, neumann, dirichlet");
  }
  const std::string def_stencil = spec_.dim == 2 ? "5pt" : "7pt";
  const std::string st =
      opt.choice("stencil", def_stencil,
                 spec_.dim == 2 ? std::vector<std::string>{"5pt", "9pt"}
                                : std::vector<std::string>{"7pt", "19pt", "27pt"},
                 "Laplacian stencil: 5pt or 9pt (isotropic, Garrity) in 2-D, 7pt, 19pt or 27pt "
                 "(isotropic, Patra-Karttunen) in 3-D");
  const double h[3] = {spec_.h(0), spec_.h(1), spec_.h(2)};
  if (!make_stencil(st, spec_.dim, h, stencil_))
    throw UserError("-stencil " + st + ": the isotropic " + st +
                    " stencil needs equal spacings (got " + format_number(h[0]) + ", " +
                    format_number(h[1]) + (spec_.dim == 3 ? ", " + format_number(h[2]) : "") + ")");
  spec_.stencil_width = 1;
  spec_.box_stencil = isotropic_box(stencil_);
  read_diffusion_kinds(opt, st);
  read_device_types(opt);
  grid_ = std::make_unique<Grid>(comm_, spec_);
  spec_ = grid_->spec();
  halo_ = std::make_unique<Halo>(*grid_);
}

void Simulation::read_diffusion_kinds(Options& opt, const std::string& stencil) {
  model_ = read_model_choice(opt);
  tensor_.clear();
  for (int s = 0; s < model_->nspecies; ++s) {
    tensor_.push_back(read_tensor_choice(opt, model_->species[s].name));
    if (!tensor_.back()) continue;
    spec_.box_stencil = true; // cross terms read the ghost corners
    if (stencil == "9pt" || stencil == "19pt" || stencil == "27pt")
      throw UserError("-stencil " + stencil + ": the isotropic " + stencil +
                      " stencil cannot be combined with -diffusion_" +
                      std::string(model_->species[s].name) +
                      " tensor (the tensor operator has its own box stencil); use -stencil " +
                      (spec_.dim == 2 ? "5pt" : "7pt"));
  }
  check_surface_needs_tensor(opt);
}

void Simulation::check_surface_needs_tensor(const Options& opt) const {
  bool any_tensor = false;
  for (bool t : tensor_)
    any_tensor = any_tensor || t;
  for (const char* k : {"surface_x", "surface_y", "surface_z"})
    if (opt.is_set(k) && !any_tensor)
      throw UserError(std::string("-") + k +
                      ": the surface-metric correction applies to diffusion tensors; add "
                      "-diffusion tensor (the default l1 = l2 = 1 is isotropic on the surface)");
}

// Parameters: scalars where constant in space (and time), fields where they vary in space;
// values using t also go to timed_ (re-evaluated each step).
void Simulation::read_params(Options& opt, const std::string& base_dir) {
  params_ = ParamSet{};
  timed_ = std::make_unique<TimedParams>(*grid_);
  for (int q = 0; q < model_->nparams; ++q) {
    const ParamInfo& p = model_->params[q];
    const std::string key = std::string("params_") + p.name;
    const std::string help = std::string(p.doc) + " (" + allowed_range(p.lo, p.hi) +
                             "); a number, expression (may use t), 'v +- a%' or png(...)";
    const std::string text = opt.string(key, p.def_text ? p.def_text : format_double(p.def), help);
    auto vs = std::make_unique<ValueSpec>(key, text, spec_, seed_, base_dir);
    params_.names.emplace_back(p.name);
    if (vs->is_constant()) {
      const double v = vs->constant_value();
      if (!(v >= p.lo && v <= p.hi))
        throw UserError("-" + key + " " + text + ": out of range, " + allowed_range(p.lo, p.hi));
      params_.scalar.push_back(v);
      params_.field.emplace_back();
    } else if (vs->uniform_in_space()) { // depends on t only: a scalar set each step
      params_.scalar.push_back(std::nan(""));
      params_.field.emplace_back();
    } else {
      params_.scalar.push_back(std::nan(""));
      params_.field.push_back(grid_->create_global());
      if (!vs->uses_time()) {
        PetscScalar* a;
        MG_PETSC(VecGetArray(params_.field.back(), &a));
        try {
          fill_field(*grid_, *vs, a, ArrayLayout::Owned, p.lo, p.hi);
        } catch (...) {
          MG_PETSC(VecRestoreArray(params_.field.back(), &a));
          throw;
        }
        MG_PETSC(VecRestoreArray(params_.field.back(), &a));
      }
    }
    if (vs->uses_time()) timed_->add(q, std::move(vs), p.lo, p.hi);
  }
  timed_->set_time(params_, 0.0); // checks the values at t = 0 before anything runs
}

void Simulation::read_model(Options& opt, const std::string& base_dir) {
  seed_ = static_cast<std::uint64_t>(
      opt.integer("seed", 1, 0, std::numeric_limits<PetscInt>::max(),
                  "seed of every random value (hashed with the key and the global cell index)"));
  const bool clamp = opt.flag("clamp", model_->clamp_default,
                              "clamp negative concentrations to 0 after each step");
  const int ns = model_->nspecies;

  read_params(opt, base_dir);

  // Species: diffusion, initial values, Dirichlet values.
  species_.clear();
  D_.assign(ns, 0.0);
  floor_.assign(ns, clamp ? 0.0 : -kInf);
  bool any_dirichlet = false;
  for (int d = 0; d < spec_.dim; ++d)
    any_dirichlet |= spec_.bc[d] == Boundary::Dirichlet;
  dirichlet_.assign(any_dirichlet ? ns : 0, FaceValues{});
  boundary_ = std::make_unique<DirichletValues>(*grid_, *halo_, dirichlet_);
  u_.clear();
  ops_.clear();
  rules_.clear();
  timed_coef_.clear();
  timed_nc_.clear();
  for (int s = 0; s < ns; ++s) {
    const SpeciesInfo& si = model_->species[s];
    species_.emplace_back(si.name);
    DiffusionSetup ds =
        read_diffusion(opt, *grid_, *halo_, stencil_, si, tensor_[s], seed_, base_dir);
    if (!ds.op->constant() && isotropic_box(stencil_))
      throw UserError("-stencil " + stencil_.name + ": a diffusion map -D_" + std::string(si.name) +
                      " (or a D using t) needs -stencil " + (spec_.dim == 2 ? "5pt" : "7pt") +
                      " (the map's operator has its own star form)");
    D_[s] = ds.D_mean;
    ops_.push_back(std::move(ds.op));
    rules_.push_back(std::move(ds.rule));
    timed_coef_.push_back(std::move(ds.timed));
    timed_nc_.push_back(ds.components);
    const std::string ikey = std::string("init_") + si.name;
    ValueSpec init(ikey,
                   opt.string(ikey, format_double(si.init),
                              std::string("initial value of ") + si.name +
                                  ": number, expression, 'v +- a%', shapes, png(...)"),
                   spec_, seed_, base_dir);
    u_.push_back(grid_->create_local());
    PetscScalar* a;
    MG_PETSC(VecGetArray(u_.back(), &a));
    try {
      fill_field(*grid_, init, a, ArrayLayout::Ghosted, -kInf, kInf);
    } catch (...) {
      MG_PETSC(VecRestoreArray(u_.back(), &a));
      throw;
    }
    MG_PETSC(VecRestoreArray(u_.back(), &a));
    if (any_dirichlet) {
      const std::string dkey = std::string("dirichlet_") + si.name;
      boundary_->add(s, std::make_unique<ValueSpec>(
                            dkey,
                            opt.string(dkey, format_double(si.init),
                                       std::string("Dirichlet boundary value of ") + si.name +
                                           " (expression of the face position; may use t)"),
                            spec_, seed_, base_dir));
    }
  }
  read_pins(opt, base_dir);
  integrator_ = std::make_unique<ExplicitIntegrator>(*grid_, *halo_, fused_row_kernel(false), ns,
                                                     stencil_, D_, floor_, params_,
                                                     any_dirichlet ? &dirichlet_ : nullptr);
  if (!model_->kernels.fused || !all_constant_diffusion())
    integrator_->use_operators(operators(),
                               model_->kernels.explicit_pre[params_.any_field() ? 1 : 0]);
  integrator_->update_ghosts(u_);
}

// -pin_<species> MASK: cells where the mask is non-zero keep their initial value.
void Simulation::read_pins(Options& opt, const std::string& base_dir) {
  pins_.assign(species_.size(), {});
  any_pins_ = false;
  const Box& ob = grid_->owned();
  for (size_t s = 0; s < species_.size(); ++s) {
    const std::string key = "pin_" + species_[s];
    const auto text = opt.get(key, "cells of " + species_[s] +
                                       " held at their initial value: a mask, non-zero where "
                                       "pinned (expression, png(...)), e.g. 'j < 2'");
    if (!text) continue;
    ValueSpec mask(key, *text, spec_, seed_, base_dir);
    if (mask.uses_time())
      throw UserError("-" + key + " " + *text + ": a pin mask cannot depend on t");
    std::vector<double> m(static_cast<size_t>(ob.size()));
    fill_field(*grid_, mask, m.data(), ArrayLayout::Owned, -kInf, kInf);
    const PetscScalar* a;
    MG_PETSC(VecGetArrayRead(u_[s], &a));
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
        for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
          const PetscInt o = grid_->owned_index(i, j, k), l = grid_->local_index(i, j, k);
          if (m[static_cast<size_t>(o)] != 0.0) pins_[s].push_back({l, o, a[l]});
        }
    MG_PETSC(VecRestoreArrayRead(u_[s], &a));
    any_pins_ = true;
  }
}

// Pinned cells out of the implicit operators (rows of the DMDA's global numbering).
void Simulation::pin_matrices() {
  if (!any_pins_ || !matrices_) return;
  PetscInt rstart = 0;
  {
    VecH g = grid_->create_global();
    MG_PETSC(VecGetOwnershipRange(g, &rstart, nullptr));
  }
  for (size_t s = 0; s < pins_.size(); ++s) {
    int any = !pins_[s].empty();
    MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_LOR, comm_);
    if (!any) continue;
    std::vector<PetscInt> rows;
    std::vector<double> values;
    for (const auto& c : pins_[s]) {
      rows.push_back(rstart + c.owned);
      values.push_back(c.value);
    }
    matrices_->pin(static_cast<int>(s), rows, values);
  }
}

void Simulation::read_time(Options& opt) {
  const std::string kind =
      opt.choice("integrator", "explicit", {"explicit", "split", "ts"},
                 "time integrator: explicit (forward Euler, diffusion and reaction fused), "
                 "split (Lie/Strang splitting, implicit diffusion by KSP, per-cell reaction by "
                 "Newton) or ts (PETSc TS, ARKIMEX 2E: diffusion implicit, reaction explicit; "
                 "every -ts_ option)");
  split_ = kind == "split";
  ts_ = kind == "ts";
  if (ts_)
    ts_implicit_diffusion_ =
        opt.choice("ts_diffusion", "implicit", {"implicit", "explicit"},
                   "with -integrator ts: diffusion in the implicit part (IMEX, default) or with "
                   "every other term in the explicit right-hand side (explicit TS types: rk, "
                   "euler, ssp)") == "implicit";
  else if (opt.is_set("ts_diffusion"))
    throw UserError("-ts_diffusion: applies to -integrator ts only");
  if (ts_ && ts_implicit_diffusion_)
    ts_solver_ = opt.choice(
        "ts_diffusion_solver", "auto", {"auto", "ksp", "spectral"},
        "with -integrator ts: the implicit diffusion solve of each stage: spectral (the exact "
        "inverse by FFT/DCT, tridiagonal along the slowest axis where it applies, as the "
        "preconditioner of -ksp_type preonly: periodic, zero-flux or Dirichlet axes, "
        "constant coefficients), ksp (-ksp_type/-pc_type; default CG with ICC), or auto (spectral "
        "where "
        "it applies and no -ksp_type, -pc_type, -sub_pc_type, -ksp_rtol, -ksp_atol, "
        "-ksp_max_it, -ksp_initial_guess_nonzero or -snes_mf is given)");
  else if (opt.is_set("ts_diffusion_solver"))
    throw UserError("-ts_diffusion_solver: applies to -integrator ts with -ts_diffusion "
                    "implicit only");
  // With grid sequencing every level uses the finest level's dt and stability bound (the
  // bound scales with h^2), so a bad -dt fails before the first level writes anything.
  const bool constant = all_constant_diffusion();
  sources_ = std::make_unique<SourceTerms>(*grid_, opt, species_, seed_, base_dir_);
  build_terms();
  stable_dt_ = (constant ? ExplicitIntegrator::stable_dt(stencil_, D_) : terms_.stable_dt()) /
               static_cast<double>(level_factor_ * level_factor_);
  const double def_dt = std::isfinite(stable_dt_) ? 0.9 * stable_dt_ : 1.0;
  // (at least the smallest normal double: a subnormal step reads as 0 where subnormals flush)
  dt_ = opt.real("dt", def_dt, std::numeric_limits<double>::min(), kMaxReal, "time step");
  if (!split_ && !(ts_ && ts_implicit_diffusion_)) {
    const bool force = opt.flag("force_dt", false,
                                "run even when -dt exceeds the explicit diffusion stability bound");
    force_dt_ = force;
    double lmax = 0;
    for (const auto& op : ops_)
      lmax = std::max(lmax, op->max_eigenvalue());
    if (dt_ > stable_dt_ && !force && !constant)
      throw UserError(
          "-dt " + format_number(dt_) +
          ": exceeds the explicit diffusion stability bound dt <= " + format_number(stable_dt_) +
          " (2/(lambda_max*rho(L)), the largest eigenvalue of the diffusion "
          "tensors/maps over the grid lambda_max = " +
          format_number(lmax) +
          "); use a smaller -dt, -integrator split (unconditionally stable "
          "diffusion), or -force_dt");
    if (dt_ > stable_dt_ && !force)
      throw UserError(
          "-dt " + format_number(dt_) + ": exceeds the explicit diffusion stability bound dt <= " +
          format_number(stable_dt_) + " (2/(D_max*rho(L)) for the " + stencil_.name +
          " stencil, D_max = " + format_number(*std::max_element(D_.begin(), D_.end())) +
          "); use a smaller -dt, -integrator split (unconditionally stable "
          "diffusion), or -force_dt");
  } else if (const double ratio = dt_ / stable_dt_; ratio > kMaxDiffusionNumber) {
    // (stable_dt_ is 0 where h^2 underflows: the ratio is then inf; +inf without diffusion)
    throw UserError("-dt " + format_number(dt_) + ": " + format_number(ratio) +
                    " times the explicit diffusion stability bound " + format_number(stable_dt_) +
                    ", allowed at most " + format_number(kMaxDiffusionNumber) +
                    " times (beyond it the implicit diffusion solves lose the cell's own value "
                    "to rounding); use a smaller -dt or D, or a coarser grid");
  }
  steps_ =
      opt.integer("steps", 1000, 0, std::numeric_limits<PetscInt>::max(), "number of time steps");
  if (!std::isfinite(static_cast<double>(steps_) * dt_))
    throw UserError("-dt " + format_number(dt_) + ": the end time -steps " +
                    std::to_string(steps_) + " times -dt overflows a double");
  stepper_ = integrator_.get();
  if (ts_) read_ts(opt);
  if (split_) read_split(opt);
}

// The run's terms: diffusion per species, the reaction, sources, and the clamp floor.
void Simulation::build_terms() {
  for (size_t s = 0; s < ops_.size(); ++s)
    if (rules_[s]) // solution-dependent: refreshed per step (operators/state_diffusion.hpp)
      terms_.add(std::make_unique<StateDiffusionTerm>(static_cast<int>(s), species_[s], *ops_[s],
                                                      *halo_, std::move(rules_[s])),
                 true);
    else if (timed_coef_[s]) // coefficients using t: set per step (operators/timed_diffusion.hpp)
      terms_.add(std::make_unique<TimedDiffusionTerm>(static_cast<int>(s), species_[s], *ops_[s],
                                                      *halo_, timed_nc_[s], timed_coef_[s]));
    else
      terms_.add(std::make_unique<DiffusionTerm>(static_cast<int>(s), species_[s], *ops_[s]));
  terms_.add(std::make_unique<ReactionTerm>(*grid_, model_->name, model_->rates, model_->nspecies,
                                            params_, timed_.get()));
  if (sources_->any()) terms_.add(std::make_unique<SourceTerm>(*grid_, *sources_, species_));
  bool clamp = false;
  for (double f : floor_)
    clamp = clamp || std::isfinite(f);
  if (clamp) terms_.add(std::make_unique<ClampFloor>(*grid_, floor_));
  if (any_pins_) terms_.add(std::make_unique<PinnedCells>(pins_, species_));
  terms_.use_boundary(boundary_.get());
  integrator_->use_terms(terms_);
}

void Simulation::read_ts(Options& opt) {
  // The step loop sets TS's time, final time and step from -dt: refuse the TS spellings.
  for (const char* k : {"ts_dt", "ts_max_time", "ts_init_time", "ts_max_steps"})
    if (opt.is_set(k))
      throw UserError(std::string("-") + k +
                      ": set by morphogen with -integrator ts; use -dt (the step, or the "
                      "output interval with -ts_adapt_type basic) and -steps");
  for (const char* k :
       {"ts_type", "ts_arkimex_type", "ts_rk_type", "ts_adapt_type", "ts_rtol", "ts_atol",
        "ts_monitor", "snes_type", "ksp_type", "pc_type", "sub_pc_type", "ksp_rtol"})
    opt.known(k);
  const bool implicit = ts_implicit_diffusion_;
  if (implicit) {
    matrices_ = std::make_unique<OperatorMatrices>(*grid_, *halo_, stencil_, operators(),
                                                   dirichlet_.empty() ? nullptr : &dirichlet_);
    keep_timed_patterns();
    pin_matrices();
    terms_.use_matrices(matrices_.get()); // lagged solution-dependent operators re-assembled
  }
  ts_integrator_ =
      std::make_unique<TsIntegrator>(*grid_, *halo_, species_, terms_, matrices_.get(),
                                     dirichlet_.empty() ? nullptr : &dirichlet_, dt_, ts_solver_);
  stepper_ = ts_integrator_.get();
}

void Simulation::read_split(Options& opt) {
  SplitSettings set;
  const std::string ord = opt.choice("split_ordering", "strang", {"lie", "strang"},
                                     "splitting: lie (first order) or strang (second order)");
  set.ordering = ord == "lie" ? SplitOrdering::Lie : SplitOrdering::Strang;
  const bool strang = set.ordering == SplitOrdering::Strang;
  const std::string rs =
      opt.choice("split_reaction", strang ? "trapezoidal" : "backward_euler",
                 {"euler", "heun", "rk4", "backward_euler", "trapezoidal"},
                 "reaction substep: euler, heun, rk4 (explicit: for reactions that are not "
                 "stiff at the step), backward_euler, trapezoidal (implicit per cell, Newton with "
                 "the analytic Jacobian)");
  set.reaction = rs == "euler"            ? ReactionScheme::Euler
                 : rs == "heun"           ? ReactionScheme::Heun
                 : rs == "rk4"            ? ReactionScheme::Rk4
                 : rs == "backward_euler" ? ReactionScheme::BackwardEuler
                                          : ReactionScheme::Trapezoidal;
  const std::string ds = opt.choice("split_diffusion", strang ? "crank_nicolson" : "backward_euler",
                                    {"backward_euler", "crank_nicolson"},
                                    "diffusion substep: backward_euler or crank_nicolson");
  set.theta = ds == "backward_euler" ? 1.0 : 0.5;
  set.newton_tol = opt.real("split_newton_tol", 1e-12, 1e-16, 1e-2,
                            "relative tolerance of the per-cell Newton solve");
  set.newton_max_it = static_cast<int>(
      opt.integer("split_newton_max_it", 20, 1, 1000, "Newton iteration cap per cell"));
  split_fuse_ = opt.flag(
      "split_fuse_reaction", false,
      "Strang: merge the reaction half-steps of consecutive steps that no output, sample, "
      "progress line or NaN check separates (n - 1 fewer reaction substeps per n steps, still "
      "second order; the trajectory then depends on the output times to splitting-error order, "
      "so restarts are not bitwise)");
  set.fuse_planes = opt.flag(
      "split_fuse_planes", true,
      "where every diffusing species is solved by the tridiagonal method in place, a reaction "
      "substep followed by a diffusion substep runs inside the latter's first pass, each plane of "
      "the slowest axis just before the transforms read it, in cache (the same arithmetic as "
      "false: one pass over the state less per step)");
  matrices_ = std::make_unique<OperatorMatrices>(*grid_, *halo_, stencil_, operators(),
                                                 dirichlet_.empty() ? nullptr : &dirichlet_);
  keep_timed_patterns();
  pin_matrices();
  terms_.use_matrices(matrices_.get()); // lagged solution-dependent operators re-assembled
  diffusion_ = std::make_unique<DiffusionSolver>(*grid_, *matrices_, species_, opt,
                                                 varying_diffusion(terms_, species_));
  diffusion_->prepare(dt_, set.theta);
  split_integrator_ = std::make_unique<SplitIntegrator>(
      *grid_, model_->kernels.reaction_row[params_.any_field() ? 1 : 0], species_, params_, floor_,
      sources_.get(), *diffusion_, set);
  split_integrator_->use_constraints(terms_);
  stepper_ = split_integrator_.get();
}

// Species whose coefficients use t keep one matrix pattern over time (operator_matrices.hpp).
void Simulation::keep_timed_patterns() {
  for (size_t s = 0; s < timed_coef_.size(); ++s)
    if (timed_coef_[s]) matrices_->keep_pattern(static_cast<int>(s));
}

// Explicit diffusion with coefficients using t: -dt must stay under the stability bound of the
// coefficients at every step (checked after the step that used them).
void Simulation::check_timed_stability() const {
  if (force_dt_ || split_ || (ts_ && ts_implicit_diffusion_)) return;
  bool timed = false;
  for (const auto& f : timed_coef_)
    timed = timed || static_cast<bool>(f);
  if (!timed) return;
  const double bound = terms_.stable_dt() / static_cast<double>(level_factor_ * level_factor_);
  if (dt_ > bound)
    throw UserError("-dt " + format_number(dt_) + ": at t = " + format_number(t_) +
                    " the time-dependent diffusion needs dt <= " + format_number(bound) +
                    " (explicit stability bound of the coefficients at that time); use a smaller "
                    "-dt, -integrator split, or -force_dt");
}

void Simulation::read_output(Options& opt) {
  out_.dir =
      opt.string("output_dir", "morphogen_out", "directory for images and options_used.yaml");
  if (out_.dir.empty()) throw UserError("-output_dir: must not be empty");
  out_.png_every = opt.integer("png_every", 0, 0, std::numeric_limits<PetscInt>::max(),
                               "write PNG images every N steps (0: only at the end)");
  const auto names =
      opt.list("png_species", species_, 0, 16, "species written as PNG images (default: all)");
  out_.png_species.clear();
  for (const auto& n : names) {
    auto it = std::find(species_.begin(), species_.end(), n);
    if (it == species_.end()) {
      std::string all;
      for (auto& s : species_)
        all += (all.empty() ? "" : ", ") + s;
      throw UserError("-png_species " + n + ": no such species in model " + model_->name +
                      ", allowed " + all);
    }
    const int s = static_cast<int>(it - species_.begin());
    if (std::find(out_.png_species.begin(), out_.png_species.end(), s) != out_.png_species.end())
      throw UserError("-png_species: species " + n + " given twice");
    out_.png_species.push_back(s);
  }
  out_.png_range.assign(species_.size(), {1.0, 0.0});
  for (size_t s = 0; s < species_.size(); ++s) {
    const std::string key = "png_range_" + species_[s];
    if (!opt.is_set(key)) {
      opt.known(key);
      continue;
    }
    const auto r = opt.list(key, {}, 2, 2, "colour range lo,hi of " + species_[s] + " images");
    out_.png_range[s] = {Options::parse_real(key, r[0]), Options::parse_real(key, r[1])};
    const double lo = out_.png_range[s][0], hi = out_.png_range[s][1];
    if (!(std::isfinite(lo) && std::isfinite(hi) && std::isfinite(hi - lo) && lo < hi))
      throw UserError("-" + key + " " + r[0] + "," + r[1] +
                      ": needs finite lo < hi (with a finite hi - lo)");
  }
  out_.progress_every =
      opt.integer("progress_every", std::max<PetscInt>(1, steps_ / 20), 1,
                  std::numeric_limits<PetscInt>::max(), "print a progress line every N steps");
  out_.nan_check_every =
      opt.integer("nan_check_every", 100, 1, std::numeric_limits<PetscInt>::max(),
                  "check for NaN/Inf every N steps (stops the run with the cell, time and the last "
                  "good checkpoint)");
  read_snapshot_options(opt);
}

void Simulation::read_snapshot_options(Options& opt) {
  const PetscInt imax = std::numeric_limits<PetscInt>::max();
  out_.name = opt.string("output_name", "morphogen",
                         "run name: snapshots <name>_<step>.vtkhdf, indexes <name>.vtkhdf.series "
                         "and <name>.xmf (open the .xmf in ParaView)");
  if (out_.name.empty() ||
      out_.name.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnop"
                                  "qrstuvwxyz0123456789_-.") != std::string::npos)
    throw UserError("-output_name " + out_.name +
                    ": allowed characters are letters, digits, '_', '-' and '.'");
  // Checkpoints are checkpoint_<step>.vtkhdf (io/checkpoint_files.cpp), snapshots
  // <name>_<step>.vtkhdf: one name for both would overwrite (and prune) each other.
  if (out_.name == "checkpoint")
    throw UserError("-output_name checkpoint: reserved for the checkpoint files "
                    "(checkpoint_<step>.vtkhdf); choose another run name");
  // File names are NAME_<step>.vtkhdf and the like (and MPI-IO adds its own suffixes): keep
  // them well inside the file system's 255-byte limit.
  if (out_.name.size() > 200)
    throw UserError("-output_name " + out_.name.substr(0, 40) + "...: " +
                    std::to_string(out_.name.size()) + " characters, allowed at most 200");
  out_.snapshot_every = opt.integer("snapshot_every", 0, 0, imax,
                                    "write a VTKHDF snapshot every N steps and at step 0 (0: "
                                    "only the final state)");
  out_.snapshot_every_time = opt.real("snapshot_every_time", 0, 0, kMaxReal,
                                      "write a snapshot every T of simulated time (0: off)");
  out_.snapshot_single =
      opt.choice("snapshot_precision", "float32", {"float32", "float64"},
                 "value type of snapshot files (checkpoints are float64)") == "float32";
  out_.checkpoint_every =
      opt.integer("checkpoint_every", 0, 0, imax, "write a checkpoint every N steps (0: off)");
  out_.checkpoint_every_time = opt.real("checkpoint_every_time", 0, 0, kMaxReal,
                                        "write a checkpoint every T of simulated time (0: off)");
  out_.checkpoint_every_walltime =
      opt.real("checkpoint_every_walltime", 0, 0, kMaxReal,
               "write a checkpoint every W minutes of wall time (0: off)");
  out_.max_walltime = opt.real("max_walltime", 0, 0, kMaxReal,
                               "wall-time budget in minutes: before it runs out, write a "
                               "checkpoint and exit with code 3 (0: none)");
  out_.checkpoint_keep =
      opt.integer("checkpoint_keep", 2, 1, 1000000, "number of most recent checkpoints kept");
  out_.checkpoint_final =
      opt.flag("checkpoint_final", true, "write a checkpoint of the final state (to extend a run)");
  out_.summary = opt.flag("summary", true,
                          "write summary.json at the end: pattern class and metrics per species "
                          "(2-D; the middle z slice in 3-D) and linear stability");
}

void Simulation::step() {
  // Parameters using t: once per step, at t (explicit Euler) or at the split step's midpoint
  // (second order with Strang); the TS right-hand side evaluates them at its stage times.
  if (timed_->any() && !ts_) timed_->set_time(params_, split_ ? t_ + 0.5 * dt_ : t_);
  stepper_->step(u_, t_, dt_, step_ + 1);
  check_timed_stability();
  // Advection after reaction and diffusion (stable-ARD section 5.2), then the constraints again
  // (pinned cells, the clamp floor under cubic overshoots).
  if (fluid_) fluid_->step(dt_); // the velocity of [t, t + dt] (stable-ARD section 5)
  if (advection_) {
    advection_->apply(u_, t_, dt_);
    terms_.constrain(u_);
  }
  t_ += dt_;
  ++step_;
}

// -explicit_fuse_steps k: temporal blocking of the explicit integrator where it applies;
// elsewhere one step per pass, with a log line saying why.
void Simulation::read_fuse(Options& opt) {
  const char* key = "explicit_fuse_steps";
  if (split_ || ts_) {
    for (const char* k : {key, "explicit_in_place", "explicit_fuse_tile", "explicit_vector_width",
                          "explicit_prefetch"})
      if (opt.is_set(k))
        throw UserError(std::string("-") + k + ": applies to -integrator explicit only");
    if (split_fuse_) read_split_fuse();
    return;
  }
  const PetscInt asked = opt.integer(
      key, 0, 0, 64,
      "explicit steps fused per pass over the grid (temporal blocking: a k-cell halo exchanged "
      "once per k steps; 2-D periodic fast path, else 1; results bitwise those of 1); 0: "
      "automatic, 8 where fused steps apply and the state averages at least 8 MiB per rank, "
      "else 1");
  integrator_->set_fuse_tile(opt.integer(
      "explicit_fuse_tile", 0, 0, 1 << 30,
      "owned columns per tile of a fused pass (0: automatic, the widest tile whose rows of the "
      "pass's steps stay within 1 MiB, half a typical L2 cache); the same results for any width"));
  const std::string in_place = opt.choice(
      "explicit_in_place", "auto", {"auto", "yes", "no"},
      "fast path (2-D and 3-D): update the state in place, with no second state set (8 bytes per "
      "cell and species less); auto: where a rank's state is at least 8 MiB (3-D: 64 MiB); "
      "the same results");
  integrator_->set_in_place(in_place == "yes"  ? ExplicitIntegrator::InPlace::Always
                            : in_place == "no" ? ExplicitIntegrator::InPlace::Never
                                               : ExplicitIntegrator::InPlace::Auto);
  const std::string prefetch = opt.choice(
      "explicit_prefetch", "auto", {"auto", "yes", "no"},
      "explicit fast path, single steps: software prefetch of the row read from memory two rows "
      "after the stencil's leading row (box stencils: by the row kernel between its cells; auto: "
      "where a rank's state is at least 8 MiB); the same results");
  integrator_->set_prefetch(prefetch == "yes"  ? ExplicitIntegrator::Prefetch::Always
                            : prefetch == "no" ? ExplicitIntegrator::Prefetch::Never
                                               : ExplicitIntegrator::Prefetch::Auto);
  read_vector_width(opt);
  const std::string why = fuse_blocker(integrator_->fuse_unsupported());
  const PetscInt k = asked > 0 ? asked : why.empty() ? integrator_->auto_fuse_steps() : 1;
  integrator_->set_fuse_steps(static_cast<int>(k));
  fuse_ = why.empty() ? k : 1;
  if (asked > 1 && !why.empty())
    PetscPrintf(comm_, "explicit_fuse_steps %lld: fused steps need %s; one step per pass\n",
                static_cast<long long>(asked), why.c_str());
  if (asked == 0 && fuse_ > 1)
    PetscPrintf(comm_,
                "explicit_fuse_steps auto: up to %lld steps per pass (a large state; "
                "-explicit_fuse_steps 1: one step per pass, the same results)\n",
                static_cast<long long>(fuse_));
}

// -explicit_vector_width auto|256|512: which compile of the fused row kernel the explicit
// fast path runs (the same results; auto: the faster in the first passes, timed per rank).
void Simulation::read_vector_width(Options& opt) {
  const std::string w = opt.choice(
      "explicit_vector_width", "auto", {"auto", "256", "512"},
      "explicit fast path: the row kernel compiled with 256- or 512-bit vectors (the same "
      "results); auto: each rank times both in its first passes and keeps the faster (512 "
      "only where the build's CPU has AVX-512)");
  integrator_->set_vector_width(w == "256"   ? KernelChoice::Mode::Narrow
                                : w == "512" ? KernelChoice::Mode::Wide
                                             : KernelChoice::Mode::Auto,
                                fused_row_kernel(true));
}

// The model's fused row kernel for this stencil and parameter form, 256- or 512-bit compile;
// nullptr for a model without fused kernels (a runtime model: the general path).
ExplicitIntegrator::RowFn Simulation::fused_row_kernel(bool wide) const {
  const ModelKernels& mk = model_->kernels;
  if (!mk.fused) return nullptr;
  RowStencil rows;
  to_rows(stencil_, rows);
  return mk.row_kernel(params_.field_mask(), rows.nrows, rows.box, wide);
}

std::string Simulation::explicit_vector_width() const {
  if (split_ || ts_ || integrator_->general() || !model_->kernels.fused) return "";
  return integrator_->vector_width();
}

// -split_fuse_reaction: fused Strang passes as long as nothing observes the state (the run loop
// ends a pass there), where the run has no per-step work besides the split step.
void Simulation::read_split_fuse() {
  const std::string why = fuse_blocker(split_integrator_->fuse_unsupported());
  fuse_ = why.empty() ? kMaxFusedSplitSteps : 1;
  if (!why.empty())
    PetscPrintf(comm_, "split_fuse_reaction: fused steps need %s; one step per pass\n",
                why.c_str());
}

// What fused steps need that the run lacks: the integrator's reason `why` if any, else
// parameters constant in time, else no advection or fluid; "" when steps can be fused.
std::string Simulation::fuse_blocker(std::string why) const {
  if (why.empty() && timed_->any()) why = "parameters constant in time";
  if (why.empty() && (fluid_ || advection_)) why = "no advection or fluid";
  return why;
}

void Simulation::advance(PetscInt n) {
  if (n <= 1) {
    step();
    return;
  }
  if (split_)
    split_integrator_->steps(u_, t_, dt_, step_ + 1, static_cast<int>(n));
  else
    integrator_->steps(u_, t_, dt_, static_cast<int>(n));
  for (PetscInt i = 0; i < n; ++i) { // the clock of n single steps, bit for bit
    t_ += dt_;
    ++step_;
  }
}

std::vector<const DiffusionOperator*> Simulation::operators() const {
  std::vector<const DiffusionOperator*> out;
  for (const auto& op : ops_)
    out.push_back(op.get());
  return out;
}

bool Simulation::all_constant_diffusion() const {
  for (const auto& op : ops_)
    if (!op->constant()) return false;
  return true;
}

namespace {

// A run that blows up may stay finite for a long time (a checkerboard growing to 1e69): values
// beyond the classifier's blow-up bound (analysis::kBlowupBound) count as diverged.
constexpr double kBlowup = 1e10;

// The first of n cells that is NaN, infinite or beyond kBlowup, or -1. The row is scanned with
// an integer OR (vectorised), the cell found only when there is one.
PetscInt first_diverged(const double* __restrict__ a, PetscInt n) {
  int bad = 0;
  for (PetscInt i = 0; i < n; ++i)
    bad |= !(std::fabs(a[i]) <= kBlowup);
  if (!bad) return -1;
  for (PetscInt i = 0; i < n; ++i)
    if (!(std::fabs(a[i]) <= kBlowup)) return i;
  return -1;
}

} // namespace

void Simulation::check_finite() const {
  std::string err;
  const Box& ob = grid_->owned();
  for (size_t s = 0; s < u_.size() && err.empty(); ++s) {
    const PetscScalar* a;
    MG_PETSC(VecGetArrayRead(u_[s], &a));
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2] && err.empty(); ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1] && err.empty(); ++j) {
        const double* row = a + grid_->local_index(ob.s[0], j, k);
        const PetscInt x = first_diverged(row, ob.m[0]);
        if (x < 0) continue;
        const double v = row[x];
        err = "species " + species_[s] + " became " + format_number(v) +
              (std::isfinite(v) ? " (over the blow-up bound 1e10)" : "") + " at cell (" +
              std::to_string(ob.s[0] + x) + "," + std::to_string(j) + "," + std::to_string(k) +
              ") by step " + std::to_string(step_) + " (t = " + format_number(t_) +
              "): the run diverged; reduce -dt" +
              (floor_[s] == 0.0 ? std::string() : std::string(" or try -clamp true"));
      }
    MG_PETSC(VecRestoreArrayRead(u_[s], &a));
  }
  throw_if_any(comm_, err);
}

} // namespace morphogen
