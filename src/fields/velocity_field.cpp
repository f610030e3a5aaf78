#include "fields/velocity_field.hpp"

#include "core/collective_error.hpp"
#include "core/user_error.hpp"

#include <algorithm>
#include <cmath>

namespace morphogen {

VelocityField::VelocityField(const Grid& grid, Options& opt, std::uint64_t seed,
                             const std::string& base_dir)
    : grid_(grid) {
  const char* axes[3] = {"x", "y", "z"};
  for (int d = 0; d < grid.dim(); ++d) {
    const std::string key = std::string("velocity_") + axes[d];
    const std::string text =
        opt.string(key, "0",
                   std::string("advection velocity, ") + axes[d] +
                       " component: expression of x, y, z, t (once per step if it uses t)");
    spec_.push_back(std::make_unique<ValueSpec>(key, text, grid.spec(), seed, base_dir));
  }
}

bool VelocityField::uses_time() const {
  return std::any_of(spec_.begin(), spec_.end(), [](const auto& s) { return s->uses_time(); });
}

void VelocityField::evaluate(int d, const Box& box, double t, double* out) {
  const GridSpec& g = grid_.spec();
  ValueSpec& spec = *spec_[d];
  std::string err;
  try {
    PetscInt o = 0;
    for (PetscInt k = box.s[2]; k < box.s[2] + box.m[2] && err.empty(); ++k)
      for (PetscInt j = box.s[1]; j < box.s[1] + box.m[1] && err.empty(); ++j)
        for (PetscInt i = box.s[0]; i < box.s[0] + box.m[0]; ++i, ++o) {
          // The periodic image inside the domain (non-periodic axes never leave it).
          const PetscInt c[3] = {(i % g.n[0] + g.n[0]) % g.n[0], (j % g.n[1] + g.n[1]) % g.n[1],
                                 (k % g.n[2] + g.n[2]) % g.n[2]};
          const double v = spec.at_cell(c[0], c[1], c[2], t);
          if (!std::isfinite(v)) {
            err = "-" + spec.key() + " " + spec.text() + ": value " + format_number(v) +
                  " at cell (" + std::to_string(c[0]) + "," + std::to_string(c[1]) + "," +
                  std::to_string(c[2]) + "), t = " + format_number(t) +
                  ": a velocity must be finite";
            break;
          }
          out[o] = v;
        }
  } catch (const UserError& e) {
    err = e.what();
  }
  throw_if_any(grid_.comm(), err);
}

std::array<double, 3> VelocityField::max_abs(double t) {
  std::array<double, 3> m{0, 0, 0};
  std::vector<double> v(static_cast<size_t>(grid_.owned().size()));
  for (int d = 0; d < grid_.dim(); ++d) {
    evaluate(d, grid_.owned(), t, v.data());
    for (double x : v)
      m[d] = std::max(m[d], std::fabs(x));
  }
  MPI_Allreduce(MPI_IN_PLACE, m.data(), 3, MPI_DOUBLE, MPI_MAX, grid_.comm());
  return m;
}

} // namespace morphogen
