#include "sweep/sweep_table.hpp"

#include "analysis/linear_stability.hpp"
#include "app/pattern_summary.hpp"
#include "app/simulation.hpp"
#include "io/series_index.hpp"
#include "sweep/point_record.hpp"
#include "sweep/point_runner.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fcntl.h>
#include <fstream>
#include <map>
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

// Linear stability over a refined grid of the axes (empty for a listed sweep, when an axis is
// not a model parameter or diffusion coefficient, or when a parameter varies in space).
nlohmann::json stability_map(const SweepSpec& spec, const std::string& base_dir) {
  if (spec.listed) return {};
  // The base configuration: the options database holds the deck plus the last point's values.
  Options opt(PETSC_COMM_SELF);
  for (const auto& a : spec.axes)
    MG_PETSC(PetscOptionsSetValue(nullptr, ("-" + a.option).c_str(), a.values[0].c_str()));
  Simulation sim(PETSC_COMM_SELF, opt, base_dir);
  if (sim.params().any_field()) return {};
  const ModelEntry& m = sim.model();
  std::vector<double> params = sim.params().scalar, D = sim.diffusion();
  std::vector<double*> target;
  for (const auto& a : spec.axes) {
    double* t = nullptr;
    for (int q = 0; q < m.nparams; ++q)
      if (a.option == std::string("params_") + m.params[q].name) t = &params[q];
    for (int s = 0; s < m.nspecies; ++s)
      if (a.option == std::string("D_") + m.species[s].name) t = &D[s];
    if (!t) return {};
    target.push_back(t);
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
  analysis::StabilityOptions so;
  so.grid = dg;
  so.samples = 256;
  const int refine = spec.points() > 4096 ? 1 : 4;
  std::vector<std::vector<double>> axes;
  size_t total = 1;
  for (const auto& a : spec.axes) {
    axes.push_back(refined(a.numbers, refine));
    total *= axes.back().size();
  }
  if (total > 40000) return {};
  nlohmann::json turing = nlohmann::json::array(), hopf = nlohmann::json::array(),
                 hopf_region = nlohmann::json::array(), wl = nlohmann::json::array();
  for (size_t p = 0; p < total; ++p) {
    size_t r = p;
    for (size_t a = 0; a < axes.size(); ++a) {
      *target[a] = axes[a][r % axes[a].size()];
      r /= axes[a].size();
    }
    try {
      const auto st = analyse_states(m, params, D, so, nullptr);
      turing.push_back(st.turing_unstable);
      hopf.push_back(st.hopf);
      hopf_region.push_back(past_hopf(st));
      wl.push_back(st.turing_unstable && std::isfinite(st.wavelength_fastest)
                       ? nlohmann::json(st.wavelength_fastest)
                       : nlohmann::json());
    } catch (const std::exception&) {
      turing.push_back(false);
      hopf.push_back(false);
      hopf_region.push_back(false);
      wl.push_back(nullptr);
    }
  }
  return {{"axes", axes},
          {"turing", turing},
          {"hopf", hopf},
          {"hopf_region", hopf_region},
          {"wavelength", wl}};
}

} // namespace

std::string write_sweep_table(const std::string& dir, const SweepSpec& spec,
                              const std::string& base_options, const std::string& base_dir) {
  nlohmann::json map;
  try {
    map = stability_map(spec, base_dir);
  } catch (const std::exception& e) {
    map = {{"error", e.what()}};
  }
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
    std::ifstream f(dir + "/points/" + point_file(p, "json"));
    if (!f) continue;
    nlohmann::json r = nlohmann::json::parse(f, nullptr, false);
    if (r.is_discarded() || !r.contains("class")) continue;
    r.erase("series");
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
