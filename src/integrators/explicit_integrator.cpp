#include "integrators/explicit_integrator.hpp"

#include "core/log_events.hpp"
#include "core/prefetch.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <limits>
#include <utility>

namespace morphogen {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
} // namespace

ExplicitIntegrator::ExplicitIntegrator(const Grid& grid, const Halo& halo, RowFn row_fn,
                                       int nspecies, const Stencil& stencil, std::vector<double> D,
                                       std::vector<double> floor, const ParamSet& params,
                                       const std::vector<FaceValues>* dirichlet)
    : grid_(grid), halo_(halo), row_fn_(row_fn), ns_(nspecies), stencil_(stencil), D_(std::move(D)),
      floor_(std::move(floor)), params_(params), dirichlet_(dirichlet) {
  to_rows(stencil_, rows_);
  // 9pt, 19pt, 27pt: weight classes, rows in class order (the form of the fused passes too, so
  // that one step per pass and k give the same bits).
  by_class_ = box_classes(rows_, classes_);
  ring_depth_ = static_cast<int>(reach(1) * block_rows()) + reach(0) + 1;
  ring_n_ = static_cast<size_t>(grid.owned().m[0]);
  if (params_.any_field())
    params_.expand_scalars(static_cast<size_t>(grid.owned().m[0]), const_rows_);
  const GridSpec& g = grid.spec();
  x_fill_ = !rows_.box && g.bc[0] == Boundary::Periodic && g.stencil_width == 1 &&
            grid.ownership_ranges()[0].size() == 1;
}

double ExplicitIntegrator::stable_dt(const Stencil& stencil, const std::vector<double>& D) {
  double dmax = 0;
  for (double d : D)
    dmax = std::max(dmax, d);
  const double rho = stencil.spectral_radius();
  return dmax > 0 && rho > 0 ? 2.0 / (dmax * rho) : std::numeric_limits<double>::infinity();
}

void ExplicitIntegrator::use_operators(std::vector<const DiffusionOperator*> ops, PreFn pre_fn) {
  ops_ = std::move(ops);
  pre_fn_ = std::move(pre_fn);
  div_.assign(static_cast<size_t>(ns_), std::vector<double>(grid_.owned().m[0]));
}

void ExplicitIntegrator::update_ghosts(std::vector<VecH>& u) const {
  exchange(u, halo_);
}

void ExplicitIntegrator::exchange(std::vector<VecH>& u, const Halo& halo) const {
  LogScope log_scope(log_events().halo);
  std::vector<PetscScalar*>& a = tab_.in;
  a.assign(static_cast<size_t>(ns_), nullptr);
  for (int s = 0; s < ns_; ++s)
    MG_PETSC(VecGetArray(u[s], &a[s]));
  for (int s = 0; s < ns_; ++s)
    halo.begin(a[s]);
  for (int s = 0; s < ns_; ++s) {
    halo.end(a[s]);
    halo.fill_boundaries(a[s], dirichlet_ ? &(*dirichlet_)[s] : nullptr);
  }
  for (int s = 0; s < ns_; ++s)
    MG_PETSC(VecRestoreArray(u[s], &a[s]));
}

void ExplicitIntegrator::step_general(std::vector<VecH>& u, std::vector<VecH>& work,
                                      double dt) const {
  LogScope log_scope(log_events().sweep);
  const int np = static_cast<int>(params_.scalar.size());
  SweepTables& tb = tab_; // reused between steps (no allocation per step)
  auto& in = tb.cin;
  auto& pf = tb.pf;
  auto& out = tb.out;
  tb.reset(static_cast<size_t>(ns_), static_cast<size_t>(np), 1);
  for (int s = 0; s < ns_; ++s) {
    MG_PETSC(VecGetArrayRead(u[s], &in[s]));
    MG_PETSC(VecGetArray(work[s], &out[s]));
  }
  for (int q = 0; q < np; ++q)
    if (params_.field[q].get()) MG_PETSC(VecGetArrayRead(params_.field[q], &pf[q]));
  const Box& ob = grid_.owned();
  auto& src = tb.src;
  auto& div = tb.div;
  auto& prow = tb.prow;
  auto& dst = tb.dst;
  for (int s = 0; s < ns_; ++s)
    div[s] = div_[s].data();
  ExplicitRow row;
  row.n = static_cast<int>(ob.m[0]);
  row.src = src.data();
  row.div = div.data();
  row.floor = floor_.data();
  row.prow = prow.data();
  row.pconst = params_.scalar.data();
  row.dt = dt;
  row.dst = dst.data();
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j) {
      const PetscInt c = grid_.local_index(ob.s[0], j, k);
      for (int s = 0; s < ns_; ++s) {
        ops_[s]->apply_row(in[s], c, row.n, div_[s].data());
        src[s] = in[s] + c;
        dst[s] = out[s] + c;
      }
      if (params_.any_field()) {
        const PetscInt o = grid_.owned_index(ob.s[0], j, k);
        for (int q = 0; q < np; ++q)
          prow[q] = pf[q] ? pf[q] + o : const_rows_[q].data();
      }
      pre_fn_(row);
    }
  for (int q = 0; q < np; ++q)
    if (pf[q]) MG_PETSC(VecRestoreArrayRead(params_.field[q], &pf[q]));
  for (int s = 0; s < ns_; ++s) {
    MG_PETSC(VecRestoreArrayRead(u[s], &in[s]));
    MG_PETSC(VecRestoreArray(work[s], &out[s]));
  }
  std::swap(u, work);
}

void ExplicitIntegrator::use_terms(const TermList& terms) {
  terms_ = &terms;
  others_.clear();
  for (const auto& t : terms.terms())
    if (t->kind() != Term::Kind::Diffusion && t->kind() != Term::Kind::Reaction)
      others_.push_back(t.get());
  constrain_after_sweep_ = false; // the fused kernels apply the clamp floor themselves
  for (const auto& c : terms.constraints())
    constrain_after_sweep_ = constrain_after_sweep_ || !dynamic_cast<const ClampFloor*>(c.get());
  rates_.clear(); // (no prototype row of a field's size where no other term needs one)
  if (!others_.empty())
    rates_.assign(static_cast<size_t>(ns_),
                  std::vector<double>(static_cast<size_t>(grid_.owned().size())));
}

void ExplicitIntegrator::step(std::vector<VecH>& u, double t, double dt, PetscInt /*step*/) {
  if (work_.empty() && !in_place())
    for (int s = 0; s < ns_; ++s)
      work_.push_back(grid_.create_local());
  // Coefficients and Dirichlet values using t: at the step's start (before the ghosts take the
  // boundary values).
  if (terms_) terms_->set_time(t);
  if (fills_x() && !x_halo_) x_halo_ = std::make_unique<Halo>(grid_, false); // collective
  exchange(u, fills_x() ? *x_halo_ : halo_);
  if (terms_) terms_->refresh(u); // solution-dependent diffusion: coefficients of u^n
  if (others_.empty()) {
    sweep(u, in_place() ? nullptr : &work_, dt);
    if (constrain_after_sweep_) terms_->constrain(u);
    return;
  }
  // Rates of the other terms on u^n (ghosts current), added after the sweep.
  StateArrays state;
  RateArrays rates;
  std::vector<const PetscScalar*> in(ns_);
  for (int s = 0; s < ns_; ++s) {
    MG_PETSC(VecGetArrayRead(u[s], &in[s]));
    state.u.push_back(in[s]);
    std::fill(rates_[s].begin(), rates_[s].end(), 0.0);
    rates.r.push_back(rates_[s].data());
  }
  std::exception_ptr error;
  try {
    for (const Term* term : others_)
      term->add_rates(state, t, rates);
  } catch (...) {
    error = std::current_exception();
  }
  for (int s = 0; s < ns_; ++s)
    MG_PETSC(VecRestoreArrayRead(u[s], &in[s]));
  if (error) std::rethrow_exception(error);
  sweep(u, in_place() ? nullptr : &work_, dt);
  add_other_terms(u, t, dt);
}

// u += dt r on the owned cells, then the constraints.
void ExplicitIntegrator::add_other_terms(std::vector<VecH>& u, double /*t*/, double dt) {
  const Box& ob = grid_.owned();
  for (int s = 0; s < ns_; ++s) {
    PetscScalar* a;
    MG_PETSC(VecGetArray(u[s], &a));
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j) {
        double* row = a + grid_.local_index(ob.s[0], j, k);
        const double* r = rates_[s].data() + grid_.owned_index(ob.s[0], j, k);
        for (PetscInt i = 0; i < ob.m[0]; ++i)
          row[i] += dt * r[i];
      }
    MG_PETSC(VecRestoreArray(u[s], &a));
  }
  if (terms_) terms_->constrain(u);
}

std::string ExplicitIntegrator::fuse_unsupported() const {
  const GridSpec& g = grid_.spec();
  if (grid_.dim() != 2) return "a 2-D grid";
  if (g.bc[0] != Boundary::Periodic || g.bc[1] != Boundary::Periodic)
    return "periodic boundaries on both axes";
  if (!ops_.empty() || !row_fn_) return "constant isotropic diffusion and a fused model kernel";
  if (!others_.empty() || constrain_after_sweep_)
    return "no terms or constraints besides the clamp floor";
  return "";
}

int ExplicitIntegrator::auto_fuse_steps() const {
  if (!fuse_unsupported().empty()) return 1;
  int ranks = 1;
  MPI_Comm_size(grid_.comm(), &ranks);
  const double bytes = 8.0 * ns_ * static_cast<double>(grid_.global_cells()) / ranks;
  return bytes >= kAutoFuseBytes ? kAutoFuseSteps : 1;
}

void ExplicitIntegrator::steps(std::vector<VecH>& u, double t, double dt, int n) {
  if (n <= 1) {
    step(u, t, dt, 0);
    return;
  }
  const bool in_place = this->in_place(); // the pass writes the state it reads (no second set)
  if (work_.empty() && !in_place)
    for (int s = 0; s < ns_; ++s)
      work_.push_back(grid_.create_local());
  if (!fused_) {
    fused_ = std::make_unique<FusedSweep>(grid_, rows_, ns_, fuse_steps(), fuse_tile_);
    if (params_.any_field()) fused_->set_params(params_); // fixed in time (no fusion otherwise)
  }
  if (terms_) terms_->set_time(t);
  std::vector<const PetscScalar*> in(ns_);
  std::vector<PetscScalar*> out(ns_);
  for (int s = 0; s < ns_; ++s) {
    MG_PETSC(VecGetArray(in_place ? u[s] : work_[s], &out[s]));
    if (in_place)
      in[s] = out[s];
    else
      MG_PETSC(VecGetArrayRead(u[s], &in[s]));
  }
  ExplicitRow row;
  row.w = rows_.w.data();
  row.D = D_.data();
  row.floor = floor_.data();
  row.pconst = params_.scalar.data();
  row.dt = dt;
  const auto t0 = fused_choice_.timing() ? Clock::now() : Clock::time_point{};
  fused_->run(in, out, n, row, fused_choice_.next());
  fused_choice_.record(fused_choice_.timing() ? seconds_since(t0) / n : 0.0);
  for (int s = 0; s < ns_; ++s) {
    MG_PETSC(VecRestoreArray(in_place ? u[s] : work_[s], &out[s]));
    if (!in_place) MG_PETSC(VecRestoreArrayRead(u[s], &in[s]));
  }
  if (!in_place) std::swap(u, work_);
}

void ExplicitIntegrator::step(std::vector<VecH>& u, std::vector<VecH>& work, double dt) const {
  update_ghosts(u);
  sweep(u, &work, dt);
}

std::string ExplicitIntegrator::vector_width() const {
  const std::string a = sweep_choice_.describe(), b = fused_choice_.describe();
  if (fused_choice_.runs() == 0) return a;
  if (sweep_choice_.runs() == 0) return "fused passes " + b;
  return "single steps " + a + ", fused passes " + b;
}

bool ExplicitIntegrator::in_place() const {
  if (!ops_.empty() || in_place_ == InPlace::Never) return false;
  const double bytes = 8.0 * ns_ * static_cast<double>(grid_.owned().size());
  return in_place_ == InPlace::Always ||
         bytes >= (grid_.dim() == 3 ? kInPlaceBytes3d : kInPlaceBytes);
}

bool ExplicitIntegrator::prefetch() const {
  if (prefetch_ != Prefetch::Auto) return prefetch_ == Prefetch::Always;
  return 8.0 * ns_ * static_cast<double>(grid_.owned().size()) >= kPrefetchBytes;
}

PetscInt ExplicitIntegrator::prefetch_offset(const std::vector<PetscInt>& delta) const {
  if (!prefetch() || delta.empty()) return -1;
  return *std::max_element(delta.begin(), delta.end()) + kPrefetchRows * grid_.ghosted().m[0];
}

void ExplicitIntegrator::wrap_x(const std::vector<PetscScalar*>& u, PetscInt c, int rows,
                                PetscInt gx) const {
  const PetscInt n = grid_.owned().m[0];
  for (int s = 0; s < ns_; ++s)
    for (int r = 0; r < rows; ++r) {
      double* p = u[s] + c + r * gx;
      p[-1] = p[n - 1];
      p[n] = p[0];
    }
}

// In-place sweeps (header comment): the old row t is last read by row t + R_z bh + R_y.
int ExplicitIntegrator::reach(int axis) const {
  int r = 0;
  for (int q = 0; q < rows_.nrows; ++q)
    r = std::max(r, std::abs(rows_.off[q][axis]));
  return r;
}

// In 3-D the box is swept in blocks of y rows so that the three z planes a row reads stay in the
// per-core L2 cache (about 256 KiB of state per block); in 2-D (and for stencils reaching more
// than one row in y, which the in-place edge rows do not cover) one block is the box.
PetscInt ExplicitIntegrator::block_rows() const {
  const Box& ob = grid_.owned();
  if (grid_.dim() != 3 || reach(0) > 1) return ob.m[1];
  const PetscInt bytes_per_row =
      3 * ns_ * grid_.ghosted().m[0] * static_cast<PetscInt>(sizeof(double));
  return std::min(ob.m[1], std::max<PetscInt>(4, (256 * 1024) / bytes_per_row - 2));
}

// Copies the new row t of the block of rows jb .. jb + bh - 1 from the ring into u. Before the
// block's last row is overwritten, its old values go to edge_[1] (ghosted row, plane k), where
// the next block reads its row jb - 1.
void ExplicitIntegrator::commit_row(const std::vector<PetscScalar*>& u, PetscInt t, PetscInt jb,
                                    PetscInt bh, bool save_edge) const {
  const Box &ob = grid_.owned(), &gb = grid_.ghosted();
  const PetscInt k = ob.s[2] + t / bh, j = jb + t % bh;
  for (int s = 0; s < ns_; ++s) {
    if (save_edge && j == jb + bh - 1)
      std::copy_n(u[s] + grid_.local_index(gb.s[0], j, k), gb.m[0], edge_row(1, s, k));
    std::copy_n(ring_row(s, t), ob.m[0], u[s] + grid_.local_index(ob.s[0], j, k));
  }
}

// The old rows jend - 1 of the ghost planes (never overwritten) into edge_[1].
void ExplicitIntegrator::save_ghost_plane_edges(const std::vector<PetscScalar*>& u,
                                                PetscInt jend) const {
  const Box &ob = grid_.owned(), &gb = grid_.ghosted();
  for (PetscInt k = gb.s[2]; k < gb.s[2] + gb.m[2]; ++k)
    if (k < ob.s[2] || k >= ob.s[2] + ob.m[2])
      for (int s = 0; s < ns_; ++s)
        std::copy_n(u[s] + grid_.local_index(gb.s[0], jend - 1, k), gb.m[0], edge_row(1, s, k));
}

void ExplicitIntegrator::sweep(std::vector<VecH>& u, std::vector<VecH>* work, double dt) const {
  if (params_.any_field()) // scalars may have changed (parameters using t)
    params_.expand_scalars(static_cast<size_t>(grid_.owned().m[0]), const_rows_);
  if (!ops_.empty()) {
    step_general(u, *work, dt);
    return;
  }
  LogScope log_scope(log_events().sweep);
  const auto t0 = sweep_choice_.timing() ? Clock::now() : Clock::time_point{};
  const RowFn row_fn = sweep_choice_.next();
  const int nr = rows_.nrows;
  const int np = static_cast<int>(params_.scalar.size());
  const bool field_mode = params_.any_field();
  const bool in_place = work == nullptr; // in_place()
  const bool fill_x = fills_x();
  if (in_place) ring_.resize(static_cast<size_t>(ns_) * ring_depth_ * ring_n_);
  SweepTables& tb = tab_;
  auto& in = tb.in;
  auto& out = tb.out;
  auto& pf = tb.pf;
  tb.reset(static_cast<size_t>(ns_), static_cast<size_t>(np), static_cast<size_t>(nr));
  for (int s = 0; s < ns_; ++s) {
    MG_PETSC(VecGetArray(u[s], &in[s]));
    if (!in_place) MG_PETSC(VecGetArray((*work)[s], &out[s]));
  }
  for (int q = 0; q < np; ++q)
    if (params_.field[q].get()) MG_PETSC(VecGetArrayRead(params_.field[q], &pf[q]));

  const Box& ob = grid_.owned();
  const PetscInt gx = grid_.ghosted().m[0], gxy = gx * grid_.ghosted().m[1];
  auto& delta = tb.delta;
  auto& dy = tb.dy;
  auto& dz = tb.dz;
  delta.resize(static_cast<size_t>(nr));
  dy.resize(static_cast<size_t>(nr));
  dz.resize(static_cast<size_t>(nr));
  for (int r = 0; r < nr; ++r) {
    const int q = by_class_ ? classes_.perm[r] : r;
    dy[r] = rows_.off[q][0];
    dz[r] = rows_.off[q][1];
    delta[r] = gx * dy[r] + gxy * dz[r];
  }
  auto& src = tb.src;
  auto& dst = tb.dst;
  auto& prow = tb.prow;
  ExplicitRow row;
  row.n = static_cast<int>(ob.m[0]);
  row.src = src.data();
  row.w = rows_.w.data();
  row.D = D_.data();
  row.floor = floor_.data();
  row.prow = prow.data();
  row.pconst = params_.scalar.data();
  row.dt = dt;
  row.dst = dst.data();
  row.wclass = by_class_ ? classes_.w.data() : nullptr;
  const PetscInt jblock = block_rows(), jlast = ob.s[1] + ob.m[1];
  const int ry = reach(0), rz = reach(1);
  if (in_place && jblock < ob.m[1])
    for (auto& e : edge_)
      e.resize(static_cast<size_t>(ns_ * grid_.ghosted().m[2] * gx));
  // With scalar parameters into a second state set (no ring), one call sweeps all rows of a
  // block (the kernel steps the row pointers by the ghosted row length): small grids spend less
  // on per-call setup. Same arithmetic per cell either way.
  const PetscInt pf_off = prefetch_offset(delta), pf_end = grid_.ghosted().size() - ob.m[0];
  const bool multi = !in_place && !field_mode && pf_off < 0;
  row.src_stride = row.dst_stride = gx;
  for (PetscInt jb = ob.s[1]; jb < jlast; jb += jblock) {
    const PetscInt jend = std::min(jb + jblock, jlast), bh = jend - jb, lag = rz * bh + ry;
    const bool from_edge = in_place && jb > ob.s[1], to_edge = in_place && jend < jlast;
    if (to_edge) save_ghost_plane_edges(in, jend);
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
      for (PetscInt j = jb; j < jend; j += row.rows) {
        row.rows = multi ? static_cast<int>(jend - j) : 1;
        const PetscInt c = grid_.local_index(ob.s[0], j, k);
        const PetscInt t = (k - ob.s[2]) * bh + (j - jb); // order within the block
        for (int s = 0; s < ns_; ++s) {
          for (int r = 0; r < nr; ++r)
            src[s * nr + r] = from_edge && j == jb && dy[r] < 0
                                  ? edge_row(0, s, k + dz[r]) + (ob.s[0] - grid_.ghosted().s[0])
                                  : in[s] + c + delta[r];
          dst[s] = in_place ? ring_row(s, t) : out[s] + c;
        }
        if (field_mode) {
          const PetscInt o = grid_.owned_index(ob.s[0], j, k);
          for (int q = 0; q < np; ++q)
            prow[q] = pf[q] ? pf[q] + o : const_rows_[q].data();
        }
        if (fill_x) wrap_x(in, c, row.rows, gx);
        // The row read first kPrefetchRows rows later in the block's order (in 3-D, near the
        // block's last row, a row of the next plane's block rows).
        const PetscInt ahead =
            pf_off < 0 || j + kPrefetchRows < jend ? pf_off : pf_off - bh * gx + gxy;
        row.prefetch_ahead = ahead >= 0 && c + ahead <= pf_end ? ahead : 0;
        if (!by_class_ && row.prefetch_ahead != 0) { // the tap loop: the whole row, before it
          for (int s = 0; s < ns_; ++s)
            prefetch_doubles(in[s] + c + row.prefetch_ahead, ob.m[0]);
          row.prefetch_ahead = 0;
        }
        row_fn(row);
        if (in_place && t >= lag) commit_row(in, t - lag, jb, bh, to_edge);
      }
    if (!in_place) continue;
    const PetscInt tend = bh * ob.m[2];
    for (PetscInt t = std::max<PetscInt>(0, tend - lag); t < tend; ++t)
      commit_row(in, t, jb, bh, to_edge);
    std::swap(edge_[0], edge_[1]);
  }

  for (int q = 0; q < np; ++q)
    if (pf[q]) MG_PETSC(VecRestoreArrayRead(params_.field[q], &pf[q]));
  for (int s = 0; s < ns_; ++s) {
    MG_PETSC(VecRestoreArray(u[s], &in[s]));
    if (!in_place) MG_PETSC(VecRestoreArray((*work)[s], &out[s]));
  }
  if (!in_place) std::swap(u, *work);
  sweep_choice_.record(sweep_choice_.timing() ? seconds_since(t0) : 0.0);
}

} // namespace morphogen
