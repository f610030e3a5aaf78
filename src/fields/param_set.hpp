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
  bool any_field() const { return field_mask() != 0; }
  // Bit q set where parameter q is a field (parameters from the 32nd on: bit 31).
  unsigned field_mask() const {
    unsigned m = 0;
    for (size_t q = 0; q < field.size(); ++q)
      if (field[q].get()) m |= 1u << (q < 31 ? q : 31);
    return m;
  }
  // For kernels in field mode: each scalar parameter as a row of n copies (empty rows for the
  // fields). Called again after the scalars change (parameters using t).
  void expand_scalars(size_t n, std::vector<std::vector<double>>& rows) const {
    rows.resize(scalar.size());
    for (size_t q = 0; q < scalar.size(); ++q)
      rows[q].assign(field[q].get() ? 0 : n, scalar[q]);
  }
};

} // namespace morphogen
