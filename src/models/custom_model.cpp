// User-defined kinetics from muParser expressions (see models/runtime_model.hpp).
#include "core/user_error.hpp"
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

  void rates(const double* u, const double* p, double* r) {
    std::copy(u, u + ns, vars.begin());
    std::copy(p, p + np, vars.begin() + ns);
    for (int s = 0; s < ns; ++s)
      r[s] = parsers[static_cast<size_t>(s)]->Eval();
  }
  // Central differences, step cbrt(eps) (1 + |u_q|): error ~ eps^(2/3) relative.
  void jacobian(const double* u, const double* p, double* J) {
    std::vector<double> x(u, u + ns), rp(static_cast<size_t>(ns)), rm(static_cast<size_t>(ns));
    const double c = std::cbrt(std::numeric_limits<double>::epsilon());
    for (int q = 0; q < ns; ++q) {
      const double h = c * (1.0 + std::fabs(u[q]));
      x[static_cast<size_t>(q)] = u[q] + h;
      rates(x.data(), p, rp.data());
      x[static_cast<size_t>(q)] = u[q] - h;
      rates(x.data(), p, rm.data());
      x[static_cast<size_t>(q)] = u[q];
      for (int s = 0; s < ns; ++s)
        J[s * ns + q] = (rp[static_cast<size_t>(s)] - rm[static_cast<size_t>(s)]) / (2 * h);
    }
  }
};

void check_species(const CustomKinetics& spec) {
  if (spec.species.empty())
    throw UserError("-species: the custom model needs its species, e.g. -species a,b");
  std::set<std::string> seen;
  for (const auto& n : spec.species) {
    if (!is_identifier(n) || kReserved.count(n))
      throw UserError("-species " + n +
                      ": not a usable species name (letters, digits and _, starting with a "
                      "letter; not x, y, z, t or pi)");
    if (!seen.insert(n).second) throw UserError("-species " + n + ": given twice");
  }
}

// Parses every expression and returns the names that are not species (the parameters).
std::vector<std::string> parse_all(const CustomKinetics& spec, Expressions& ex) {
  std::vector<std::string> params;
  for (size_t s = 0; s < spec.species.size(); ++s) {
    auto P = std::make_unique<mu::Parser>();
    const std::string& text = spec.rates[s];
    if (text.find_first_not_of(" \t") == std::string::npos)
      throw UserError(spec.keys[s] +
                      ": empty rate expression (on the command line a value that starts with "
                      "'-' is read as an option name: write \"0 - k*a\" or \" -k*a\")");
    try {
      P->DefineConst("pi", M_PI);
      P->SetExpr(text);
      for (const auto& used : P->GetUsedVar()) { // parses; lists undefined names too
        const std::string& n = used.first;
        if (std::count(spec.species.begin(), spec.species.end(), n)) continue;
        if (!std::count(params.begin(), params.end(), n)) params.push_back(n);
      }
    } catch (const mu::Parser::exception_type& e) {
      throw UserError(spec.keys[s] + " " + text + ": " + e.GetMsg());
    }
    ex.parsers.push_back(std::move(P));
  }
  std::sort(params.begin(), params.end());
  return params;
}

} // namespace

ModelInfo custom_model(const CustomKinetics& spec) {
  check_species(spec);
  auto ex = std::make_shared<Expressions>();
  const std::vector<std::string> params = parse_all(spec, *ex);
  ex->ns = static_cast<int>(spec.species.size());
  ex->np = static_cast<int>(params.size());
  ex->vars.assign(static_cast<size_t>(ex->ns + ex->np), 0.0);
  std::vector<std::string> all = spec.species;
  all.insert(all.end(), params.begin(), params.end());
  for (size_t s = 0; s < ex->parsers.size(); ++s) {
    try {
      for (size_t v = 0; v < all.size(); ++v)
        ex->parsers[s]->DefineVar(all[v], &ex->vars[v]);
      ex->parsers[s]->Eval(); // binds the variables
    } catch (const mu::Parser::exception_type& e) {
      throw UserError(spec.keys[s] + " " + spec.rates[s] + ": " + e.GetMsg());
    }
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
  m.steady_state = [](const double*, double*) { return false; };
  names->finish(names, m);
  return m;
}

} // namespace morphogen
