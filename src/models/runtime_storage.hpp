// Owned names of a model built at run time: ModelInfo's species/params/name pointers point
// into this (held by ModelInfo::storage).
#pragma once

#include "models/model_info.hpp"

#include <memory>
#include <string>
#include <vector>

namespace morphogen::detail {

struct RuntimeNames {
  std::string name, doc, reference;
  std::vector<std::string> species_names, species_docs, param_names, param_docs, param_texts;
  std::vector<SpeciesInfo> species;
  std::vector<ParamInfo> params;

  void add_species(std::string n, double D, double init, std::string doc) {
    species_names.push_back(std::move(n));
    species_docs.push_back(std::move(doc));
    species.push_back({nullptr, D, init, nullptr});
  }
  // def_text: a default given as an expression ("" for none: def).
  void add_param(std::string n, double def, double lo, double hi, std::string doc,
                 std::string def_text = "") {
    param_names.push_back(std::move(n));
    param_docs.push_back(std::move(doc));
    param_texts.push_back(std::move(def_text));
    params.push_back({nullptr, def, lo, hi, nullptr, nullptr});
  }
  // Points the infos at the owned strings and fills m's descriptors (the kinetics are the
  // caller's); `self` keeps this alive as long as any copy of m.
  void finish(const std::shared_ptr<const void>& self, ModelInfo& m) {
    for (size_t s = 0; s < species.size(); ++s)
      species[s].name = species_names[s].c_str(), species[s].doc = species_docs[s].c_str();
    for (size_t q = 0; q < params.size(); ++q)
      params[q].name = param_names[q].c_str(), params[q].doc = param_docs[q].c_str(),
      params[q].def_text = param_texts[q].empty() ? nullptr : param_texts[q].c_str();
    m.name = name.c_str();
    m.doc = doc.c_str();
    m.reference = reference.c_str();
    m.nspecies = static_cast<int>(species.size());
    m.nparams = static_cast<int>(params.size());
    m.species = species.data();
    m.params = params.data();
    m.storage = self;
  }
};

} // namespace morphogen::detail
