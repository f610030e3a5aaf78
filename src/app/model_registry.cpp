#include "app/model_registry.hpp"

#include <tuple>

namespace morphogen {

namespace {

template <class M> ModelEntry make_entry() {
  ModelEntry e{model_info<M>(), model_kernels<M>()};
  return e;
}

template <class Tuple, size_t... I> std::vector<ModelEntry> make_all(std::index_sequence<I...>) {
  return {make_entry<std::tuple_element_t<I, Tuple>>()...};
}

} // namespace

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
