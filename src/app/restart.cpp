#include "app/restart.hpp"

#include "core/collective_error.hpp"
#include "core/user_error.hpp"
#include "io/checkpoint_files.hpp"

#include <cmath>
#include <cstdio>

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
          // A complete checkpoint of another model is a mistake, not a reason to start over
          // (which would retire the whole chain).
          const std::string wrong = check_model(*info, model);
          if (!wrong.empty()) err = "-restart latest: " + p + ": " + wrong;
          path = p;
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
      if (info && why.empty()) why = check_model(*info, model);
      if (!info || !why.empty())
        err = "-restart " + spec + ": not a usable checkpoint: " + why +
              " (allowed: a checkpoint_*.vtkhdf file or 'latest')";
      path = spec;
      if (info) json = info->to_json();
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
}

void restore(Simulation& sim, const RestartPoint& rp) {
  check_restart_grid(sim, rp);
  std::vector<Vec> fields;
  for (auto& v : sim.state())
    fields.push_back(v);
  io::VtkHdfIO io(sim.grid());
  const std::string err = io.read(rp.path, sim.species(), fields);
  throw_if_any(sim.grid().comm(),
               err.empty() ? err : "-restart " + rp.path + ": cannot read the fields: " + err);
  sim.set_clock(rp.time, static_cast<PetscInt>(rp.step));
  sim.refresh_ghosts();
}

} // namespace morphogen
