// Typed tests over every compiled model: MG_MODEL_TYPED_TEST_SUITE(Suite) declares the fixture
// Suite<M> and runs its TYPED_TESTs once per model of models/all_models.hpp (AllModels), each
// named by the model.
#pragma once

#include "models/all_models.hpp"

#include <gtest/gtest.h>

#include <string>
#include <tuple>

namespace morphogen::testing {

template <class Tuple> struct ToTypes;
template <class... Ms> struct ToTypes<std::tuple<Ms...>> { using type = ::testing::Types<Ms...>; };
using ModelTypes = ToTypes<AllModels>::type;

struct ModelNames {
  template <class M> static std::string GetName(int) { return M::name; }
};

} // namespace morphogen::testing

#define MG_MODEL_TYPED_TEST_SUITE(Suite)                                                           \
  template <class M> class Suite : public ::testing::Test {};                                      \
  TYPED_TEST_SUITE(Suite, morphogen::testing::ModelTypes, morphogen::testing::ModelNames)
