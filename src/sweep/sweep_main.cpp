#include "sweep/sweep_main.hpp"

#include "analysis/linear_stability.hpp"
#include "app/deck.hpp"
#include "app/help.hpp"
#include "app/simulation.hpp"
#include "core/collective_error.hpp"
#include "core/user_error.hpp"
#include "fields/value_spec.hpp"
#include "io/series_index.hpp"
#include "sweep/point_list.hpp"
#include "sweep/point_record.hpp"
#include "sweep/point_runner.hpp"
#include "sweep/sweep_table.hpp"
#include "sweep/work_queue.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

namespace morphogen::sweep {

namespace {

// The sweep's own keys, then the points' keys that the sweep did not write (both read some
// options, e.g. -max_walltime; a deck must not repeat a key). One "key: value" per line.
std::string merge_yaml_keys(const std::string& first, const std::string& second) {
  std::set<std::string> keys;
  std::istringstream a(first);
  for (std::string line; std::getline(a, line);)
    if (const auto c = line.find(':'); c != std::string::npos && line[0] != '#')
      keys.insert(line.substr(0, c));
  std::string out = first;
  std::istringstream b(second);
  for (std::string line; std::getline(b, line);) {
    const auto c = line.find(':');
    if (c != std::string::npos && line[0] != '#' && keys.count(line.substr(0, c))) continue;
    out += line + "\n";
  }
  return out;
}

namespace fs = std::filesystem;

struct Setup {
  SweepSpec spec;
  SweepSettings set;
  int group_size = 1;
  long long chunk = 0, chunks = 1;
  double max_walltime = 0; // minutes
};

constexpr const char* kAxesHelp =
    "options swept (1 to 3), e.g. params_F,params_k; each needs -sweep_<option> with its values "
    "(with -sweep_points: 1 to 16 columns of the file; default: a screen file's varied ones)";

// -sweep_axes: 1 to `most` distinct options; optional (-sweep_points: the file's own columns
// then): an empty list when not given.
std::vector<std::string> read_axis_names(Options& opt, int most, bool optional) {
  if (optional && !opt.is_set("sweep_axes")) return {};
  const auto axes = opt.list("sweep_axes", {}, 1, most, kAxesHelp);
  for (const auto& a : axes)
    if (std::count(axes.begin(), axes.end(), a) > 1)
      throw UserError("-sweep_axes: " + a + " is given twice");
  return axes;
}

// The axes of a product sweep: -sweep_axes and each axis's -sweep_<option> values.
SweepSpec read_product_axes(Options& opt, std::vector<std::string>& known) {
  SweepSpec spec;
  for (const auto& a : read_axis_names(opt, 3, false)) {
    const std::string key = "sweep_" + a;
    const auto text = opt.get(key, "values of " + a +
                                       ": linspace(a, b, n), logspace(a, b, n), "
                                       "range(a, b, step) or v1,v2,...");
    if (!text) throw UserError("-" + key + ": missing (the values of sweep axis " + a + ")");
    Axis ax;
    ax.option = a;
    ax.values = parse_axis_values(key, *text);
    for (const auto& v : ax.values)
      ax.numbers.push_back(Options::parse_real(key, v));
    spec.axes.push_back(std::move(ax));
    known.push_back(key);
  }
  return spec;
}

// The axes of a listed sweep: the rows of -sweep_points (point_list.hpp).
SweepSpec read_listed_axes(Options& opt, const std::string& file, const std::string& base_dir,
                           long long max_points) {
  const auto axes = read_axis_names(opt, 16, true);
  for (const auto& a : axes)
    if (opt.is_set("sweep_" + a))
      throw UserError("-sweep_" + a + ": not used with -sweep_points " + file + " (the values of " +
                      a + " come from the file)");
  return read_point_list("sweep_points", resolve_path(base_dir, file), axes, max_points);
}

Setup read_setup(Options& opt, const std::string& base_dir) {
  Setup s;
  const std::string points =
      opt.string("sweep_points", "",
                 "CSV file (a header names the columns) or HDF5 table of points, one per row, e.g. "
                 "a screen's turing_sets.csv or .h5: sweep these instead of the product of the "
                 "axes' values");
  const long long max_points = opt.integer(
      "sweep_points_max", 0, 0, 10000000,
      "with -sweep_points: at most N points, evenly spaced rows of the file (0: every row)");
  if (points.empty() && max_points > 0) // 0 (the default) is what options_used.yaml records
    throw UserError("-sweep_points_max " + std::to_string(max_points) +
                    ": needs -sweep_points (a file of points)");
  s.spec = points.empty() ? read_product_axes(opt, s.set.known)
                          : read_listed_axes(opt, points, base_dir, max_points);
  if (s.spec.points() > 10000000)
    throw UserError(points.empty() ? "-sweep_axes: more than 10^7 points"
                                   : "-sweep_points " + points +
                                         ": more than 10^7 rows (use -sweep_points_max)");
  s.group_size = static_cast<int>(
      opt.integer("sweep_group_size", 1, 1, 1 << 20, "ranks per sweep point (divides the ranks)"));
  int world_size = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &world_size);
  if (world_size % s.group_size != 0)
    throw UserError("-sweep_group_size " + std::to_string(s.group_size) +
                    ": must divide the number of ranks (" + std::to_string(world_size) + ")");
  s.chunks = opt.integer("sweep_chunks", 1, 1, 1 << 30,
                         "split the sweep into this many chunks (job arrays)");
  s.chunk = opt.integer("sweep_chunk", 0, 0, 1 << 30,
                        "run only chunk c (0-based): the points p with p mod chunks == c");
  if (s.chunk >= s.chunks)
    throw UserError("-sweep_chunk " + std::to_string(s.chunk) + ": must be < -sweep_chunks (" +
                    std::to_string(s.chunks) + ")");
  s.set.species = opt.string("sweep_species", "",
                             "species the metrics and class are computed on (default: the "
                             "model's first)");
  s.set.samples = opt.integer("sweep_samples", 1000, 4, 1000000,
                              "time-series samples per point (for steady / periodic / chaotic)");
  s.max_walltime = opt.real("max_walltime", 0, 0, Options::inf,
                            "wall-time budget in minutes: no point starts that might not finish "
                            "within it (unfinished points: exit code 3; rerun to continue)");
  const std::string restart = opt.string("restart", "latest",
                                         "sweeps always resume (finished points are skipped): "
                                         "only 'latest' is accepted");
  if (restart != "latest")
    throw UserError("-restart " + restart +
                    ": a sweep always resumes from its finished points; allowed: latest");
  s.set.base_dir = base_dir;
  for (const char* k :
       {"sweep_axes", "sweep_points", "sweep_points_max", "sweep_group_size", "sweep_chunks",
        "sweep_chunk", "sweep_species", "sweep_samples", "max_walltime", "restart"})
    s.set.known.emplace_back(k);
  return s;
}

// The points whose simulations are built before the sweep runs: point 0, then for a product
// every value of each axis (the others at their first value), for a list the rows holding each
// axis's smallest and largest value.
std::vector<long long> points_to_validate(const SweepSpec& spec) {
  std::vector<long long> out{0};
  for (size_t a = 0; a < spec.axes.size(); ++a) {
    const auto& v = spec.axes[a].numbers;
    if (spec.listed) {
      out.push_back(std::min_element(v.begin(), v.end()) - v.begin());
      out.push_back(std::max_element(v.begin(), v.end()) - v.begin());
      continue;
    }
    long long stride = 1;
    for (size_t b = 0; b < a; ++b)
      stride *= static_cast<long long>(spec.axes[b].values.size());
    for (size_t i = 1; i < v.size(); ++i)
      out.push_back(static_cast<long long>(i) * stride);
  }
  std::sort(out.begin() + 1, out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// Every rank, on PETSC_COMM_SELF: build the simulation of each point of points_to_validate so a
// bad value fails before anything runs. Returns the first point's options.
std::string validate(const Setup& s, const Options& sopt, std::string& dir) {
  std::string yaml;
  for (const long long p : points_to_validate(s.spec)) {
    for (const auto& [option, value] : s.spec.assignment(p))
      MG_PETSC(PetscOptionsSetValue(nullptr, ("-" + option).c_str(), value.c_str()));
    Options opt(PETSC_COMM_SELF);
    for (const auto& k : s.set.known)
      opt.known(k);
    Simulation sim(PETSC_COMM_SELF, opt, s.set.base_dir);
    if (!s.set.species.empty()) {
      const auto& n = sim.species();
      if (std::find(n.begin(), n.end(), s.set.species) == n.end())
        throw UserError("-sweep_species " + s.set.species + ": no such species in model " +
                        sim.model().name);
    }
    if (p == 0) {
      const std::string model = sim.model().name;
      opt.set_unknown_hint(
          [model](const std::string& name) { return other_model_hint(name, model); });
      opt.check_unused();
      dir = sim.output().dir;
      yaml = opt.to_yaml("");
      int rank = 0;
      MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
      if (s.spec.listed && rank == 0)
        for (const auto& w : screen_mismatches(s.spec, sim))
          std::fprintf(stderr, "morphogen: warning: -sweep_points %s: %s\n",
                       s.spec.points_file.c_str(), w.c_str());
      if (opt.help_requested()) { // the options are listed once
        print_options_help(PETSC_COMM_WORLD, {&sopt, &opt});
        print_models_help(PETSC_COMM_WORLD);
        return yaml;
      }
    }
  }
  return yaml;
}

// Points with a record in dir/points. A record whose parameters differ from this sweep's at
// its index (the axes changed since) is an error; an unreadable record or one of class
// "error" is not finished (it runs again).
std::vector<long long> finished_points(const std::string& dir, const SweepSpec& spec,
                                       std::string& err) {
  std::vector<long long> done;
  const long long n = spec.points();
  std::error_code ec;
  for (fs::directory_iterator it(dir + "/points", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string f = it->path().filename().string();
    long long p = -1;
    char tail[8] = "";
    if (std::sscanf(f.c_str(), "point_%lld.%7s", &p, tail) != 2 || std::string(tail) != "json" ||
        p < 0 || p >= n || f != point_file(p, "json"))
      continue;
    const nlohmann::json r = read_record(it->path().string());
    if (r.is_discarded() || !r.contains("class") || !r.contains("params") || r["class"] == "error")
      continue;
    const auto idx = spec.indices(p);
    for (size_t a = 0; a < spec.axes.size() && err.empty(); ++a) {
      const auto& ax = spec.axes[a];
      const double want = ax.numbers[static_cast<size_t>(idx[a])];
      const auto& got = r["params"].contains(ax.option) ? r["params"][ax.option] : nlohmann::json();
      if (!got.is_number() ||
          std::fabs(got.get<double>() - want) > 1e-12 * std::max(1.0, std::fabs(want)))
        err = "-output_dir " + dir + ": points/" + f + " was computed with " + ax.option + " = " +
              (got.is_number() ? format_double(got.get<double>()) : std::string("(none)")) +
              ", this sweep has " + format_double(want) +
              " at that point (the axes changed); use another -output_dir";
    }
    done.push_back(p);
  }
  return done;
}

} // namespace

int run_sweep(int* argc, char*** argv, const std::vector<OptionsFileArg>& options_files) {
  const double wall_start = MPI_Wtime();
  MPI_Comm world = PETSC_COMM_WORLD;
  int rank = 0;
  MPI_Comm_rank(world, &rank);
  // Drop "sweep": the deck becomes argv[1].
  for (int i = 1; i + 1 < *argc; ++i)
    (*argv)[i] = (*argv)[i + 1];
  --*argc;
  if (*argc < 2 || (*argv)[1][0] == '-')
    throw UserError("sweep: needs a deck (morphogen sweep DECK.yaml [-option value ...])");
  const std::string deck = (*argv)[1];
  const std::string deck_dir = load_deck(argc, argv, options_files);
  Options sopt(world);
  const std::string base_dir = read_deck_dir(sopt, deck_dir);
  if (!sopt.is_set("sweep_axes") && !sopt.is_set("sweep_points"))
    throw UserError("deck " + deck +
                    ": no sweep: section (sweep: {axes: [params_F, ...], params_F: "
                    "linspace(a, b, n), ...} or sweep: {points: FILE.csv}); to run it once: "
                    "morphogen " +
                    deck);
  Setup s = read_setup(sopt, base_dir);
  std::string dir;
  const std::string yaml = validate(s, sopt, dir);
  if (sopt.help_requested()) return 0; // -help lists the options; it runs nothing
  s.set.dir = dir;
  const long long npoints = s.spec.points();

  // Output directory, options and the list of points still to run.
  std::string err;
  std::vector<long long> todo;
  if (rank == 0) {
    std::vector<long long> done = finished_points(dir, s.spec, err);
    std::error_code ec;
    if (err.empty()) fs::create_directories(dir + "/points", ec);
    if (ec)
      err = "-output_dir " + dir + ": cannot create " + dir + "/points (" + ec.message() + ")";
    if (err.empty()) {
      const std::string werr =
          io::write_file_atomically(dir + "/options_used.yaml",
                                    "# Options of this sweep (morphogen " MORPHOGEN_VERSION ")\n" +
                                        merge_yaml_keys(sopt.to_yaml(""), yaml));
      if (!werr.empty()) err = "-output_dir " + dir + ": " + werr;
    }
    for (long long p = s.chunk; p < npoints; p += s.chunks)
      if (std::find(done.begin(), done.end(), p) == done.end()) todo.push_back(p);
    if (err.empty()) {
      std::string axes = s.spec.listed ? "rows of " + s.spec.points_file + ": " : "";
      for (size_t a = 0; a < s.spec.axes.size(); ++a) {
        const Axis& ax = s.spec.axes[a];
        if (a > 0) axes += s.spec.listed ? ", " : " x ";
        axes +=
            s.spec.listed ? ax.option : ax.option + "[" + std::to_string(ax.values.size()) + "]";
      }
      std::printf("sweep: %lld points (%s), chunk %lld/%lld: %zu to run, %zu already done -> %s/\n",
                  npoints, axes.c_str(), s.chunk, s.chunks, todo.size(), done.size(), dir.c_str());
      std::fflush(stdout);
    }
  }
  throw_if_any(world, err);
  long long ntodo = static_cast<long long>(todo.size());
  MPI_Bcast(&ntodo, 1, MPI_LONG_LONG, 0, world);
  todo.resize(static_cast<size_t>(ntodo));
  MPI_Bcast(todo.data(), static_cast<int>(ntodo), MPI_LONG_LONG, 0, world);

  WorkQueue q(world, s.group_size, todo);
  const double t0 = MPI_Wtime();
  if (s.max_walltime > 0) q.set_deadline(wall_start + s.max_walltime * 60.0);
  double cell_updates = 0;
  long long ran = 0;
  bool interrupted = false;
  double last_seconds = 0;
  for (long long p = q.next(); p >= 0; p = q.next(last_seconds)) {
    const double tp = MPI_Wtime();
    const nlohmann::json r = run_point(s.spec, p, s.set, q, interrupted);
    last_seconds = MPI_Wtime() - tp;
    if (interrupted) {
      q.next(-1.0); // tells rank 0 to stop handing out points
      break;
    }
    if (q.leader()) {
      const std::string jerr = io::write_file_atomically(
          dir + "/points/" + point_file(p, "json"),
          r.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
      if (!jerr.empty()) {
        std::fprintf(stderr, "morphogen: error: %s\n", jerr.c_str());
        MPI_Abort(world, 4);
      }
      if (r.contains("cells")) cell_updates += r["cells"].get<double>() * r["steps"].get<double>();
      ++ran;
      std::string params, wavelength = "-";
      for (const auto& [k, v] : r["params"].items())
        params += (params.empty() ? "" : " ") + k + "=" + format_double(v.get<double>());
      if (r.contains("metrics") && r["metrics"]["wavelength"].is_number())
        wavelength = format_double(r["metrics"]["wavelength"].get<double>());
      std::printf("point %lld [%s]: %s (wavelength %s), %.2f s, group %d\n", p, params.c_str(),
                  r["class"].get<std::string>().c_str(), wavelength.c_str(),
                  r["runtime_s"].get<double>(), q.group_index());
      std::fflush(stdout);
    }
  }
  q.drain();
  const double wall = MPI_Wtime() - t0;
  double totals[2] = {cell_updates, static_cast<double>(ran)};
  MPI_Allreduce(MPI_IN_PLACE, totals, 2, MPI_DOUBLE, MPI_SUM, world);
  int any_interrupted = interrupted;
  MPI_Allreduce(MPI_IN_PLACE, &any_interrupted, 1, MPI_INT, MPI_LOR, world);
  int cut = q.cut_by_deadline();
  MPI_Bcast(&cut, 1, MPI_INT, 0, world);
  nlohmann::json map = stability_map(s.spec, s.set.base_dir, world);
  if (rank == 0) {
    const std::string terr = write_sweep_table(dir, s.spec, yaml, std::move(map));
    if (!terr.empty()) {
      std::fprintf(stderr, "morphogen: error: %s\n", terr.c_str());
      MPI_Abort(world, 4);
    }
    std::printf("sweep: ran %.0f points in %.2f s on %d group%s: %.3e cell-updates/s aggregate; "
                "table %s/sweep.csv\n",
                totals[1], wall, q.groups(), q.groups() == 1 ? "" : "s",
                wall > 0 ? totals[0] / wall : 0.0, dir.c_str());
    std::fflush(stdout);
  }
  if (any_interrupted || cut) {
    PetscPrintf(world,
                "sweep: stopped by %s; run the same command again to finish the remaining "
                "points (exit code 3)\n",
                any_interrupted ? "a signal" : "the -max_walltime budget");
    return 3;
  }
  return 0;
}

} // namespace morphogen::sweep
