// A model's runtime descriptor (species, parameters, kinetics) and the registry of all models by
// name, built at compile time from the header-only model types in models/all_models.hpp. The
// kernels instantiated from a model (explicit sweeps, reaction substeps) are the integrators'
// business (app/model_registry.hpp adds them).
#pragma once

#include "models/all_models.hpp"
#include "models/model.hpp"

#include <functional>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace morphogen {

// Kinetics as callables: a model type's static functions, or a model built at run time
// (models/runtime_model.hpp: coupled layers, user-defined rates) whose state `storage` owns.
using RatesFn = std::function<void(const double* u, const double* p, double* r)>;
using SteadyFn = std::function<bool(const double* p, double* u)>;
// The rates of a row of n cells at once: r[s][i] = R_s(u[0][i], u[1][i], ...; p_i) with
// p_i[q] = prow[q][i] when prow is non-null (per-cell parameters), else pconst[q]. Bitwise
// equal to rates() called cell by cell.
using RatesRowFn = std::function<void(int n, const double* const* u, const double* const* prow,
                                      const double* pconst, double* const* r)>;

struct ModelInfo {
  const char* name;
  const char* doc;
  const char* reference;
  int nspecies;
  int nparams;
  const SpeciesInfo* species;
  const ParamInfo* params;
  bool clamp_default;
  RatesFn rates;
  RatesFn jacobian; // J[s*N+q] = dR_s/du_q
  SteadyFn steady_state;
  std::shared_ptr<const void> storage; // names and kinetics of a model built at run time
  // Optional (empty for the compiled models): rates() over a row in one call, for models whose
  // per-cell call is costly (custom_model: muParser's bulk mode). The explicit general path
  // uses it when set (integrators/runtime_kernels.cpp).
  RatesRowFn rates_row = {};
};

template <class M> ModelInfo model_info() {
  return {M::name,
          M::doc,
          M::reference,
          M::nspecies,
          M::nparams,
          M::species.data(),
          M::params.data(),
          M::clamp_default,
          &M::rates,
          &M::jacobian,
          &M::steady_state,
          nullptr,
          {}};
}

namespace detail {
template <class Tuple, size_t... I> std::vector<ModelInfo> model_infos(std::index_sequence<I...>) {
  return {model_info<std::tuple_element_t<I, Tuple>>()...};
}
} // namespace detail

// Every registered model, in AllModels order.
inline const std::vector<ModelInfo>& model_infos() {
  static const std::vector<ModelInfo> all =
      detail::model_infos<AllModels>(std::make_index_sequence<std::tuple_size_v<AllModels>>{});
  return all;
}

} // namespace morphogen
