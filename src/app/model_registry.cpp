#include "app/model_registry.hpp"

#include "models/all_models.hpp"

#include <tuple>

namespace morphogen {

namespace {

template <class M> ModelEntry make_entry() {
  ModelEntry e{};
  e.name = M::name;
  e.doc = M::doc;
  e.reference = M::reference;
  e.nspecies = M::nspecies;
  e.nparams = M::nparams;
  e.species = M::species.data();
  e.params = M::params.data();
  e.clamp_default = M::clamp_default;
  e.rates = &M::rates;
  e.jacobian = &M::jacobian;
  e.steady_state = &M::steady_state;
  e.explicit_row[0][0] = &explicit_row<M, 3, false, false>; // 5pt
  e.explicit_row[0][1] = &explicit_row<M, 5, false, false>; // 7pt
  e.explicit_row[0][2] = &explicit_row<M, 3, true, false>;  // 9pt
  e.explicit_row[1][0] = &explicit_row<M, 3, false, true>;
  e.explicit_row[1][1] = &explicit_row<M, 5, false, true>;
  e.explicit_row[1][2] = &explicit_row<M, 3, true, true>;
  e.explicit_pre[0] = &explicit_row_pre<M, false>;
  e.explicit_pre[1] = &explicit_row_pre<M, true>;
  e.reaction_row[0] = &reaction_row<M, false>;
  e.reaction_row[1] = &reaction_row<M, true>;
  return e;
}

template <class Tuple, size_t... I> std::vector<ModelEntry> make_all(std::index_sequence<I...>) {
  return {make_entry<std::tuple_element_t<I, Tuple>>()...};
}

} // namespace

ExplicitRowFn ModelEntry::row_kernel(bool field_params, int nrows, bool box) const {
  const int idx = !box && nrows == 3 ? 0 : !box && nrows == 5 ? 1 : box && nrows == 3 ? 2 : -1;
  return idx < 0 ? nullptr : explicit_row[field_params ? 1 : 0][idx];
}

const std::vector<ModelEntry>& model_registry() {
  static const std::vector<ModelEntry> all =
      make_all<AllModels>(std::make_index_sequence<std::tuple_size_v<AllModels>>{});
  return all;
}

const ModelEntry* find_model(const std::string& name) {
  for (const auto& e : model_registry())
    if (name == e.name) return &e;
  return nullptr;
}

std::vector<std::string> model_names() {
  std::vector<std::string> out;
  for (const auto& e : model_registry())
    out.emplace_back(e.name);
  return out;
}

} // namespace morphogen
