#include "fields/field_fill.hpp"

#include "core/collective_error.hpp"
#include "core/options.hpp"
#include "core/user_error.hpp"

#include <vector>

namespace morphogen {

void fill_field(const Grid& grid, ValueSpec& spec, double* a, ArrayLayout layout, double lo,
                double hi, double t) {
  std::string err;
  try {
    const Box& ob = grid.owned();
    std::vector<double> row(static_cast<size_t>(ob.m[0]));
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2] && err.empty(); ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1] && err.empty(); ++j) {
        spec.fill_row(ob.s[0], ob.m[0], j, k, t, row.data());
        for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
          const double v = row[static_cast<size_t>(i - ob.s[0])];
          if (!(v >= lo && v <= hi)) {
            err = "-" + spec.key() + " " + spec.text() + ": value " + format_double(v) +
                  " at cell (" + std::to_string(i) + "," + std::to_string(j) + "," +
                  std::to_string(k) + ")" +
                  (spec.uses_time() ? " at t = " + format_number(t) : std::string()) +
                  " is outside the allowed range [" + format_double(lo) + ", " + format_double(hi) +
                  "]";
            break;
          }
          a[layout == ArrayLayout::Owned ? grid.owned_index(i, j, k) : grid.local_index(i, j, k)] =
              v;
        }
      }
  } catch (const UserError& e) {
    err = e.what();
  }
  throw_if_any(grid.comm(), err);
}

} // namespace morphogen
