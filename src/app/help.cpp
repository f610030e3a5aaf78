#include "app/help.hpp"

#include "app/model_registry.hpp"

#include <map>
#include <string>

namespace morphogen {

namespace {

bool starts_with(const std::string& s, const std::string& p) {
  return s.compare(0, p.size(), p) == 0;
}

// Topics, in the order listed, with the name prefixes of their options.
const std::vector<std::pair<const char*, std::vector<const char*>>>& topics() {
  static const std::vector<std::pair<const char*, std::vector<const char*>>> groups = {
      {"Model and values",
       {"model", "layers", "species", "rate_", "jac_", "params_", "D_", "init_", "dirichlet_",
        "source_", "pin_", "clamp", "seed"}},
      {"Grid", {"grid_", "stencil", "sequence_"}},
      {"Diffusion", {"diffusion", "tensor_", "surface_", "polar_", "shaped_"}},
      {"Time integration", {"integrator", "dt", "force_dt", "steps", "split_", "ts_", "explicit_"}},
      {"Advection", {"advect", "velocity_", "fluid"}},
      {"Checkpoints and restart", {"checkpoint_", "restart", "max_walltime"}},
      {"Output",
       {"output_", "png_", "snapshot_", "summary", "progress_every", "nan_check_every", "movie_"}},
      {"Sweep", {"sweep_"}},
      {"Other", {""}},
  };
  return groups;
}

// Topic of an option, by its name.
const char* group_of(const std::string& n) {
  for (const auto& [group, prefixes] : topics())
    for (const char* p : prefixes)
      if (starts_with(n, p)) return group;
  return "Other";
}

// Options read only in some configurations, in generic form: listed when this configuration
// read none of them. {prefix that marks them as read, usage, help}.
struct Conditional {
  const char *read_prefix, *usage, *help;
};
const Conditional kConditional[] = {
    {"source_", "-source_<species> VALUE",
     "source term added to the species' reaction rate; may use t (default: none)"},
    {"pin_", "-pin_<species> MASK",
     "cells held at their initial value where the mask is non-zero (default: none)"},
    {"ts_diffusion_solver", "-ts_diffusion_solver auto|ksp|spectral",
     "with -integrator ts and implicit diffusion: each stage's linear solve by the exact "
     "FFT/DCT inverse (spectral), by -ksp_type/-pc_type (ksp), or spectral where it applies "
     "(auto, default)"},
    {"explicit_",
     "-explicit_fuse_steps K, -explicit_fuse_tile N, -explicit_in_place auto|yes|no, "
     "-explicit_vector_width auto|256|512, -explicit_prefetch auto|yes|no",
     "with -integrator explicit: K steps fused per pass (temporal blocking; 0, the default: 8 "
     "for large 2-D periodic states, else 1), owned columns per "
     "tile of a fused pass, the in-place update, the row kernel compiled with 256- or "
     "512-bit vectors (auto: timed per rank), and software prefetch of the rows read from "
     "memory; all give the same results"},
    {"ts_diffusion", "-ts_diffusion implicit|explicit",
     "with -integrator ts: diffusion implicit (IMEX) or in the explicit right-hand side "
     "(default implicit)"},
    {"dirichlet_", "-dirichlet_<species> VALUE",
     "boundary value on Dirichlet faces, an expression of the face position that may use t "
     "(re-evaluated once per step, or at the TS stage times) (default: the species' initial "
     "value; with -grid_bc dirichlet)"},
    {"png_range_", "-png_range_<species> LO,HI",
     "fixed colour range of the species' images (default: from the data)"},
    {"diffusion_", "-diffusion_<species> iso|tensor|polar|shaped",
     "diffusion of one species (default: -diffusion)"},
    {"polar_", "-polar_form cosine|witkin_kass, -polar_lobes J, -polar_speeds A1,..,AJ",
     "with -diffusion polar: D_S a(theta), theta the angle of grad u; j cosine lobes with a "
     "speed each (stable-ARD eq. 16; default 4 lobes, speeds 1) or Witkin-Kass's four lobes "
     "(eq. 15, speeds a1,a2); also -polar_<species>_<name>"},
    {"polar_", "-polar_theta0 VALUE",
     "with -diffusion polar: rotation of a(theta + theta0) in radians, a number or any value "
     "(field) (default 0)"},
    {"shaped_", "-shaped_I I, -shaped_vx VALUE, -shaped_vy VALUE, -shaped_vz VALUE",
     "with -diffusion shaped: the -tensor_theta/l1/l2 tensor with l1 + dl, l2 - dl, dl = I "
     "(grad u/|grad u|).(v/|v|) (Sanderson eqs. 18-19; default I 0.25, v the first principal "
     "direction); also -shaped_<species>_<name>"},
    {"tensor_", "-tensor_<name>, -tensor_<species>_<name>",
     "diffusion tensor (theta, l1, l2[, phi, l3] or xx, xy, yy[, xz, yz, zz]; with -diffusion "
     "tensor)"},
    {"split_", "-split_ordering lie|strang",
     "operator splitting order (default strang; with -integrator split)"},
    {"split_", "-split_reaction euler|heun|rk4|backward_euler|trapezoidal",
     "reaction substep (default trapezoidal with strang, backward_euler with lie)"},
    {"split_", "-split_diffusion backward_euler|crank_nicolson",
     "diffusion substep (default crank_nicolson with strang, backward_euler with lie)"},
    {"split_", "-split_newton_tol X, -split_newton_max_it N",
     "per-cell Newton tolerance (default 1e-12, allowed [1e-16, 0.01]) and iteration cap "
     "(default 20, allowed [1, 1000])"},
    {"split_", "-split_fuse_reaction true|false, -split_fuse_planes true|false",
     "Strang: merge the reaction half-steps of consecutive steps that nothing observes in between "
     "(default false); run a reaction substep inside the next diffusion substep's first pass "
     "where every diffusing species is solved by the tridiagonal method (default true, bitwise "
     "the same)"},
    {"advect", "-advect a,b",
     "species carried by the velocity: semi-Lagrangian advection after reaction and diffusion "
     "each step, with every integrator (default: none)"},
    {"advect", "-velocity_x EXPR, -velocity_y EXPR, -velocity_z EXPR",
     "with -advect: velocity components, expressions of x, y, z, t (default 0; once per step "
     "at t + dt/2 if t is used)"},
    {"advect", "-advection_scheme linear|cubic, -advection_backtrace rk2|euler",
     "with -advect: interpolation at the departure point (default linear) and its back-trace "
     "(default rk2; euler is the stable-ARD paper's eq. 20)"},
    {"advect", "-advection_halo W",
     "with -advect: halo width in cells (default 0: from max|u| dt/h at the start; at most 64)"},
    {"velocity_file", "-velocity_file FILE|A,B,..|S.series, -velocity_datasets X,Y[,Z]",
     "with -advect: velocity from HDF5/VTKHDF files instead of -velocity_x/_y: one file "
     "(steady), a comma list, a numbered pattern (flow_%04d.h5: from 0 or 1 to the first "
     "missing) or a .series JSON file (linear in t between frames, end frames "
     "held outside); component datasets (default velocity_x,velocity_y[,velocity_z])"},
    {"velocity_time", "-velocity_times T1,T2,.., -velocity_time_attribute /object/name",
     "with a comma list in -velocity_file: the files' times (default: each file's attribute "
     "/morphogen/time)"},
    {"fluid_", "-fluid_viscosity NU, -fluid_lid_speed U, -fluid_inflow U, -fluid_obstacle EXPR",
     "with -fluid: viscosity (default 0.01), cavity lid speed and channel inflow (default 1), "
     "solid cells where EXPR > 0.5 (default none)"},
    {"fluid_", "-fluid_substeps N, -fluid_scheme linear|cubic",
     "with -fluid: substeps per step (default 1), self-advection interpolation (default linear)"},
    {"sequence_steps", "-sequence_steps N1,...",
     "steps on each coarse level, coarsest first (with -sequence_levels L > 1: L-1 values)"},
    {"", "-fluid_ksp_*, -fluid_pc_*, -fluid_visc_ksp_*, -fluid_visc_pc_*",
     "PETSc KSP/PC options of the fluid's pressure solve (default cg/gamg) and viscosity "
     "solves (default cg/jacobi)"},
    {"", "-diffusion_ksp_*, -diffusion_pc_*",
     "PETSc KSP/PC options of the diffusion solves (split and ts integrators; see -help petsc)"},
    {"", "-ts_*, -snes_*, -ksp_*, -pc_*",
     "PETSc TS options (with -integrator ts; see -help petsc)"},
    {"", "-options_file FILE, -options_file_yaml FILE",
     "more options from a file (after the deck, before the command line)"},
    {"", "-help [petsc], -h, --help", "this listing; with petsc, PETSc's own options too"},
    {"", "-version, --version", "morphogen's and PETSc's versions"},
};

} // namespace

void print_options_help(MPI_Comm comm, const std::vector<const Options*>& opts) {
  std::map<std::string, std::vector<const Options::Record*>> by_group;
  std::map<std::string, bool> seen;
  for (const Options* o : opts)
    for (const auto& r : o->records()) {
      if (seen[r.name]) continue;
      seen[r.name] = true;
      by_group[group_of(r.name)].push_back(&r);
    }
  PetscPrintf(comm,
              "morphogen %s: morphogen [DECK.yaml] [-option value ...]\n"
              "Options read by this configuration (-name <current value>: meaning):\n",
              MORPHOGEN_VERSION);
  for (const auto& [g, prefixes] : topics()) {
    if (by_group[g].empty()) continue;
    PetscPrintf(comm, "\n%s:\n", g);
    for (const auto* r : by_group[g])
      PetscPrintf(comm, "  -%s <%s>: %s\n", r->name.c_str(), r->value.c_str(), r->help.c_str());
  }
  PetscPrintf(comm, "\nOther options (read only in other configurations):\n");
  for (const auto& c : kConditional) {
    bool read = false;
    for (const auto& [name, s] : seen)
      read |= c.read_prefix[0] != '\0' && starts_with(name, c.read_prefix);
    if (!read) PetscPrintf(comm, "  %s: %s\n", c.usage, c.help);
  }
}

void print_models_help(MPI_Comm comm) {
  PetscPrintf(comm, "\nModels (-model NAME):\n");
  for (const auto& m : model_registry()) {
    PetscPrintf(comm, "  %-18s %s (%s)\n", m.name, m.doc, m.reference);
    for (int s = 0; s < m.nspecies; ++s)
      PetscPrintf(comm, "      species %-6s D %-10s init %-10s %s\n", m.species[s].name,
                  format_number(m.species[s].D).c_str(), format_number(m.species[s].init).c_str(),
                  m.species[s].doc);
    for (int q = 0; q < m.nparams; ++q)
      PetscPrintf(comm, "      param   %-6s default %-10s %-22s %s\n", m.params[q].name,
                  format_number(m.params[q].def).c_str(),
                  allowed_range(m.params[q].lo, m.params[q].hi).c_str(), m.params[q].doc);
  }
  PetscPrintf(comm, "  %-18s %s\n", "custom",
              "user-defined kinetics: -species a,b and -rate_a EXPR, -rate_b EXPR (muParser, "
              "functions of the species); every other name in a rate is a parameter, given "
              "with -params_NAME; optional Jacobian -jac_a_b EXPR (dR_a/db, all entries or "
              "none: central differences) for the implicit paths");
  PetscPrintf(comm, "  %-18s %s\n", "-layers L",
              "L coupled copies of any model (Sanderson et al. 2006, eqs. 20-21): species a1, "
              "b1, a2, b2, ...; parameters alpha1, ...; coupling rates -params_couple_a, ... "
              "between neighbouring layers");
}

std::string other_model_hint(const std::string& option, const std::string& model) {
  const auto us = option.find('_');
  if (us == std::string::npos) return {};
  const std::string kind = option.substr(0, us + 1), name = option.substr(us + 1);
  std::string owners;
  for (const auto& m : model_registry()) {
    bool has = false;
    if (kind == "params_")
      for (int q = 0; q < m.nparams; ++q)
        has |= name == m.params[q].name;
    if (kind == "D_" || kind == "init_" || kind == "source_" || kind == "dirichlet_" ||
        kind == "png_range_")
      for (int s = 0; s < m.nspecies; ++s)
        has |= name == m.species[s].name;
    if (has && model != m.name) owners += (owners.empty() ? "" : ", ") + std::string(m.name);
  }
  if (owners.empty()) return {};
  const std::string what = kind == "params_" ? "a parameter" : "a species";
  return name + " is " + what + " of " + owners + ", not of " + model + " (-model " +
         owners.substr(0, owners.find(',')) + ")";
}

} // namespace morphogen
