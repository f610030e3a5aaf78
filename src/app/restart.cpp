#include "app/restart.hpp"

#include "core/collective_error.hpp"
#include "core/options.hpp"
#include "core/petsc_handle.hpp"
#include "core/user_error.hpp"
#include "io/checkpoint_files.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

namespace morphogen {

namespace {

// "" if the file is a complete checkpoint, else why not.
std::string check_complete(const io::ImageInfo& info) {
  const auto& a = info.attributes;
  const long long* complete = a.integer("complete");
  if (!complete || *complete != 1 || !a.real("time") || !a.integer("step") || !a.integer("level"))
    return "no complete /morphogen restart record (a snapshot, or an interrupted write)";
  return {};
}

// "" if every attribute of a complete checkpoint is in range, else "attribute NAME = VALUE:
// allowed ..." for the first one that is not (a NaN time would otherwise reach the JSON
// broadcast, a negative step would run and retire the checkpoint chain).
std::string check_attributes(const io::ImageInfo& info) {
  const auto& a = info.attributes;
  const auto real = [&](const char* name, double lo, bool open_lo, bool required) -> std::string {
    const double* v = a.real(name);
    if (!v) return required ? std::string("attribute /morphogen/") + name + " missing" : "";
    if (std::isfinite(*v) && (open_lo ? *v > lo : *v >= lo)) return {};
    return std::string("attribute /morphogen/") + name + " = " + format_number(*v) +
           ": allowed a finite number " + (open_lo ? "> " : ">= ") + format_number(lo);
  };
  const auto integer = [&](const char* name, long long lo, long long hi) -> std::string {
    const long long* v = a.integer(name);
    if (!v || (*v >= lo && *v <= hi)) return {};
    return std::string("attribute /morphogen/") + name + " = " + std::to_string(*v) + ": allowed " +
           (hi == std::numeric_limits<long long>::max()
                ? ">= " + std::to_string(lo)
                : "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  };
  constexpr long long big = std::numeric_limits<long long>::max();
  for (const std::string& e :
       {real("time", 0, false, true), real("dt", 0, true, false), integer("step", 0, big),
        integer("level", 0, 7), integer("nranks", 1, big), integer("seed", 0, big)})
    if (!e.empty()) return e;
  for (int d = 0; d < 3; ++d) {
    const std::string axis = std::string(1, "xyz"[d]);
    if (info.n[d] < 1)
      return "/VTKHDF WholeExtent: " + std::to_string(info.n[d]) + " cells along " + axis +
             ", allowed >= 1";
    if (!std::isfinite(info.origin[d]))
      return "/VTKHDF Origin " + axis + " = " + format_number(info.origin[d]) +
             ": allowed a finite number";
    if (!(std::isfinite(info.spacing[d]) && info.spacing[d] > 0))
      return "/VTKHDF Spacing " + axis + " = " + format_number(info.spacing[d]) +
             ": allowed a finite number > 0";
  }
  return {};
}

// "" if a complete checkpoint fits this run's model, else why not.
std::string check_model(const io::ImageInfo& info, const ModelEntry& model) {
  const auto& a = info.attributes;
  const std::string* m = a.string("model");
  if (!m || *m != model.name)
    return "written by model " + (m ? *m : std::string("?")) + ", this run uses " + model.name;
  for (int s = 0; s < model.nspecies; ++s) {
    bool found = false;
    for (const auto& n : info.arrays)
      found |= n == model.species[s].name;
    if (!found) return std::string("no field for species ") + model.species[s].name;
  }
  if (info.precision != 8) return "fields are not float64";
  return {};
}

// "" if the checkpoint's fluid state fits this run, else why not: a -fluid run needs the
// fluid's state (a checkpoint without it would silently restart the flow from rest), and a run
// without -fluid refuses a checkpoint that has one (its flow would silently stop).
std::string check_fluid(const io::ImageInfo& info, const FluidSolver* fluid) {
  const std::string* kind = info.attributes.string("fluid");
  if (!fluid && kind)
    return "the checkpoint holds the flow of -fluid " + *kind +
           ", this run has no -fluid (add -fluid " + *kind + " to continue it)";
  if (!fluid) return {};
  if (!kind)
    return "the checkpoint has no fluid state (written without -fluid, or by a morphogen that "
           "did not checkpoint the flow), this run has -fluid " +
           fluid->kind_name() + " (restart without -fluid, or start the run afresh)";
  for (const auto& [name, vec] : fluid->state()) {
    bool found = false;
    for (const auto& n : info.arrays)
      found |= n == name;
    if (!found) return "the checkpoint of -fluid " + *kind + " has no dataset " + name;
  }
  return {};
}

void bcast_string(MPI_Comm comm, std::string& s) {
  long long n = static_cast<long long>(s.size());
  MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, comm);
  s.resize(static_cast<size_t>(n));
  MPI_Bcast(s.data(), static_cast<int>(n), MPI_CHAR, 0, comm);
}

} // namespace

std::optional<RestartPoint> locate_restart(MPI_Comm comm, const std::string& spec,
                                           const std::string& dir, const ModelEntry& model) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::string err, path, json;
  if (rank == 0) {
    std::string why;
    if (spec == "latest") {
      for (const auto& [step, p] : io::list_checkpoints(dir)) {
        auto info = io::inspect_vtkhdf(p, why);
        if (info) why = check_complete(*info);
        if (info && why.empty()) {
          // A complete checkpoint of another model, or with attributes out of range, is a
          // mistake, not a reason to start over (which would retire the whole chain).
          std::string wrong = check_attributes(*info);
          if (wrong.empty()) wrong = check_model(*info, model);
          path = p;
          if (!wrong.empty())
            err = "-restart latest: " + p + ": " + wrong;
          else
            json = info->to_json();
          break;
        }
        std::fprintf(stderr, "morphogen: warning: -restart latest: skipping %s: %s\n", p.c_str(),
                     why.c_str());
      }
      if (path.empty() && err.empty())
        std::printf("note: -restart latest: no usable checkpoint in %s/, starting from the initial "
                    "condition\n",
                    dir.c_str());
    } else {
      auto info = io::inspect_vtkhdf(spec, why);
      if (info) why = check_complete(*info);
      if (info && why.empty()) why = check_attributes(*info);
      if (info && why.empty()) why = check_model(*info, model);
      if (!info || !why.empty())
        err = "-restart " + spec + ": not a usable checkpoint: " + why +
              " (allowed: a checkpoint_*.vtkhdf file or 'latest')";
      path = spec;
      if (info && err.empty()) json = info->to_json();
    }
    std::fflush(stdout);
  }
  throw_if_any(comm, err);
  bcast_string(comm, path);
  bcast_string(comm, json);
  if (json.empty()) return std::nullopt;
  RestartPoint rp;
  rp.path = path;
  rp.info = io::ImageInfo::from_json(json);
  rp.step = *rp.info.attributes.integer("step");
  rp.time = *rp.info.attributes.real("time");
  rp.level = static_cast<int>(*rp.info.attributes.integer("level"));
  return rp;
}

void check_restart_grid(const Simulation& sim, const RestartPoint& rp) {
  const auto& g = sim.grid().spec();
  for (int d = 0; d < 3; ++d) {
    const long long n = d < g.dim ? g.n[d] : 1;
    const bool spacing_ok =
        d >= g.dim || std::fabs(rp.info.spacing[d] - g.h(d)) <= 1e-12 * std::fabs(g.h(d));
    if (rp.info.n[d] != n || !spacing_ok)
      throw UserError(
          "-restart " + rp.path + ": grid " + std::to_string(rp.info.n[0]) + "x" +
          std::to_string(rp.info.n[1]) + "x" + std::to_string(rp.info.n[2]) + " with spacing " +
          format_double(rp.info.spacing[0]) + " does not match this run's -grid_n/-grid_L" +
          (sim.level() > 0 || rp.level > 0 ? " (sequencing level " + std::to_string(rp.level) + ")"
                                           : std::string()));
  }
  const std::string why = check_fluid(rp.info, sim.fluid());
  if (!why.empty()) throw UserError("-restart " + rp.path + ": " + why);
}

namespace {

// "" if every value of the state (ghosts refreshed) is finite on this rank, else the first
// species that is not, with the value: a checkpoint that holds a NaN or an infinity is refused
// at the start instead of being reported as a divergence later.
std::string non_finite_state(Simulation& sim) {
  for (size_t s = 0; s < sim.state().size(); ++s) {
    const PetscScalar* a = nullptr;
    PetscInt n = 0;
    MG_PETSC(VecGetLocalSize(sim.state()[s], &n));
    MG_PETSC(VecGetArrayRead(sim.state()[s], &a));
    double bad = 0;
    for (PetscInt i = 0; i < n && std::isfinite(bad); ++i)
      bad = std::isfinite(a[i]) ? 0.0 : a[i];
    MG_PETSC(VecRestoreArrayRead(sim.state()[s], &a));
    if (!std::isfinite(bad))
      return "species " + sim.species()[s] + " holds a non-finite value (" + format_number(bad) +
             ")";
  }
  return {};
}

} // namespace

void restore(Simulation& sim, const RestartPoint& rp) {
  check_restart_grid(sim, rp);
  std::vector<Vec> fields;
  for (auto& v : sim.state())
    fields.push_back(v);
  io::VtkHdfIO io(sim.grid());
  const std::string err = io.read(rp.path, sim.species(), fields);
  throw_if_any(sim.grid().comm(),
               err.empty() ? err : "-restart " + rp.path + ": cannot read the fields: " + err);
  if (FluidSolver* fluid = sim.fluid()) {
    std::vector<std::string> names;
    std::vector<Vec> vecs;
    for (const auto& [name, vec] : fluid->state()) {
      names.push_back(name);
      vecs.push_back(vec);
    }
    const std::string ferr = io.read(rp.path, names, vecs);
    throw_if_any(sim.grid().comm(),
                 ferr.empty() ? ferr
                              : "-restart " + rp.path + ": cannot read the fluid state: " + ferr);
    fluid->state_restored();
  }
  sim.set_clock(rp.time, static_cast<PetscInt>(rp.step));
  sim.refresh_ghosts();
  const std::string bad = non_finite_state(sim);
  throw_if_any(sim.grid().comm(), bad.empty() ? bad : "-restart " + rp.path + ": " + bad);
}

} // namespace morphogen
