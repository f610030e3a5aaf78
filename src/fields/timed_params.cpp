#include "fields/timed_params.hpp"

#include "core/options.hpp"
#include "core/user_error.hpp"
#include "fields/field_fill.hpp"

#include <cmath>

namespace morphogen {

void TimedParams::add(int q, std::unique_ptr<ValueSpec> spec, double lo, double hi) {
  entries_.push_back({q, std::move(spec), lo, hi});
  evaluated_ = false;
}

void TimedParams::set_time(ParamSet& params, double t) {
  if (evaluated_ && t == last_t_) return;
  for (Entry& e : entries_) {
    const size_t q = static_cast<size_t>(e.q);
    if (e.spec->uniform_in_space()) {
      const double v = e.spec->at_cell(0, 0, 0, t); // the same on every rank
      if (!(v >= e.lo && v <= e.hi))
        throw UserError("-" + e.spec->key() + " " + e.spec->text() + ": value " + format_number(v) +
                        " at t = " + format_number(t) + " is out of range, " +
                        allowed_range(e.lo, e.hi));
      params.scalar[q] = v;
    } else {
      PetscScalar* a = nullptr;
      MG_PETSC(VecGetArray(params.field[q], &a));
      try {
        fill_field(grid_, *e.spec, a, ArrayLayout::Owned, e.lo, e.hi, t);
      } catch (...) {
        MG_PETSC(VecRestoreArray(params.field[q], &a));
        throw;
      }
      MG_PETSC(VecRestoreArray(params.field[q], &a));
    }
  }
  last_t_ = t;
  evaluated_ = true;
}

} // namespace morphogen
