// Coupled layers of a registered model (see models/runtime_model.hpp).
#include "core/user_error.hpp"
#include "models/runtime_model.hpp"
#include "models/runtime_storage.hpp"

#include <set>

namespace morphogen {

namespace {

using PlainRates = void (*)(const double*, const double*, double*);

struct Layers {
  ModelInfo base;
  int L = 0, ns = 0, np = 0;
  PlainRates plain = nullptr; // base.rates when it is a compiled model's function (no indirection)

  // Coupling rate of base species s (the parameters after the layers' own).
  double couple(const double* p, int s) const { return p[L * np + s]; }

  void rates(const double* u, const double* p, double* r) const {
    for (int l = 0; l < L; ++l)
      if (plain)
        plain(u + l * ns, p + l * np, r + l * ns);
      else
        base.rates(u + l * ns, p + l * np, r + l * ns);
    for (int s = 0; s < ns; ++s) {
      const double k = couple(p, s);
      if (k == 0.0) continue;
      for (int l = 0; l < L; ++l) {
        const double ul = u[l * ns + s];
        if (l > 0) r[l * ns + s] += k * (u[(l - 1) * ns + s] - ul);
        if (l + 1 < L) r[l * ns + s] += k * (u[(l + 1) * ns + s] - ul);
      }
    }
  }

  void jacobian(const double* u, const double* p, double* J) const {
    const int n = L * ns;
    std::fill(J, J + n * n, 0.0);
    double block[kMaxModelSpecies * kMaxModelSpecies]; // ns <= kMaxModelSpecies (checked)
    for (int l = 0; l < L; ++l) {
      base.jacobian(u + l * ns, p + l * np, block);
      for (int a = 0; a < ns; ++a)
        for (int b = 0; b < ns; ++b)
          J[(l * ns + a) * n + l * ns + b] = block[a * ns + b];
    }
    for (int s = 0; s < ns; ++s)
      for (int l = 0; l < L; ++l) {
        const int row = l * ns + s;
        for (int m : {l - 1, l + 1}) {
          if (m < 0 || m >= L) continue;
          J[row * n + row] -= couple(p, s);
          J[row * n + m * ns + s] += couple(p, s);
        }
      }
  }

  bool steady_state(const double* p, double* u) const {
    for (int l = 0; l < L; ++l)
      if (!base.steady_state(p + l * np, u + l * ns)) return false;
    for (int s = 0; s < ns; ++s)
      for (int l = 1; l < L; ++l)
        if (couple(p, s) != 0.0 && u[l * ns + s] != u[s]) return false;
    return true;
  }
};

} // namespace

ModelInfo layered_model(const ModelInfo& base, int layers) {
  if (layers < 2 || layers > 16)
    throw UserError("-layers " + std::to_string(layers) + ": allowed 2 to 16 (1: the model alone)");
  if (base.nspecies > kMaxModelSpecies)
    throw UserError("-layers " + std::to_string(layers) + ": model " + base.name + " has " +
                    std::to_string(base.nspecies) + " species, allowed at most " +
                    std::to_string(kMaxModelSpecies) + " per layer");
  auto names = std::make_shared<detail::RuntimeNames>();
  names->name = std::string(base.name);
  names->doc = std::to_string(layers) + " coupled layers of " + base.name + ": " + base.doc;
  names->reference = std::string("Sanderson et al. 2006, eqs. 20-21; ") + base.reference;
  std::set<std::string> seen;
  auto unique = [&](const std::string& n, const char* what) {
    if (!seen.insert(n).second)
      throw UserError("-layers " + std::to_string(layers) + ": the " + what + " name " + n +
                      " of model " + base.name + " occurs twice across layers");
    return n;
  };
  for (int l = 1; l <= layers; ++l)
    for (int s = 0; s < base.nspecies; ++s) {
      const SpeciesInfo& si = base.species[s];
      names->add_species(unique(si.name + std::to_string(l), "species"), si.D, si.init,
                         std::string(si.doc) + " (layer " + std::to_string(l) + ")");
    }
  seen.clear();
  for (int l = 1; l <= layers; ++l)
    for (int q = 0; q < base.nparams; ++q) {
      const ParamInfo& pi = base.params[q];
      names->add_param(unique(pi.name + std::to_string(l), "parameter"), pi.def, pi.lo, pi.hi,
                       std::string(pi.doc) + " (layer " + std::to_string(l) + ")",
                       pi.def_text ? pi.def_text : "");
    }
  for (int s = 0; s < base.nspecies; ++s)
    names->add_param(unique(std::string("couple_") + base.species[s].name, "parameter"), 0.0, 0.0,
                     1e6,
                     std::string("coupling rate of ") + base.species[s].name +
                         " between neighbouring layers (mu, nu of eqs. 20-21)");
  const PlainRates* plain = base.rates.target<PlainRates>();
  auto kin = std::make_shared<const Layers>(
      Layers{base, layers, base.nspecies, base.nparams, plain ? *plain : nullptr});
  ModelInfo m{};
  m.clamp_default = base.clamp_default;
  m.rates = [kin](const double* u, const double* p, double* r) { kin->rates(u, p, r); };
  m.jacobian = [kin](const double* u, const double* p, double* J) { kin->jacobian(u, p, J); };
  m.steady_state = [kin](const double* p, double* u) { return kin->steady_state(p, u); };
  names->finish(names, m);
  return m;
}

} // namespace morphogen
