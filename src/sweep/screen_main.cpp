// `morphogen screen`: see screen_main.hpp.
#include "sweep/screen_main.hpp"

#include "app/help.hpp"
#include "core/collective_error.hpp"
#include "core/petsc_handle.hpp"
#include "core/user_error.hpp"
#include "io/series_index.hpp"
#include "sweep/screen_output.hpp"
#include "sweep/screen_spec.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace morphogen::sweep {

namespace {

struct Counts {
  long long v[4] = {0, 0, 0, 0}; // by Verdict
};

// Options of the model deck that a screen does not use are allowed; screen_*, params_* and D_*
// ones must have been read (a typo there fails).
void check_unused_screen_options(Options& opt, const std::string& model) {
  PetscInt n = 0;
  char** names = nullptr;
  char** values = nullptr;
  MG_PETSC(PetscOptionsLeftGet(nullptr, &n, &names, &values));
  for (PetscInt i = 0; i < n; ++i) {
    const std::string name = names[i];
    bool strict = false;
    for (const char* pre : {"screen_", "params_", "D_"})
      strict = strict || name.rfind(pre, 0) == 0;
    if (!strict) opt.known(name);
  }
  MG_PETSC(PetscOptionsLeftRestore(nullptr, &n, &names, &values));
  opt.set_unknown_hint([model](const std::string& o) { return other_model_hint(o, model); });
  opt.check_unused();
}

std::string describe_axes(const ScreenSpec& s) {
  std::string axes;
  for (size_t j = 0; j < s.sampler.names.size(); ++j) {
    axes += (j ? " x " : "") + s.sampler.names[j];
    if (s.sampler.sampling == Sampling::Grid)
      axes += "[" + std::to_string(s.sampler.points[j]) + "]";
  }
  const char* how[] = {"grid", "random", "lhs"};
  return axes + ", " + how[static_cast<int>(s.sampler.sampling)];
}

// Classifies this rank's chunks; Turing-unstable rows into `rows`. Returns "" or the error.
std::string screen_chunks(const ScreenSpec& s, MPI_Comm comm, long long chunk, ScreenRows& rows,
                          Counts& counts) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const long long total = s.sampler.total(), nchunks = (total + chunk - 1) / chunk;
  std::vector<double> params = s.params, D = s.D, vals(s.sampler.names.size());
  SetResult res;
  const double t0 = MPI_Wtime();
  double last = t0;
  try {
    for (long long c = rank; c < nchunks; c += size) {
      for (long long i = c * chunk; i < std::min(total, (c + 1) * chunk); ++i) {
        s.sampler.values(i, vals.data());
        for (size_t j = 0; j < vals.size(); ++j)
          (s.axis_target[j] >= 0 ? params[s.axis_target[j]] : D[-1 - s.axis_target[j]]) = vals[j];
        classify_set(*s.model, params, D, s.classify, res);
        ++counts.v[static_cast<int>(res.verdict)];
        if (res.verdict == Verdict::Turing) rows.add(i, vals, res);
      }
      rows.end_chunk(c);
      if (const double now = MPI_Wtime(); rank == 0 && now - last > 10) {
        const double f = static_cast<double>(c / size + 1) / ((nchunks - 1) / size + 1);
        std::printf("screen: %.0f%% of rank 0's sets, ETA %.0f s\n", 100 * f,
                    (now - t0) * (1 - f) / f);
        std::fflush(stdout);
        last = now;
      }
    }
  } catch (const std::exception& e) {
    return std::string("screen: ") + e.what();
  }
  return "";
}

nlohmann::json summary_json(const ScreenSpec& s, const Counts& c, int ranks, double compute_s,
                            double wall_s) {
  const ModelInfo& m = *s.model;
  nlohmann::json j;
  j["model"] = m.name;
  j["sampling"] = describe_axes(s).substr(describe_axes(s).rfind(' ') + 1);
  j["seed"] = s.sampler.seed;
  for (size_t a = 0; a < s.sampler.names.size(); ++a) {
    nlohmann::json ax = {
        {"name", s.sampler.names[a]}, {"lo", s.sampler.lo[a]}, {"hi", s.sampler.hi[a]}};
    if (s.sampler.sampling == Sampling::Grid) ax["points"] = s.sampler.points[a];
    j["varied"].push_back(ax);
  }
  auto screened = [&](int t) {
    return std::count(s.axis_target.begin(), s.axis_target.end(), t) > 0;
  };
  for (int q = 0; q < m.nparams; ++q) // the fixed values
    if (!screened(q)) j["params"][m.params[q].name] = s.params[q];
  for (int sp = 0; sp < m.nspecies; ++sp)
    if (!screened(-1 - sp)) j["D"][m.species[sp].name] = s.D[sp];
  j["closed_form"] = m.nspecies == 2 && !s.classify.general;
  j["counts"] = {{"total", s.sampler.total()},
                 {"no_steady_state", c.v[0]},
                 {"unstable_k0", c.v[1]},
                 {"stable", c.v[2]},
                 {"turing_unstable", c.v[3]}};
  j["ranks"] = ranks;
  j["compute_s"] = compute_s;
  j["wall_s"] = wall_s;
  j["sets_per_s"] = wall_s > 0 ? static_cast<double>(s.sampler.total()) / wall_s : 0.0;
  if (s.csv) j["table"] = "turing_sets.csv";
  if (s.hdf5) j["table_h5"] = "turing_sets.h5";
  return j;
}

} // namespace

int run_screen(int* argc, char*** argv, const std::vector<OptionsFileArg>& options_files) {
  MPI_Comm world = PETSC_COMM_WORLD;
  int rank = 0, size = 1;
  MPI_Comm_rank(world, &rank);
  MPI_Comm_size(world, &size);
  for (int i = 1; i + 1 < *argc; ++i) // drop "screen": the deck (if any) becomes argv[1]
    (*argv)[i] = (*argv)[i + 1];
  --*argc;
  load_deck(argc, argv, options_files);
  Options opt(world);
  const ScreenSpec s = read_screen_spec(opt);
  check_unused_screen_options(opt, s.model->name);
  if (opt.help_requested()) {
    print_options_help(world, {&opt});
    print_models_help(world);
    return 0;
  }
  std::string err;
  if (rank == 0) {
    std::error_code ec;
    std::filesystem::create_directories(s.output, ec);
    if (ec) err = "-screen_output " + s.output + ": cannot create it (" + ec.message() + ")";
  }
  throw_if_any(world, err);
  const long long total = s.sampler.total();
  const long long chunk = std::max(4096LL, (total + 99999) / 100000);
  if (rank == 0) {
    std::printf("screen: %lld sets (%s) of model %s on %d rank%s -> %s/\n", total,
                describe_axes(s).c_str(), s.model->name, size, size == 1 ? "" : "s",
                s.output.c_str());
    std::fflush(stdout);
  }
  MPI_Barrier(world);
  const double t0 = MPI_Wtime();
  ScreenRows rows;
  rows.csv = s.csv;
  rows.numbers = s.hdf5;
  Counts counts;
  throw_if_any(world, screen_chunks(s, world, chunk, rows, counts));
  MPI_Allreduce(MPI_IN_PLACE, counts.v, 4, MPI_LONG_LONG, MPI_SUM, world);
  const double compute_s = MPI_Wtime() - t0;
  std::vector<std::string> species;
  for (int sp = 0; sp < s.model->nspecies; ++sp)
    species.emplace_back(s.model->species[sp].name);
  const long long nchunks = (total + chunk - 1) / chunk;
  if (s.csv)
    err = write_screen_csv(world, s.output + "/turing_sets.csv",
                           screen_csv_header(s.sampler.names, species), rows, nchunks);
  if (s.hdf5 && err.empty()) {
    std::vector<std::string> columns = s.sampler.names;
    columns.insert(columns.end(), {"wavelength", "k", "growth"});
    for (const auto& sp : species)
      columns.push_back("u_" + sp);
    err =
        write_screen_h5(world, s.output + "/turing_sets.h5", columns, rows, nchunks, s.model->name);
  }
  const double wall_s = MPI_Wtime() - t0;
  if (rank == 0 && err.empty())
    err = io::write_file_atomically(
        s.output + "/screen.json", summary_json(s, counts, size, compute_s, wall_s).dump(1) + "\n");
  int failed = !err.empty();
  MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_LOR, world);
  if (failed) {
    if (!err.empty()) std::fprintf(stderr, "morphogen: error: %s\n", err.c_str());
    return 4;
  }
  if (rank == 0) {
    std::printf("screen: %lld sets in %.2f s (%.3g sets/s on %d rank%s): %lld Turing-unstable, "
                "%lld stable, %lld unstable at k = 0, %lld without a steady state; table "
                "%s/turing_sets.%s\n",
                total, wall_s, wall_s > 0 ? total / wall_s : 0.0, size, size == 1 ? "" : "s",
                counts.v[3], counts.v[2], counts.v[1], counts.v[0], s.output.c_str(),
                s.csv ? (s.hdf5 ? "csv, .h5" : "csv") : "h5");
    std::fflush(stdout);
  }
  return 0;
}

} // namespace morphogen::sweep
