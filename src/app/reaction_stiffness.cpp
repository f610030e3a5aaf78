#include "app/reaction_stiffness.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace morphogen {

namespace {

// The forward-Euler bound of a 2x2 Jacobian's decaying eigenvalues (infinity if none); sets
// the eigenvalue that gives it.
double bound_2x2(const double* J, double& re, double& im) {
  const double tr = J[0] + J[3], det = J[0] * J[3] - J[1] * J[2];
  const double disc = 0.25 * tr * tr - det;
  double best = std::numeric_limits<double>::infinity();
  if (disc >= 0) {
    const double r = std::sqrt(disc);
    for (double l : {0.5 * tr - r, 0.5 * tr + r})
      if (l < 0 && -2.0 / l < best) best = -2.0 / l, re = l, im = 0;
  } else if (tr < 0 && det > 0) { // lambda = tr/2 +- i sqrt(-disc), |lambda|^2 = det
    best = -tr / det, re = 0.5 * tr, im = std::sqrt(-disc);
  }
  return best;
}

} // namespace

ReactionBound reaction_dt_bound(const Simulation& sim) {
  ReactionBound out;
  out.dt = std::numeric_limits<double>::infinity();
  const ModelEntry& m = sim.model();
  if (m.nspecies == 2) {
    const Grid& g = sim.grid();
    const Box& ob = g.owned();
    const ParamSet& ps = sim.params();
    std::vector<const PetscScalar*> u(2), p(static_cast<size_t>(m.nparams), nullptr);
    auto& state = const_cast<Simulation&>(sim).state();
    for (int s = 0; s < 2; ++s)
      MG_PETSC(VecGetArrayRead(state[static_cast<size_t>(s)], &u[static_cast<size_t>(s)]));
    for (size_t q = 0; q < p.size(); ++q)
      if (ps.field[q].get()) MG_PETSC(VecGetArrayRead(ps.field[q], &p[q]));
    std::vector<double> uc(2), pc(p.size() ? p.size() : 1), J(4);
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
        for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
          for (int s = 0; s < 2; ++s)
            uc[static_cast<size_t>(s)] = u[static_cast<size_t>(s)][g.local_index(i, j, k)];
          for (size_t q = 0; q < p.size(); ++q)
            pc[q] = p[q] ? p[q][g.owned_index(i, j, k)] : ps.scalar[q];
          m.jacobian(uc.data(), pc.data(), J.data());
          double re = 0, im = 0;
          const double b = bound_2x2(J.data(), re, im);
          if (b < out.dt) out = {b, {i, j, k}, re, im};
        }
    for (int s = 0; s < 2; ++s)
      MG_PETSC(VecRestoreArrayRead(state[static_cast<size_t>(s)], &u[static_cast<size_t>(s)]));
    for (size_t q = 0; q < p.size(); ++q)
      if (p[q]) MG_PETSC(VecRestoreArrayRead(ps.field[q], &p[q]));
  }
  // The global minimum and the rank that holds it (MPI_MINLOC), which then shares the details.
  struct {
    double v;
    int rank;
  } mine{out.dt, 0}, best{};
  MPI_Comm comm = sim.grid().comm();
  MPI_Comm_rank(comm, &mine.rank);
  MPI_Allreduce(&mine, &best, 1, MPI_DOUBLE_INT, MPI_MINLOC, comm);
  double detail[5] = {static_cast<double>(out.cell[0]), static_cast<double>(out.cell[1]),
                      static_cast<double>(out.cell[2]), out.lambda_re, out.lambda_im};
  MPI_Bcast(detail, 5, MPI_DOUBLE, best.rank, comm);
  out.dt = best.v;
  for (int d = 0; d < 3; ++d)
    out.cell[static_cast<size_t>(d)] = static_cast<PetscInt>(detail[d]);
  out.lambda_re = detail[3];
  out.lambda_im = detail[4];
  return out;
}

void warn_if_reaction_stiff(const Simulation& sim) {
  char kind[32] = "explicit";
  MG_PETSC(PetscOptionsGetString(nullptr, nullptr, "-integrator", kind, sizeof kind, nullptr));
  if (std::string(kind) != "explicit") return;
  const ReactionBound b = reaction_dt_bound(sim);
  if (!(sim.dt() > b.dt)) return;
  int rank = 0;
  MPI_Comm_rank(sim.grid().comm(), &rank);
  if (rank != 0) return;
  char lambda[64];
  if (b.lambda_im != 0)
    std::snprintf(lambda, sizeof lambda, "%.3g +- %.3gi", b.lambda_re, b.lambda_im);
  else
    std::snprintf(lambda, sizeof lambda, "%.3g", b.lambda_re);
  std::fprintf(stderr,
               "morphogen: warning: -dt %.4g exceeds the reaction's explicit stability bound "
               "%.3g (Jacobian eigenvalue %s at cell (%lld,%lld,%lld) of the initial state): "
               "the run may blow up; use -dt %.3g or less, or -integrator split\n",
               sim.dt(), b.dt, lambda, static_cast<long long>(b.cell[0]),
               static_cast<long long>(b.cell[1]), static_cast<long long>(b.cell[2]), 0.9 * b.dt);
  std::fflush(stderr);
}

} // namespace morphogen
