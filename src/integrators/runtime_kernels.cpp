#include "integrators/runtime_kernels.hpp"

#include <array>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace morphogen {

namespace {

// The kernels' model object: rates and jacobian forwarded to the model's callables.
struct RuntimeKinetics {
  RatesFn rates_fn, jacobian_fn;
  RatesRowFn rates_row; // may be empty
  void rates(const double* u, const double* p, double* r) const { rates_fn(u, p, r); }
  void jacobian(const double* u, const double* p, double* J) const { jacobian_fn(u, p, J); }
};

// The explicit row: with the model's row rates when it has them (one call per row into a
// scratch of NS rows, then the update), else cell by cell through rates().
template <int NS, bool FieldParams>
std::function<void(const ExplicitRow&)> pre_row(RuntimeKinetics k, int np) {
  if (k.rates_row)
    return [row = k.rates_row,
            scratch = std::make_shared<std::vector<double>>()](const ExplicitRow& a) {
      const size_t n = static_cast<size_t>(a.n > 0 ? a.n : 0);
      if (scratch->size() < NS * n) scratch->resize(NS * n);
      double* r[NS];
      for (int s = 0; s < NS; ++s)
        r[s] = scratch->data() + static_cast<size_t>(s) * n;
      row(a.n, a.src, FieldParams ? a.prow : nullptr, a.pconst, r);
      explicit_row_pre_rates<NS>(a, r);
    };
  return [k = std::move(k), np](const ExplicitRow& a) {
    explicit_row_pre_of<NS, kMaxRuntimeParams, FieldParams>(k, np, a);
  };
}

template <int NS, bool FieldParams> auto reaction_row_fn(RuntimeKinetics k, int np) {
  return [k = std::move(k),
          np](ReactionScheme scheme, int n, const double* const* u, const double* const* prow,
              const double* pconst, const double* const* S0, const double* const* S1, double dt,
              double tol, int maxit, const double* floor, double* const* out, CellSolve* worst) {
    return reaction_row_of<NS, kMaxRuntimeParams, FieldParams>(
        k, np, scheme, n, u, prow, pconst, S0, S1, dt, tol, maxit, floor, out, worst);
  };
}

template <int NS> ModelKernels kernels_for(const RuntimeKinetics& k, int np) {
  ModelKernels out;
  out.fused = false;
  out.explicit_pre[0] = pre_row<NS, false>(k, np);
  out.explicit_pre[1] = pre_row<NS, true>(k, np);
  out.reaction_row[0] = reaction_row_fn<NS, false>(k, np);
  out.reaction_row[1] = reaction_row_fn<NS, true>(k, np);
  return out;
}

template <size_t... I>
ModelKernels dispatch(int ns, const RuntimeKinetics& k, int np, std::index_sequence<I...>) {
  using Maker = ModelKernels (*)(const RuntimeKinetics&, int);
  static constexpr std::array<Maker, sizeof...(I)> makers{&kernels_for<static_cast<int>(I) + 1>...};
  return makers[static_cast<size_t>(ns - 1)](k, np);
}

} // namespace

ModelKernels runtime_model_kernels(const ModelInfo& model) {
  if (model.nspecies < 1 || model.nspecies > kMaxRuntimeSpecies)
    throw std::invalid_argument(std::string("model ") + model.name + " has " +
                                std::to_string(model.nspecies) + " species; allowed 1 to " +
                                std::to_string(kMaxRuntimeSpecies));
  if (model.nparams < 0 || model.nparams > kMaxRuntimeParams)
    throw std::invalid_argument(std::string("model ") + model.name + " has " +
                                std::to_string(model.nparams) + " parameters; allowed at most " +
                                std::to_string(kMaxRuntimeParams));
  const RuntimeKinetics k{model.rates, model.jacobian, model.rates_row};
  return dispatch(model.nspecies, k, model.nparams, std::make_index_sequence<kMaxRuntimeSpecies>{});
}

} // namespace morphogen
