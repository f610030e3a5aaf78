#include "fields/dirichlet_values.hpp"

#include "core/collective_error.hpp"
#include "core/user_error.hpp"

namespace morphogen {

DirichletValues::DirichletValues(const Grid& grid, const Halo& halo, std::vector<FaceValues>& out)
    : grid_(grid), halo_(halo), out_(out) {}

void DirichletValues::add(int s, std::unique_ptr<ValueSpec> g) {
  fill(s, *g, 0.0);
  if (g->uses_time()) timed_.emplace_back(s, std::move(g));
}

bool DirichletValues::time_dependent() const {
  return !timed_.empty();
}

bool DirichletValues::set_time(double t) {
  if (timed_.empty() || t == last_t_) return false;
  for (auto& [s, g] : timed_)
    fill(s, *g, t);
  last_t_ = t;
  return true;
}

void DirichletValues::fill(int s, ValueSpec& g, double t) {
  const GridSpec& spec = grid_.spec();
  const Box& gb = grid_.ghosted();
  for (int d = 0; d < spec.dim; ++d) {
    if (spec.bc[d] != Boundary::Dirichlet) continue;
    for (int side = 0; side < 2; ++side) {
      auto& face = out_[static_cast<size_t>(s)].face[2 * d + side];
      face.assign(static_cast<size_t>(halo_.face_size(d)), 0.0);
      std::string err;
      try {
        for (PetscInt k = gb.s[2]; k < gb.s[2] + gb.m[2]; ++k)
          for (PetscInt j = gb.s[1]; j < gb.s[1] + gb.m[1]; ++j)
            for (PetscInt i = gb.s[0]; i < gb.s[0] + gb.m[0]; ++i) {
              PetscInt c[3] = {i, j, k};
              if (c[d] != gb.s[d]) continue;     // one entry per face position
              for (int e = 0; e < spec.dim; ++e) // periodic images share face values
                if (spec.bc[e] == Boundary::Periodic)
                  c[e] = (c[e] % spec.n[e] + spec.n[e]) % spec.n[e];
              double x[3] = {grid_.centre(0, c[0]), grid_.centre(1, c[1]),
                             spec.dim == 3 ? grid_.centre(2, c[2]) : 0.0};
              x[d] = side == 0 ? 0.0 : spec.L[d];
              c[d] = side == 0 ? 0 : spec.n[d] - 1;
              face[halo_.face_index(d, i, j, k)] =
                  g.at_point(x[0], x[1], x[2], c[0], c[1], c[2], t);
            }
      } catch (const UserError& e) {
        err = e.what();
      }
      throw_if_any(grid_.comm(), err);
    }
  }
}

} // namespace morphogen
