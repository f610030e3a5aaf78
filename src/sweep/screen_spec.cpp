// The options of a Turing screen: see screen_spec.hpp.
#include "sweep/screen_spec.hpp"

#include "app/model_setup.hpp"
#include "core/petsc_handle.hpp"
#include "core/user_error.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace morphogen::sweep {

namespace {

constexpr long long kMaxSets = 10000000000000LL; // 1e13

// A number, or a UserError naming the option (fields and expressions vary in space).
double number(const std::string& key, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  while (end && *end == ' ')
    ++end;
  if (text.empty() || !end || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    throw UserError("-" + key + " " + text +
                    ": a screen needs a number here (the analysis is of a homogeneous state; "
                    "fields, expressions and 'v +- a%' are not allowed)");
  return v;
}

long long count_of(const std::string& key, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || !end || *end != '\0' || errno == ERANGE || v < 1 || v > kMaxSets)
    throw UserError("-" + key + " " + text + ": must be an integer in [1, 1e13]");
  return v;
}

std::string param_names(const ModelInfo& m) {
  std::string s;
  for (int q = 0; q < m.nparams; ++q)
    s += (s.empty() ? "" : ", ") + std::string(m.params[q].name);
  return s;
}

// Per axis: parameter index, or -1 - s for D of species s.
int target_of(const ModelInfo& m, const std::string& name) {
  for (int q = 0; q < m.nparams; ++q)
    if (name == m.params[q].name) return q;
  for (int s = 0; s < m.nspecies; ++s)
    if (name == "D_" + std::string(m.species[s].name)) return -1 - s;
  throw UserError("-screen_params " + name + ": not a parameter of model " + m.name + " (" +
                  param_names(m) + ") nor D_<species>");
}

void read_fixed(Options& opt, const ModelInfo& m, const std::vector<int>& targets, ScreenSpec& s) {
  auto screened = [&](int t) { return std::count(targets.begin(), targets.end(), t) > 0; };
  s.params.assign(m.nparams, 0.0);
  for (int q = 0; q < m.nparams; ++q) {
    const ParamInfo& p = m.params[q];
    const std::string key = std::string("params_") + p.name;
    if (screened(q)) {
      opt.known(key);
      continue;
    }
    const std::string text =
        opt.string(key, p.def_text ? p.def_text : format_double(p.def), std::string(p.doc));
    s.params[q] = number(key, text);
    if (!(s.params[q] >= p.lo && s.params[q] <= p.hi))
      throw UserError("-" + key + " " + text + ": out of range, " + allowed_range(p.lo, p.hi));
  }
  s.D.assign(m.nspecies, 0.0);
  for (int sp = 0; sp < m.nspecies; ++sp) {
    const std::string key = std::string("D_") + m.species[sp].name;
    if (screened(-1 - sp)) {
      opt.known(key);
      continue;
    }
    const std::string text =
        opt.string(key, format_double(m.species[sp].D),
                   "diffusion coefficient of " + std::string(m.species[sp].name) + " (a number)");
    s.D[sp] = number(key, text);
    if (s.D[sp] < 0) throw UserError("-" + key + " " + text + ": out of range, allowed >= 0");
  }
}

void read_ranges(Options& opt, const ModelInfo& m, ScreenSpec& s) {
  for (size_t j = 0; j < s.sampler.names.size(); ++j) {
    const std::string& name = s.sampler.names[j];
    const std::string key = "screen_range_" + name;
    if (!opt.is_set(key))
      throw UserError("-" + key + ": missing (the range lo,hi of screened " + name + ")");
    const auto v = opt.list(key, {}, 2, 2, "range lo,hi of screened " + name);
    const double lo = number(key, v[0]), hi = number(key, v[1]);
    if (!(lo < hi)) throw UserError("-" + key + " " + v[0] + "," + v[1] + ": lo must be < hi");
    const int t = s.axis_target[j];
    const double plo = t >= 0 ? m.params[t].lo : 0.0;
    const double phi = t >= 0 ? m.params[t].hi : Options::inf;
    if (lo < plo || hi > phi)
      throw UserError("-" + key + " " + v[0] + "," + v[1] + ": outside the allowed range of " +
                      name + ", " + allowed_range(plo, phi));
    s.sampler.lo.push_back(lo);
    s.sampler.hi.push_back(hi);
  }
}

void read_sampling(Options& opt, ScreenSpec& s) {
  const size_t na = s.sampler.names.size();
  const std::string how = opt.choice("screen_sampling", "grid", {"grid", "random", "lhs"},
                                     "how the sets fill the ranges");
  s.sampler.sampling = how == "grid"     ? Sampling::Grid
                       : how == "random" ? Sampling::Random
                                         : Sampling::Lhs;
  const bool grid = s.sampler.sampling == Sampling::Grid;
  const auto pts =
      opt.list("screen_points", {grid ? "101" : "10000"}, 1, grid ? std::max<size_t>(na, 1) : 1,
               "grid: points per axis (one value, or one per axis); random, "
               "lhs: the number of sets");
  if (grid && pts.size() != 1 && pts.size() != na)
    throw UserError("-screen_points: one value or one per screened quantity (" +
                    std::to_string(na) + ")");
  long long total = 1;
  for (size_t j = 0; j < (grid ? na : 1); ++j) {
    const long long n = count_of("screen_points", pts[pts.size() == 1 ? 0 : j]);
    if (total > kMaxSets / n)
      throw UserError("-screen_points: more than 1e13 parameter sets in all");
    total *= n;
    if (grid) s.sampler.points.push_back(n);
  }
  s.sampler.count = total;
  s.sampler.seed = static_cast<std::uint64_t>(opt.integer(
      "screen_seed", 1, 0, std::numeric_limits<int>::max(), "seed of random and lhs sampling"));
}

void read_analysis(Options& opt, const ModelInfo& m, ScreenSpec& s) {
  s.classify.general = opt.flag("screen_general", false,
                                "eigenvalues and a k scan even for 2 species (no closed form)");
  s.classify.all_states = opt.flag("screen_all_states", false,
                                   "search every homogeneous steady state, not only the model's");
  s.classify.k_samples = static_cast<int>(opt.integer(
      "screen_k_samples", 256, 3, 1 << 20, "sampled wavenumbers of the general (N-species) path"));
  s.classify.search.points = static_cast<int>(opt.integer(
      "screen_search_points", 0, 0, 1000, "steady-state search: starts per species (0: auto)"));
  for (int sp = 0; sp < m.nspecies; ++sp) {
    const std::string key = std::string("screen_search_") + m.species[sp].name;
    if (!opt.is_set(key)) continue;
    const auto v = opt.list(key, {}, 2, 2, "steady-state search box lo,hi of this species");
    const double lo = number(key, v[0]), hi = number(key, v[1]);
    if (!(lo < hi)) throw UserError("-" + key + " " + v[0] + "," + v[1] + ": lo must be < hi");
    if (s.classify.search.lo.empty()) // the others: |u_s| <= 2 max(1, |init_s|)
      for (int r = 0; r < m.nspecies; ++r) {
        const double h = 2 * std::max(1.0, std::abs(m.species[r].init));
        s.classify.search.lo.push_back(-h);
        s.classify.search.hi.push_back(h);
      }
    s.classify.search.lo[sp] = lo, s.classify.search.hi[sp] = hi;
  }
}

} // namespace

ScreenSpec read_screen_spec(Options& opt) {
  ScreenSpec s;
  if (!opt.is_set("screen_params") && !opt.help_requested()) // -help: list the options anyway
    throw UserError("-screen_params: missing (the parameters to vary, e.g. alpha,beta, each "
                    "with -screen_range_<name> lo,hi)");
  s.sampler.names = opt.list("screen_params", {}, opt.help_requested() ? 0 : 1, 16,
                             "varied parameters (or D_<species>), comma-separated");
  for (const auto& n : s.sampler.names) {
    if (std::count(s.sampler.names.begin(), s.sampler.names.end(), n) > 1)
      throw UserError("-screen_params: " + n + " is given twice");
    // A custom model needs every parameter's value to exist (app/model_setup.hpp).
    if (n.rfind("D_", 0) != 0 && !opt.is_set("params_" + n))
      MG_PETSC(PetscOptionsSetValue(nullptr, ("-params_" + n).c_str(), "0"));
  }
  s.model = read_model_choice(opt);
  for (const auto& n : s.sampler.names)
    s.axis_target.push_back(target_of(*s.model, n));
  read_fixed(opt, *s.model, s.axis_target, s);
  read_ranges(opt, *s.model, s);
  read_sampling(opt, s);
  read_analysis(opt, *s.model, s);
  s.output = opt.string("screen_output", "screen", "output directory of the screen");
  if (s.output.empty()) throw UserError("-screen_output: empty");
  const std::string format =
      opt.choice("screen_format", "csv", {"csv", "hdf5", "both"},
                 "the table of Turing-unstable sets: turing_sets.csv, turing_sets.h5 (one 1-D "
                 "dataset per column) or both");
  s.csv = format != "hdf5";
  s.hdf5 = format != "csv";
  return s;
}

} // namespace morphogen::sweep
