#include "app/model_setup.hpp"

#include "core/user_error.hpp"
#include "integrators/runtime_kernels.hpp"
#include "models/runtime_model.hpp"

#include <algorithm>
#include <stdexcept>

namespace morphogen {

namespace {

// -jac_<s>_<q> EXPR: dR_s/du_q, all ns^2 entries or none (then central differences).
void read_custom_jacobian(Options& opt, CustomKinetics& spec) {
  std::vector<std::string> missing, keys;
  for (const auto& s : spec.species)
    for (const auto& q : spec.species) {
      const std::string key = "jac_" + s + "_" + q;
      if (std::count(keys.begin(), keys.end(), key))
        throw UserError("-" + key +
                        ": names two Jacobian entries (species names joined by _ "
                        "are ambiguous): rename the species");
      keys.push_back(key);
      const auto text = opt.get(key, "Jacobian entry dR_" + s + "/d" + q +
                                         " (custom model): an expression like the rates; all "
                                         "entries or none (finite differences)");
      if (text) {
        spec.jac.push_back(*text);
        spec.jac_keys.push_back("-" + key);
      } else {
        missing.push_back("-" + key);
      }
    }
  if (spec.jac.empty()) return;
  if (!missing.empty())
    throw UserError(missing.front() + ": missing; a Jacobian by expressions needs all " +
                    std::to_string(keys.size()) + " entries -jac_<s>_<q> (" +
                    std::to_string(missing.size()) + " missing), or none for finite differences");
}

// Under -layers L each parameter p of the rates is given per layer (-params_p1, ...).
ModelInfo read_custom(Options& opt, int layers) {
  CustomKinetics spec;
  if (!opt.is_set("species"))
    throw UserError("-model custom: give the species (-species a,b) and each one's rate "
                    "(-rate_a EXPR, -rate_b EXPR)");
  spec.species = opt.list("species", {}, 1, kMaxRuntimeSpecies,
                          "species of the custom model, comma-separated (e.g. a,b)");
  check_species(spec);
  for (const auto& s : spec.species) {
    const std::string key = "rate_" + s;
    const auto text = opt.get(key, "rate of " + s +
                                       " (custom model): an expression of the "
                                       "species, x, y, z, t and parameters");
    if (!text)
      throw UserError("-species " + s + ": the custom model needs its rate, -" + key +
                      " EXPR (e.g. \"k*a - a*b\")");
    spec.rates.push_back(*text);
    spec.keys.push_back("-" + key);
  }
  read_custom_jacobian(opt, spec);
  ModelInfo m = custom_model(spec);
  std::string species;
  for (const auto& s : spec.species)
    species += (species.empty() ? "" : ", ") + s;
  for (int q = 0; q < m.nparams; ++q)
    for (int l = 1; l <= layers && !m.params[q].def_text; ++l) {
      const std::string n = m.params[q].name + (layers > 1 ? std::to_string(l) : "");
      if (!opt.is_set("params_" + n))
        throw UserError("-rate_*: '" + std::string(m.params[q].name) + "' is neither a species (" +
                        species + ") nor given a value: add -params_" + n + " VALUE");
    }
  return m;
}

std::shared_ptr<const ModelEntry> runtime_entry(const ModelInfo& info) {
  try {
    return std::make_shared<const ModelEntry>(ModelEntry{info, runtime_model_kernels(info)});
  } catch (const std::invalid_argument& e) {
    throw UserError(std::string("-model ") + info.name + ": " + e.what());
  }
}

} // namespace

std::vector<std::string> model_choices() {
  std::vector<std::string> names = model_names();
  names.emplace_back("custom");
  return names;
}

std::shared_ptr<const ModelEntry> read_model_choice(Options& opt) {
  const std::string name = opt.choice("model", "turing", model_choices(), "reaction model");
  const PetscInt layers =
      opt.integer("layers", 1, 1, 16,
                  "coupled layers of the model (species a1, b1, a2, ...; coupling rates "
                  "-params_couple_<species>)");
  if (name != "custom" && layers == 1) // the registry's entry, not owned
    return std::shared_ptr<const ModelEntry>(find_model(name), [](const ModelEntry*) {});
  const ModelInfo base =
      name == "custom" ? read_custom(opt, static_cast<int>(layers)) : ModelInfo(*find_model(name));
  if (base.nspecies * layers > kMaxRuntimeSpecies)
    throw UserError(
        "-layers " + std::to_string(layers) + ": " + std::to_string(layers) + " layers of " + name +
        "'s " + std::to_string(base.nspecies) + " species make " +
        std::to_string(base.nspecies * layers) + ", allowed at most " +
        std::to_string(kMaxRuntimeSpecies) + " species (-layers " +
        std::to_string(std::max(1, kMaxRuntimeSpecies / base.nspecies)) + " or fewer here)");
  return runtime_entry(layers > 1 ? layered_model(base, static_cast<int>(layers)) : base);
}

} // namespace morphogen
