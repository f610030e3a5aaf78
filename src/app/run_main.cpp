#include "app/run_main.hpp"

#include "app/deck.hpp"
#include "app/help.hpp"
#include "app/path_check.hpp"
#include "app/png_output.hpp"
#include "app/restart.hpp"
#include "app/run_loop.hpp"
#include "app/simulation.hpp"
#include "core/collective_error.hpp"
#include "core/user_error.hpp"

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <vector>

namespace morphogen {

namespace {

void print_header(MPI_Comm comm, const Simulation& sim, int level, int levels) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  const auto& g = sim.grid().spec();
  if (levels > 1) PetscPrintf(comm, "level %d/%d: ", level + 1, levels);
  PetscPrintf(comm, "morphogen %s: model %s, grid %lld", MORPHOGEN_VERSION, sim.model().name,
              static_cast<long long>(g.n[0]));
  for (int d = 1; d < g.dim; ++d)
    PetscPrintf(comm, "x%lld", static_cast<long long>(g.n[d]));
  PetscPrintf(comm, " (%s", boundary_name(g.bc[0]));
  for (int d = 1; d < g.dim; ++d)
    PetscPrintf(comm, ",%s", boundary_name(g.bc[d]));
  PetscPrintf(comm, "), %s stencil, dt %s (explicit bound %s), %lld steps, %d rank%s -> %s/\n",
              sim.stencil().name.c_str(), format_number(sim.dt()).c_str(),
              format_number(sim.stable_dt()).c_str(), static_cast<long long>(sim.steps()), size,
              size == 1 ? "" : "s", sim.output().dir.c_str());
  PetscPrintf(comm, "%s", sim.terms().describe().c_str());
}

} // namespace

int run_main(int* argc, char*** argv, double wall_start,
             const std::vector<OptionsFileArg>& options_files) {
  MPI_Comm comm = PETSC_COMM_WORLD;
  const std::string deck_dir = load_deck(argc, argv, options_files);
  Options opt(comm);
  const std::string base_dir = read_deck_dir(opt, deck_dir);
  if (opt.is_set("sweep_axes"))
    throw UserError("-sweep_axes: this deck is a sweep; run it with morphogen sweep DECK.yaml");
  if (opt.is_set("screen_params"))
    throw UserError("-screen_params: this is a Turing screen; run it with morphogen screen "
                    "DECK.yaml (or morphogen screen -screen_params ...)");
  // Coarse-to-fine grid sequencing (Witkin-Kass 5.2, Lawlor): levels 1..L-1 run on grids
  // coarsened by 2^(L-1-l) for -sequence_steps steps each, the last on -grid_n for -steps.
  const int levels = static_cast<int>(
      opt.integer("sequence_levels", 1, 1, 8,
                  "coarse-to-fine grid sequencing: number of levels, each twice as fine as the "
                  "previous; the last is -grid_n"));
  std::vector<PetscInt> level_steps;
  if (levels > 1)
    for (const auto& v :
         opt.list("sequence_steps", {}, static_cast<size_t>(levels - 1),
                  static_cast<size_t>(levels - 1), "steps on each coarse level, coarsest first")) {
      const PetscInt n = Options::parse_int("sequence_steps", v);
      if (n < 0) throw UserError("-sequence_steps " + v + ": must be >= 0");
      level_steps.push_back(n);
    }
  const std::string restart =
      opt.string("restart", "",
                 "restart from a checkpoint file, or 'latest': the newest complete checkpoint in "
                 "-output_dir (none there: start from the initial condition)");
  auto first = std::make_unique<Simulation>(comm, opt, base_dir, SequenceLevel{0, levels, nullptr});
  PngOutput pngs(opt, *first);
  if (opt.help_requested()) {
    print_options_help(comm, {&opt});
    print_models_help(comm);
    return 0;
  }
  const ModelEntry& m = first->model();
  std::string species; // a run-time model's own names (layers: a1, b1, ...; custom)
  for (int s = 0; s < m.nspecies && m.storage; ++s)
    species += (species.empty() ? "" : ", ") + std::string(m.species[s].name);
  const std::string model = m.name;
  opt.set_unknown_hint([model, species](const std::string& name) {
    return species.empty() ? other_model_hint(name, model) : "this run's species are " + species;
  });
  opt.check_unused();
  // A directory name that cannot be created whole fails before any parent is created.
  if (const std::string bad = directory_name_problem(first->output().dir); !bad.empty())
    throw UserError("-output_dir " + first->output().dir.substr(0, 40) + "...: " + bad);
  std::optional<RestartPoint> rp;
  if (!restart.empty()) rp = locate_restart(comm, restart, first->output().dir, first->model());
  const int start = rp ? rp->level : 0;
  if (start >= levels)
    throw UserError("-restart " + rp->path + ": written on grid-sequencing level " +
                    std::to_string(start + 1) + ", but -sequence_levels is " +
                    std::to_string(levels));
  if (rp) { // refuse a mismatched checkpoint before anything is written
    PetscInt end_at_start = 0;
    for (int l = 0; l <= start; ++l)
      end_at_start += l + 1 < levels ? level_steps[l] : first->steps();
    if (rp->step > end_at_start)
      throw UserError("-restart " + rp->path + ": the checkpoint is at step " +
                      std::to_string(rp->step) + ", past the end of the run (step " +
                      std::to_string(end_at_start) + "); raise -steps");
    if (start == 0) check_restart_grid(*first, *rp);
  }
  RunOutput output(comm, opt, wall_start);
  output.prepare(*first); // options_used.yaml is replaced when the run writes its first file
  std::unique_ptr<Simulation> prev;
  PetscInt end = 0; // global step index at which the current level ends
  for (int l = 0; l < levels; ++l) {
    if (l < start) {
      end += level_steps[l];
      continue;
    }
    std::unique_ptr<Simulation> sim =
        l == 0
            ? std::move(first)
            : std::make_unique<Simulation>(
                  comm, opt, base_dir, SequenceLevel{l, levels, l == start ? nullptr : prev.get()});
    if (l + 1 < levels) sim->set_steps(level_steps[l]);
    end += sim->steps();
    const bool restarting = rp && l == start;
    if (restarting) {
      if (rp->step > end)
        throw UserError("-restart " + rp->path + ": the checkpoint is at step " +
                        std::to_string(rp->step) + ", past the end of the run (step " +
                        std::to_string(end) + "); raise -steps");
      restore(*sim, *rp);
      const long long* nranks = rp->info.attributes.integer("nranks");
      PetscPrintf(comm, "restart from %s: step %lld, t %s (written on %lld rank%s)\n",
                  rp->path.c_str(), rp->step, format_number(rp->time).c_str(),
                  nranks ? *nranks : 0LL, nranks && *nranks == 1 ? "" : "s");
    }
    output.begin(*sim, restarting ? rp->step : (l == 0 ? -1 : sim->step_index()), end);
    print_header(comm, *sim, l, levels);
    if (run_loop(*sim, end, output, pngs, l + 1 == levels)) return kExitResubmit;
    prev = std::move(sim);
  }
  const std::string& dir = prev->output().dir;
  PetscPrintf(comm,
              "done: ParaView %s/%s.xmf, images %s/*_final.png, checkpoint %s, options "
              "%s/options_used.yaml\n",
              dir.c_str(), prev->output().name.c_str(), dir.c_str(),
              output.last_checkpoint().empty() ? "(none)" : output.last_checkpoint().c_str(),
              dir.c_str());
  return 0;
}

} // namespace morphogen
