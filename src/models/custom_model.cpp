// User-defined kinetics from muParser expressions (see models/runtime_model.hpp).
#include "core/options.hpp"
#include "core/user_error.hpp"
#include "fields/column_program.hpp"
#include "fields/value_spec.hpp"
#include "models/runtime_model.hpp"
#include "models/runtime_storage.hpp"

#include <muParser.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace morphogen {

namespace {

// Names a species may not have: the coordinates, time and the constant pi. In a rate, x, y, z
// and t are parameters whose default is that expression (a field of x, a value set each step
// for t), so they cost nothing when unused.
const std::set<std::string> kReserved = {"x", "y", "z", "t", "pi"};
const std::set<std::string> kCoordinates = {"x", "y", "z", "t"};

bool is_identifier(const std::string& n) {
  if (n.empty() || !(std::isalpha(static_cast<unsigned char>(n[0])) || n[0] == '_')) return false;
  return std::all_of(n.begin(), n.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

// The species and parameter values every expression reads (vars = species, then parameters).
struct Expressions {
  int ns = 0, np = 0;
  std::vector<double> vars;
  std::vector<std::unique_ptr<mu::Parser>> parsers;
  std::vector<ColumnProgram> programs; // per species: its bytecode, evaluated per row
  bool columns = false;                // every program is column-evaluable
  int depth = 0;                       // the deepest program's stack
  size_t cap = 0;                      // cells per scratch column
  std::vector<double> stack, pcols;    // depth * cap; np * cap (scalar parameters)

  // The rates of a row (ModelInfo::rates_row).
  void rates_row(int n, const double* const* u, const double* const* prow, const double* pconst,
                 double* const* r) {
    if (n <= 0) return;
    if (!columns) { // cell by cell
      std::vector<double> uc(static_cast<size_t>(ns)), pcell(static_cast<size_t>(np)),
          rc(static_cast<size_t>(ns));
      for (int i = 0; i < n; ++i) {
        for (int s = 0; s < ns; ++s)
          uc[static_cast<size_t>(s)] = u[s][i];
        for (int q = 0; q < np; ++q)
          pcell[static_cast<size_t>(q)] = prow ? prow[q][i] : pconst[q];
        rates(uc.data(), pcell.data(), rc.data());
        for (int s = 0; s < ns; ++s)
          r[s][i] = rc[static_cast<size_t>(s)];
      }
      return;
    }
    if (static_cast<size_t>(n) > cap) {
      cap = (static_cast<size_t>(n) + 7) / 8 * 8;
      stack.assign(static_cast<size_t>(depth) * cap, 0.0);
      pcols.assign(static_cast<size_t>(np) * cap, 0.0);
    }
    const double* col[kMaxVars];
    for (int s = 0; s < ns; ++s)
      col[s] = u[s];
    for (int q = 0; q < np; ++q) {
      if (prow) {
        col[ns + q] = prow[q];
      } else {
        double* c = pcols.data() + static_cast<size_t>(q) * cap;
        std::fill(c, c + n, pconst[q]);
        col[ns + q] = c;
      }
    }
    for (int s = 0; s < ns; ++s)
      programs[static_cast<size_t>(s)].eval(n, col, stack.data(), cap, r[s]);
  }
  static constexpr int kMaxVars = 256;

  void rates(const double* u, const double* p, double* r) {
    std::copy(u, u + ns, vars.begin());
    std::copy(p, p + np, vars.begin() + ns);
    for (int s = 0; s < ns; ++s)
      r[s] = parsers[static_cast<size_t>(s)]->Eval();
  }
  // J[s * ns + q] = d R_s / d u_q: the user's expressions when given (jparsers, row-major),
  // else central differences. ns <= kMaxModelSpecies (check_species): stack buffers only.
  void jacobian(const double* u, const double* p, double* J) {
    if (!jparsers.empty()) {
      std::copy(u, u + ns, vars.begin());
      std::copy(p, p + np, vars.begin() + ns);
      for (int e = 0; e < ns * ns; ++e)
        J[e] = jparsers[static_cast<size_t>(e)]->Eval();
      return;
    }
    fd_jacobian(u, p, J);
  }
  // Central differences, step cbrt(eps) (1 + |u_q|): error ~ eps^(2/3) relative.
  void fd_jacobian(const double* u, const double* p, double* J) {
    double x[kMaxModelSpecies], rp[kMaxModelSpecies], rm[kMaxModelSpecies];
    std::copy(u, u + ns, x);
    const double c = std::cbrt(std::numeric_limits<double>::epsilon());
    for (int q = 0; q < ns; ++q) {
      const double h = c * (1.0 + std::fabs(u[q]));
      x[q] = u[q] + h;
      rates(x, p, rp);
      x[q] = u[q] - h;
      rates(x, p, rm);
      x[q] = u[q];
      for (int s = 0; s < ns; ++s)
        J[s * ns + q] = (rp[s] - rm[s]) / (2 * h);
    }
  }
  std::vector<std::unique_ptr<mu::Parser>> jparsers; // d R_s / d u_q, row-major; empty: FD
};

// Parses one expression (key: its option in messages) and adds the names in it that are not
// species to params.
std::unique_ptr<mu::Parser> parse_one(const std::string& text, const std::string& key,
                                      const std::vector<std::string>& species,
                                      std::vector<std::string>& params) {
  auto P = std::make_unique<mu::Parser>();
  if (text.find_first_not_of(" \t") == std::string::npos)
    throw UserError(key + ": empty expression (on the command line a value that starts with "
                          "'-' is read as an option name: write \"0 - k*a\" or \" -k*a\")");
  if (const std::string bad = top_level_problem(text); !bad.empty())
    throw UserError(key + " " + text + ": " + bad);
  try {
    P->DefineConst("pi", M_PI);
    P->SetExpr(text);
    for (const auto& used : P->GetUsedVar()) { // parses; lists undefined names too
      const std::string& n = used.first;
      if (std::count(species.begin(), species.end(), n)) continue;
      if (!std::count(params.begin(), params.end(), n)) params.push_back(n);
    }
  } catch (const mu::Parser::exception_type& e) {
    throw UserError(key + " " + text + ": " + e.GetMsg());
  }
  return P;
}

// Parses every expression (rates, then the Jacobian's) and returns the names that are not
// species (the parameters).
std::vector<std::string> parse_all(const CustomKinetics& spec, Expressions& ex) {
  std::vector<std::string> params;
  for (size_t s = 0; s < spec.species.size(); ++s)
    ex.parsers.push_back(parse_one(spec.rates[s], spec.keys[s], spec.species, params));
  for (size_t e = 0; e < spec.jac.size(); ++e)
    ex.jparsers.push_back(parse_one(spec.jac[e], spec.jac_keys[e], spec.species, params));
  std::sort(params.begin(), params.end());
  return params;
}

// Binds every parser's names to ex.vars (species, then parameters).
void bind_all(const CustomKinetics& spec, const std::vector<std::string>& all, Expressions& ex) {
  auto bind = [&](mu::Parser& P, const std::string& key, const std::string& text) {
    try {
      for (size_t v = 0; v < all.size(); ++v)
        P.DefineVar(all[v], &ex.vars[v]);
      P.Eval(); // binds the variables
    } catch (const mu::Parser::exception_type& e) {
      throw UserError(key + " " + text + ": " + e.GetMsg());
    }
  };
  for (size_t s = 0; s < ex.parsers.size(); ++s)
    bind(*ex.parsers[s], spec.keys[s], spec.rates[s]);
  for (size_t e = 0; e < ex.jparsers.size(); ++e)
    bind(*ex.jparsers[e], spec.jac_keys[e], spec.jac[e]);
}

} // namespace

void check_species(const CustomKinetics& spec) {
  if (spec.species.empty())
    throw UserError("-species: the custom model needs its species, e.g. -species a,b");
  std::set<std::string> seen;
  for (const auto& n : spec.species) {
    if (!is_identifier(n) || kReserved.count(n))
      throw UserError("-species " + n +
                      ": not a usable species name (letters, digits and _, starting with a "
                      "letter; not x, y, z, t or pi)");
    if (!seen.insert(lower_case(n)).second)
      throw UserError("-species " + n +
                      ": given twice (species names are compared ignoring "
                      "case, as option names like -D_" +
                      n + " are)");
  }
  if (spec.species.size() > static_cast<size_t>(kMaxModelSpecies))
    throw UserError("-species: " + std::to_string(spec.species.size()) +
                    " species, allowed at most " + std::to_string(kMaxModelSpecies));
  const size_t nj = spec.species.size() * spec.species.size();
  if (!spec.jac.empty() && (spec.jac.size() != nj || spec.jac_keys.size() != nj))
    throw UserError("-jac_*: give all " + std::to_string(nj) + " Jacobian entries or none");
}

ModelInfo custom_model(const CustomKinetics& spec) {
  check_species(spec);
  auto ex = std::make_shared<Expressions>();
  const std::vector<std::string> params = parse_all(spec, *ex);
  ex->ns = static_cast<int>(spec.species.size());
  ex->np = static_cast<int>(params.size());
  ex->vars.assign(static_cast<size_t>(ex->ns + ex->np), 0.0);
  std::vector<std::string> all = spec.species;
  all.insert(all.end(), params.begin(), params.end());
  bind_all(spec, all, *ex);
  // The bytecode is muParser's internal form: read as 2.3.3 to 2.3.5 write it (identical
  // ParseCmdCodeBulk), else evaluated cell by cell.
  ex->columns = ex->ns + ex->np <= Expressions::kMaxVars && mu::ParserVersion.rfind("2.3.", 0) == 0;
  for (auto& P : ex->parsers) {
    ex->programs.emplace_back(P->GetByteCode(), ex->vars.data(), ex->ns + ex->np);
    ex->columns = ex->columns && ex->programs.back().ok;
    ex->depth = std::max(ex->depth, ex->programs.back().depth);
  }
  auto names = std::make_shared<detail::RuntimeNames>();
  names->name = "custom";
  names->doc = "user-defined kinetics (-species, -rate_<species>)";
  names->reference = "user";
  constexpr double big = std::numeric_limits<double>::max();
  for (size_t s = 0; s < spec.species.size(); ++s)
    names->add_species(spec.species[s], 1.0, 0.0, "species of " + spec.keys[s]);
  for (const auto& p : params)
    if (kCoordinates.count(p))
      names->add_param(p, std::nan(""), -big, big, p + " in the custom rates", p);
    else
      names->add_param(p, std::nan(""), -big, big, "parameter of the custom rates");
  ModelInfo m{};
  m.clamp_default = false;
  m.rates = [ex](const double* u, const double* p, double* r) { ex->rates(u, p, r); };
  m.jacobian = [ex](const double* u, const double* p, double* J) { ex->jacobian(u, p, J); };
  m.rates_row = [ex](int n, const double* const* u, const double* const* prow, const double* pc,
                     double* const* r) { ex->rates_row(n, u, prow, pc, r); };
  m.steady_state = [](const double*, double*) { return false; };
  names->finish(names, m);
  return m;
}

} // namespace morphogen
