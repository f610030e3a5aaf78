// Model parameters on the grid: each parameter is a scalar when it has one value everywhere
// (kept out of memory traffic), or a Vec on the DMDA (global layout, owned cells) when it
// varies in space.
#pragma once

#include "core/petsc_handle.hpp"

#include <string>
#include <vector>

namespace morphogen {

struct ParamSet {
  std::vector<std::string> names;
  std::vector<double> scalar; // the value for a constant parameter
  std::vector<VecH> field;    // non-null for a spatially varying parameter
  bool any_field() const {
    for (const auto& f : field)
      if (f.get()) return true;
    return false;
  }
};

} // namespace morphogen
