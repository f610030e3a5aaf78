#include "integrators/split_integrator.hpp"

#include "core/collective_error.hpp"
#include "core/log_events.hpp"
#include "core/options.hpp"
#include "core/prefetch.hpp"
#include "fields/clamp_floor.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace morphogen {

SplitIntegrator::SplitIntegrator(const Grid& grid, ReactionRowFn fn,
                                 const std::vector<std::string>& species, const ParamSet& params,
                                 std::vector<double> floor, SourceTerms* sources,
                                 DiffusionSolver& diffusion, const SplitSettings& settings)
    : grid_(grid), fn_(fn), species_(species), params_(params), floor_(std::move(floor)),
      sources_(sources), diffusion_(diffusion), set_(settings) {
  const size_t row = static_cast<size_t>(grid.owned().m[0]);
  if (params_.any_field()) params_.expand_scalars(row, const_rows_);
  substeps_ = split_substeps(set_.ordering);
  // The reaction pass prefetches the rows it reads from memory (core/prefetch.hpp): the same
  // cells, faster (at 1024^2 on 2 ranks the rk4 pass measured about 15 % less time).
  prefetch_ = 8.0 * static_cast<double>(species.size() * grid.owned().size()) >= kPrefetchMinBytes;
  global_ = grid.create_global();
}

// The arrays and inputs of one reaction substep from t0 over dt (react_open .. react_close).
struct SplitIntegrator::ReactionPass {
  double t0 = 0, dt = 0;
  PetscInt step = 0;
  std::vector<PetscScalar*> a;
  std::vector<const PetscScalar*> pf;
  std::vector<const double*> S0, S1, in, prow, s0, s1;
  std::vector<double*> out;
  std::vector<double> zeros; // stands in for species without a source when others have one
  bool any_source = false;
  std::string err;
  int worst_its = 0;
};

void SplitIntegrator::react_open(ReactionPass& r, std::vector<VecH>& u, double t0, double dt,
                                 PetscInt step) {
  if (params_.any_field()) // scalars may have changed (parameters using t)
    params_.expand_scalars(static_cast<size_t>(grid_.owned().m[0]), const_rows_);
  const size_t ns = species_.size(), np = params_.scalar.size();
  r.t0 = t0;
  r.dt = dt;
  r.step = step;
  r.a.assign(ns, nullptr);
  for (size_t s = 0; s < ns; ++s)
    MG_PETSC(VecGetArray(u[s], &r.a[s]));
  r.pf.assign(np, nullptr);
  for (size_t q = 0; q < np; ++q)
    if (params_.field[q].get()) MG_PETSC(VecGetArrayRead(params_.field[q], &r.pf[q]));
  r.S0.assign(ns, nullptr);
  r.S1.assign(ns, nullptr);
  if (sources_ && sources_->any())
    for (size_t s = 0; s < ns; ++s) {
      r.S0[s] = sources_->at(static_cast<int>(s), t0, 0);
      r.S1[s] = sources_->at(static_cast<int>(s), t0 + dt, 1);
      r.any_source |= r.S0[s] != nullptr;
    }
  r.zeros.assign(r.any_source ? static_cast<size_t>(grid_.owned().m[0]) : 0, 0.0);
  r.in.resize(ns);
  r.out.resize(ns);
  r.s0.resize(ns);
  r.s1.resize(ns);
  r.prow.resize(np);
}

// Owned row (j, k) in place (reaction rows read a cell before writing it); a failure is kept in
// r.err (and the rows after it are skipped).
void SplitIntegrator::react_row(ReactionPass& r, PetscInt j, PetscInt k) {
  if (!r.err.empty()) return;
  const Box& ob = grid_.owned();
  const size_t ns = species_.size();
  const PetscInt c = grid_.local_index(ob.s[0], j, k);
  const PetscInt o = grid_.owned_index(ob.s[0], j, k);
  for (size_t s = 0; s < ns; ++s) {
    r.in[s] = r.a[s] + c;
    r.out[s] = r.a[s] + c;
    r.s0[s] = r.S0[s] ? r.S0[s] + o : r.zeros.data();
    r.s1[s] = r.S1[s] ? r.S1[s] + o : r.zeros.data();
  }
  for (size_t q = 0; q < r.prow.size(); ++q)
    r.prow[q] = r.pf[q] ? r.pf[q] + o : const_rows_.empty() ? nullptr : const_rows_[q].data();
  const PetscInt ahead = c + kPrefetchRowsAhead * grid_.ghosted().m[0];
  if (prefetch_ && ahead + ob.m[0] <= grid_.ghosted().size())
    for (size_t s = 0; s < ns; ++s)
      prefetch_doubles(r.a[s] + ahead, ob.m[0]);
  CellSolve worst{};
  const int bad = fn_(set_.reaction, static_cast<int>(ob.m[0]), r.in.data(), r.prow.data(),
                      params_.scalar.data(), r.any_source ? r.s0.data() : nullptr,
                      r.any_source ? r.s1.data() : nullptr, r.dt, set_.newton_tol,
                      set_.newton_max_it, floor_.data(), r.out.data(), &worst);
  if (bad >= 0) {
    std::ostringstream m;
    m.precision(17);
    m << "reaction solve failed at cell (" << ob.s[0] + bad << "," << j << "," << k << ") at step "
      << r.step << " (t = " << r.t0 << "): values";
    for (size_t s = 0; s < ns; ++s)
      m << " " << species_[s] << " = " << r.in[s][bad];
    m << ", residual " << worst.residual << " after " << worst.iterations
      << " Newton iterations; reduce -dt or raise -split_newton_max_it";
    r.err = m.str();
    return;
  }
  r.worst_its = std::max(r.worst_its, worst.iterations);
}

// The arrays back; a failure on any rank is thrown on every rank.
void SplitIntegrator::react_close(ReactionPass& r, std::vector<VecH>& u) {
  for (size_t q = 0; q < r.pf.size(); ++q)
    if (r.pf[q]) MG_PETSC(VecRestoreArrayRead(params_.field[q], &r.pf[q]));
  for (size_t s = 0; s < species_.size(); ++s)
    MG_PETSC(VecRestoreArray(u[s], &r.a[s]));
  last_its_ = r.worst_its;
  throw_if_any(grid_.comm(), r.err);
}

void SplitIntegrator::react(std::vector<VecH>& u, double t0, double dt, PetscInt step) {
  ReactionPass r;
  react_open(r, u, t0, dt, step);
  react_rows(r);
  react_close(r, u);
}

// Every owned row of the pass.
void SplitIntegrator::react_rows(ReactionPass& r) {
  LogScope log_scope(log_events().reaction);
  const Box& ob = grid_.owned();
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      react_row(r, j, k);
}

// react (from t0 over dt_react, of step react_step), then diffuse (over dt_diffuse, of step
// diffuse_step); where every species' diffusion is a tridiagonal solve in place (and no
// constraint acts between the two), in one pass: each plane of the slowest axis reacts just
// before the solves' transforms read it (DiffusionSolver::solve_local_planes_begin), while it is
// in cache. The same arithmetic either way.
void SplitIntegrator::react_diffuse(std::vector<VecH>& u, double t0, double dt_react,
                                    PetscInt react_step, double dt_diffuse, PetscInt diffuse_step) {
  const bool constrained = terms_ && !terms_->constraints().empty();
  if (constrained || !set_.fuse_planes) {
    react(u, t0, dt_react, react_step);
    if (terms_) terms_->constrain(u);
    diffuse(u, dt_diffuse, diffuse_step);
    return;
  }
  ReactionPass r;
  react_open(r, u, t0, dt_react, react_step);
  const Box& ob = grid_.owned();
  auto plane = [&](PetscInt g) {
    LogScope log_scope(log_events().reaction);
    if (grid_.dim() == 3)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
        react_row(r, j, g);
    else
      react_row(r, g, ob.s[2]);
  };
  if (!diffusion_.solve_local_planes_begin(u, dt_diffuse, set_.theta, plane)) {
    react_rows(r);
    react_close(r, u);
    diffuse(u, dt_diffuse, diffuse_step);
    return;
  }
  for (size_t s = 0; s < u.size(); ++s)
    diffusion_.solve_local_end(static_cast<int>(s), u[s]);
  react_close(r, u);
  ++planes_fused_;
}

void SplitIntegrator::diffuse(std::vector<VecH>& u, double dt, PetscInt step) {
  // In place where the exact solve reads and writes the ghosted local state itself; otherwise
  // owned cells move between it and the solver's global vector row by row (the solve needs no
  // ghosts; DMLocalToGlobal does not support every periodic layout).
  // Local solves run in two halves: each species' wait for the other ranks comes after the
  // next species' solve has started (finished before any other solve and at the end).
  const Box& ob = grid_.owned();
  std::vector<size_t> pending;
  auto finish = [&] {
    for (size_t p : pending)
      diffusion_.solve_local_end(static_cast<int>(p), u[p]);
    pending.clear();
  };
  for (size_t s = 0; s < u.size(); ++s) {
    if (diffusion_.solve_local_begin(static_cast<int>(s), u[s], dt, set_.theta)) {
      pending.push_back(s);
      continue;
    }
    finish();
    for (int dir = 0; dir < 2; ++dir) {
      PetscScalar *l, *g;
      MG_PETSC(VecGetArray(u[s], &l));
      MG_PETSC(VecGetArray(global_, &g));
      for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
        for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j) {
          double* lr = l + grid_.local_index(ob.s[0], j, k);
          double* gr = g + grid_.owned_index(ob.s[0], j, k);
          if (dir == 0)
            std::copy(lr, lr + ob.m[0], gr);
          else
            std::copy(gr, gr + ob.m[0], lr);
        }
      MG_PETSC(VecRestoreArray(global_, &g));
      MG_PETSC(VecRestoreArray(u[s], &l));
      if (dir == 0) diffusion_.solve(static_cast<int>(s), global_, dt, set_.theta, step);
    }
  }
  finish();
}

std::vector<Substep> split_substeps(SplitOrdering ordering) {
  using K = Substep::Kind;
  if (ordering == SplitOrdering::Lie) return {{K::Reaction, 1.0}, {K::Diffusion, 1.0}};
  return {{K::Reaction, 0.5}, {K::Diffusion, 1.0}, {K::Reaction, 0.5}};
}

void SplitIntegrator::step(std::vector<VecH>& u, double t, double dt, PetscInt step) {
  if (terms_) { // solution-dependent diffusion: coefficients of u^n, lagged over the step
    for (int s : terms_->refresh(u))
      diffusion_.operator_changed(s);
    // Coefficients and Dirichlet values using t: at the midpoint of the diffusion substep, which
    // spans the whole step in both orderings (second order with Crank-Nicolson).
    std::vector<int> changed;
    terms_->set_time(t + 0.5 * dt, &changed);
    for (int s : changed)
      diffusion_.operator_changed(s);
  }
  double t_reaction = t; // the reaction's (and sources') clock advances with its substeps
  for (size_t i = 0; i < substeps_.size(); ++i) {
    const Substep& sub = substeps_[i];
    const bool then_diffuse =
        i + 1 < substeps_.size() && substeps_[i + 1].kind == Substep::Kind::Diffusion;
    if (sub.kind == Substep::Kind::Reaction && then_diffuse) {
      react_diffuse(u, t_reaction, sub.fraction * dt, step, substeps_[i + 1].fraction * dt, step);
      t_reaction += sub.fraction * dt;
      ++i;
    } else if (sub.kind == Substep::Kind::Reaction) {
      react(u, t_reaction, sub.fraction * dt, step);
      t_reaction += sub.fraction * dt;
      if (terms_) terms_->constrain(u);
    } else {
      diffuse(u, sub.fraction * dt, step);
    }
  }
  constrain(u);
}

void SplitIntegrator::constrain(std::vector<VecH>& u) const {
  if (terms_)
    terms_->constrain(u);
  else
    apply_floor(grid_, u, floor_);
}

std::string SplitIntegrator::fuse_unsupported() const {
  if (set_.ordering != SplitOrdering::Strang) return "Strang ordering";
  if (terms_ && (terms_->any_state_dependent() || terms_->any_time_dependent()))
    return "diffusion coefficients and boundary values constant in time and state";
  return {};
}

void SplitIntegrator::steps(std::vector<VecH>& u, double t, double dt, PetscInt first, int n) {
  if (n <= 1 || !fuse_unsupported().empty()) {
    for (int i = 0; i < n; ++i)
      step(u, t + i * dt, dt, first + i);
    return;
  }
  react_diffuse(u, t, 0.5 * dt, first, dt, first);
  // The merged substep spans the second half of step i and the first half of step i + 1.
  for (int i = 0; i + 1 < n; ++i)
    react_diffuse(u, t + (i + 0.5) * dt, dt, first + i, dt, first + i + 1);
  react(u, t + (n - 0.5) * dt, 0.5 * dt, first + n - 1);
  if (terms_) terms_->constrain(u);
  constrain(u);
}

} // namespace morphogen
