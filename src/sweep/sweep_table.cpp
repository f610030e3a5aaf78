#include "sweep/sweep_table.hpp"

#include "analysis/linear_stability.hpp"
#include "app/pattern_summary.hpp"
#include "app/simulation.hpp"
#include "core/collective_error.hpp"
#include "core/user_error.hpp"
#include "io/series_index.hpp"
#include "sweep/point_record.hpp"
#include "sweep/point_runner.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fcntl.h>
#include <map>
#include <memory>
#include <sys/file.h>
#include <unistd.h>

namespace morphogen::sweep {

namespace {

// Values between the axis values, `refine` per interval (index-space interpolation, so a
// logarithmic axis stays logarithmic).
std::vector<double> refined(const std::vector<double>& v, int refine) {
  if (v.size() < 2) return v;
  std::vector<double> out;
  for (size_t i = 0; i + 1 < v.size(); ++i) {
    const bool logax = v[i] > 0 && v[i + 1] > 0 && v.size() > 2 &&
                       std::fabs(v[2] / v[1] - v[1] / v[0]) < 1e-9 * std::fabs(v[1] / v[0]) &&
                       std::fabs((v[2] - v[1]) - (v[1] - v[0])) > 1e-9 * std::fabs(v[1] - v[0]);
    for (int r = 0; r < refine; ++r) {
      const double s = static_cast<double>(r) / refine;
      out.push_back(logax ? v[i] * std::pow(v[i + 1] / v[i], s) : v[i] + s * (v[i + 1] - v[i]));
    }
  }
  out.push_back(v.back());
  return out;
}

// Past the Hopf line: for two species trace J > 0 with det J > 0 (the edge of this region is the
// Hopf line trace J = 0; the edge of the complex-eigenvalue region, trace^2 = 4 det, is not a
// stability boundary); for other species counts, J has a complex pair with Re > 0.
bool past_hopf(const analysis::StabilityResult& st) {
  if (st.nspecies != 2 || st.jacobian.size() != 4) return st.hopf;
  const auto& J = st.jacobian;
  const double tr = J[0] + J[3], det = J[0] * J[3] - J[1] * J[2];
  return tr > st.tol && det > 0;
}

// What the stability map varies: the model, the base parameters and diffusion coefficients, the
// entry each axis sets, the options of the analysis and the refined axes.
struct MapSetup {
  std::unique_ptr<Simulation> sim; // owns the model entry
  std::vector<double> params, D;
  std::vector<double*> target;
  analysis::StabilityOptions so;
  std::vector<std::vector<double>> axes;
  size_t total = 1;
};

// The map's setup, or null when there is no map: a listed sweep, an axis that is not a model
// parameter or diffusion coefficient, a parameter that varies in space, or over 40,000 points.
std::unique_ptr<MapSetup> map_setup(const SweepSpec& spec, const std::string& base_dir) {
  if (spec.listed) return nullptr;
  // The base configuration: the options database holds the deck plus the last point's values.
  Options opt(PETSC_COMM_SELF);
  for (const auto& a : spec.axes)
    MG_PETSC(PetscOptionsSetValue(nullptr, ("-" + a.option).c_str(), a.values[0].c_str()));
  auto ms = std::make_unique<MapSetup>();
  ms->sim = std::make_unique<Simulation>(PETSC_COMM_SELF, opt, base_dir);
  const Simulation& sim = *ms->sim;
  if (sim.params().any_field()) return nullptr;
  const ModelEntry& m = sim.model();
  ms->params = sim.params().scalar;
  ms->D = sim.diffusion();
  for (const auto& a : spec.axes) {
    double* t = nullptr;
    for (int q = 0; q < m.nparams; ++q)
      if (a.option == std::string("params_") + m.params[q].name) t = &ms->params[q];
    for (int s = 0; s < m.nspecies; ++s)
      if (a.option == std::string("D_") + m.species[s].name) t = &ms->D[s];
    if (!t) return nullptr;
    ms->target.push_back(t);
  }
  analysis::DiscreteGrid dg;
  const auto& g = sim.grid().spec();
  dg.dim = g.dim;
  for (int d = 0; d < 3; ++d) {
    dg.h[d] = g.h(d);
    dg.n[d] = d < g.dim ? g.n[d] : 1;
    dg.periodic[d] = g.bc[d] == Boundary::Periodic;
  }
  dg.stencil = sim.stencil().name;
  ms->so.grid = dg;
  ms->so.samples = 256;
  const int refine = spec.points() > 4096 ? 1 : 4;
  for (const auto& a : spec.axes) {
    ms->axes.push_back(refined(a.numbers, refine));
    ms->total *= ms->axes.back().size();
  }
  return ms->total > 40000 ? nullptr : std::move(ms);
}

// Point p of the map: Turing-unstable, Hopf, past the Hopf line (1 or 0) and the fastest
// wavelength (NaN: none) into out[0..3]; a point whose analysis fails is 0, 0, 0, NaN.
void map_point(MapSetup& ms, size_t p, double* out) {
  size_t r = p;
  for (size_t a = 0; a < ms.axes.size(); ++a) {
    *ms.target[a] = ms.axes[a][r % ms.axes[a].size()];
    r /= ms.axes[a].size();
  }
  out[0] = out[1] = out[2] = 0;
  out[3] = std::nan("");
  try {
    const auto st = analyse_states(ms.sim->model(), ms.params, ms.D, ms.so, nullptr);
    out[0] = st.turing_unstable;
    out[1] = st.hopf;
    out[2] = past_hopf(st);
    if (st.turing_unstable && std::isfinite(st.wavelength_fastest)) out[3] = st.wavelength_fastest;
  } catch (const std::exception&) {
  }
}

// The map's JSON from the four values per point of map_point.
nlohmann::json map_json(const std::vector<std::vector<double>>& axes,
                        const std::vector<double>& v) {
  nlohmann::json turing = nlohmann::json::array(), hopf = nlohmann::json::array(),
                 hopf_region = nlohmann::json::array(), wl = nlohmann::json::array();
  for (size_t p = 0; 4 * p < v.size(); ++p) {
    turing.push_back(v[4 * p] != 0);
    hopf.push_back(v[4 * p + 1] != 0);
    hopf_region.push_back(v[4 * p + 2] != 0);
    wl.push_back(std::isnan(v[4 * p + 3]) ? nlohmann::json() : nlohmann::json(v[4 * p + 3]));
  }
  return {{"axes", axes},
          {"turing", turing},
          {"hopf", hopf},
          {"hopf_region", hopf_region},
          {"wavelength", wl}};
}

} // namespace

nlohmann::json stability_map(const SweepSpec& spec, const std::string& base_dir, MPI_Comm comm) {
  // Rank 0 sets up first; the other ranks share the points only for a base grid of at most
  // kShareCells cells, as each holds a one-rank copy of the run (points of larger grids take far
  // longer than the map, which rank 0 then computes alone).
  constexpr long long kShareCells = 1 << 20;
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::unique_ptr<MapSetup> ms;
  std::string err;
  unsigned long long info[3] = {0, 0, 0}; // a map, shared, points
  auto setup = [&] {
    try {
      ms = map_setup(spec, base_dir);
    } catch (const std::exception& e) {
      err = e.what();
    }
  };
  if (rank == 0) {
    setup();
    if (ms) {
      info[0] = 1;
      info[1] = ms->sim->grid().global_cells() <= kShareCells;
      info[2] = ms->total;
    }
  }
  MPI_Bcast(info, 3, MPI_UNSIGNED_LONG_LONG, 0, comm);
  if (rank != 0 && info[1]) {
    setup();
    if (err.empty() && (!ms || ms->total != info[2])) err = "stability map: set-up differs by rank";
  }
  try {
    throw_if_any(comm, err);
  } catch (const UserError& e) {
    return rank == 0 ? nlohmann::json{{"error", e.what()}} : nlohmann::json();
  }
  if (!info[0]) return {};
  const int parts = info[1] ? size : 1;
  // Point p on rank p mod parts, zeros elsewhere: the sum on rank 0 is each point's own values.
  const size_t total = info[2];
  std::vector<double> v(4 * total, 0.0);
  if (rank < parts)
    for (size_t p = static_cast<size_t>(rank); p < total; p += static_cast<size_t>(parts))
      map_point(*ms, p, &v[4 * p]);
  MPI_Reduce(rank == 0 ? MPI_IN_PLACE : v.data(), v.data(), static_cast<int>(v.size()), MPI_DOUBLE,
             MPI_SUM, 0, comm);
  return rank == 0 ? map_json(ms->axes, v) : nlohmann::json();
}

std::string write_sweep_table(const std::string& dir, const SweepSpec& spec,
                              const std::string& base_options, nlohmann::json map) {
  // Chunks sharing the directory: scan and write under a lock, so the newest scan wins and
  // sweep.csv and sweep.json come from the same scan.
  const int lock = open((dir + "/.sweep.lock").c_str(), O_CREAT | O_RDWR, 0644);
  if (lock >= 0) flock(lock, LOCK_EX);
  std::vector<std::string> names;
  nlohmann::json axes = nlohmann::json::array();
  for (const auto& a : spec.axes) {
    names.push_back(a.option);
    axes.push_back({{"option", a.option}, {"values", a.numbers}});
  }
  std::string csv = csv_header(names, spec.listed);
  nlohmann::json records = nlohmann::json::array();
  std::map<std::string, int> classes;
  for (long long p = 0; p < spec.points(); ++p) {
    nlohmann::json r = read_record(dir + "/points/" + point_file(p, "json"));
    if (r.is_discarded() || !r.contains("class")) continue;
    csv += csv_row(r, names, spec.listed);
    ++classes[r["class"].get<std::string>()];
    records.push_back(std::move(r));
  }
  nlohmann::json j = {
      {"axes", axes},       {"points", spec.points()},      {"finished", records.size()},
      {"classes", classes}, {"base_options", base_options}, {"records", records}};
  j["stability_map"] = std::move(map);
  if (spec.listed) j["points_file"] = spec.points_file;
  std::string err = io::write_file_atomically(dir + "/sweep.csv", csv);
  if (err.empty())
    err = io::write_file_atomically(
        dir + "/sweep.json",
        j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  if (lock >= 0) {
    flock(lock, LOCK_UN);
    close(lock);
  }
  return err;
}

} // namespace morphogen::sweep
