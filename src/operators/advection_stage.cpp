#include "operators/advection_stage.hpp"

#include "core/user_error.hpp"

#include <algorithm>
#include <cmath>

namespace morphogen {

namespace {

const char* kAxis[3] = {"x", "y", "z"};

// Largest Courant number max|u_d| dt / h_d over the axes, and its axis.
double courant_of(const Grid& grid, const std::array<double, 3>& umax, double dt, int& axis) {
  double c = 0;
  axis = 0;
  for (int d = 0; d < grid.dim(); ++d) {
    const double cd = umax[d] * (dt / grid.spec().h(d));
    if (cd > c) c = cd, axis = d;
  }
  return c;
}

} // namespace

AdvectionStage::AdvectionStage(const Grid& grid, std::unique_ptr<VelocityField> velocity,
                               AdvectionSettings settings, double dt)
    : grid_(grid), velocity_(std::move(velocity)), set_(std::move(settings)) {
  setup(velocity_->max_abs(0.5 * dt), dt);
  load_velocity(0.5 * dt);
  checked_dt_ = dt;
}

AdvectionStage::AdvectionStage(const Grid& grid, std::unique_ptr<VelocityFile> file,
                               AdvectionSettings settings, double dt)
    : grid_(grid), file_(std::move(file)), set_(std::move(settings)) {
  setup(file_->max_abs(), dt);
  load_velocity(0.5 * dt);
  checked_dt_ = dt;
}

AdvectionStage::AdvectionStage(const Grid& grid, const VelocitySource& source,
                               AdvectionSettings settings, double dt)
    : grid_(grid), source_(&source), set_(std::move(settings)) {
  const double b = source.speed_bound();
  setup({b, b, b}, dt);
  load_velocity(0.0);
}

// The wide halo from the largest speed per axis umax (or -advection_halo), and the geometry.
void AdvectionStage::setup(const std::array<double, 3>& umax, double dt) {
  const Grid& grid = grid_;
  int axis = 0;
  courant_ = courant_of(grid, umax, dt, axis);
  const long long need = advect::advection_reach(courant_, set_.interp);
  const std::string cn = "Courant number max|u_" + std::string(kAxis[axis]) + "| dt/h" +
                         kAxis[axis] + " = " + format_number(courant_);
  const std::string interp = set_.interp == advect::Interp::Cubic ? "cubic" : "linear";
  if (set_.halo > 0 && need > set_.halo)
    throw UserError(
        "-advection_halo " + std::to_string(set_.halo) + ": the back-trace of -dt " +
        format_number(dt) + " reaches " + std::to_string(need) + " cells (" + cn + ", " + interp +
        " interpolation); use -advection_halo >= " + std::to_string(need) + " or a smaller -dt");
  if (need > AdvectionSettings::kMaxHalo)
    throw UserError("-dt " + format_number(dt) + ": the advection back-trace reaches " +
                    std::to_string(need) + " cells (" + cn + ", " + interp +
                    " interpolation), more than the widest advection halo (" +
                    std::to_string(AdvectionSettings::kMaxHalo) + " cells); use a smaller -dt");
  wide_ = std::make_unique<WideHalo>(grid, set_.halo > 0 ? set_.halo : static_cast<int>(need));
  const GridSpec& g = grid.spec();
  geom_.dim = grid.dim();
  for (int d = 0; d < 3; ++d) {
    geom_.n[d] = g.n[d];
    geom_.periodic[d] = d >= grid.dim() || g.bc[d] == Boundary::Periodic;
    geom_.s[d] = wide_->box().s[d];
    geom_.m[d] = wide_->box().m[d];
  }
  w_.resize(static_cast<size_t>(wide_->size()));
}

void AdvectionStage::load_velocity(double t) {
  for (int d = 0; d < grid_.dim(); ++d) {
    u_[d].resize(static_cast<size_t>(wide_->size()));
    if (source_) {
      const PetscScalar* a;
      MG_PETSC(VecGetArrayRead(source_->component(d), &a));
      wide_->fill(a, u_[d].data());
      MG_PETSC(VecRestoreArrayRead(source_->component(d), &a));
    } else if (file_) {
      owned_.resize(static_cast<size_t>(grid_.owned().size()));
      file_->owned(d, t, owned_.data());
      spread_owned(owned_, u_[d].data());
    } else {
      velocity_->evaluate(d, wide_->box(), t, u_[d].data());
    }
  }
  for (int d = grid_.dim(); d < 3; ++d)
    u_[d].assign(static_cast<size_t>(wide_->size()), 0.0);
  dep_dt_ = -1.0;
}

// Owned values (owned layout) onto the wide box, through a ghosted-layout buffer.
void AdvectionStage::spread_owned(const std::vector<double>& owned, double* wide) {
  const Box& ob = grid_.owned();
  local_.assign(static_cast<size_t>(grid_.ghosted().size()), 0.0);
  const double* o = owned.data();
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j, o += ob.m[0])
      std::copy(o, o + ob.m[0], local_.begin() + grid_.local_index(ob.s[0], j, k));
  wide_->fill(local_.data(), wide);
}

// The velocity on the wide box (evaluated at t) with step dt: its back-trace must fit the halo.
void AdvectionStage::check_reach(double dt, double t) {
  std::array<double, 3> umax{0, 0, 0};
  const Box& ob = grid_.owned();
  for (int d = 0; d < grid_.dim(); ++d)
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
        for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
          umax[d] = std::max(umax[d], std::fabs(u_[d][wide_->index(i, j, k)]));
  MPI_Allreduce(MPI_IN_PLACE, umax.data(), 3, MPI_DOUBLE, MPI_MAX, grid_.comm());
  int axis = 0;
  courant_ = courant_of(grid_, umax, dt, axis);
  const long long need = advect::advection_reach(courant_, set_.interp);
  checked_dt_ = dt;
  if (need <= wide_->width()) return;
  const std::string what =
      source_ ? source_->option_text() + ": the fluid velocity"
      : file_ ? file_->option_text() + ": the velocity"
              : "-velocity_" + std::string(kAxis[axis]) + " " + velocity_->text(axis);
  throw UserError(what + ": at t = " + format_number(t) + " the advection back-trace of -dt " +
                  format_number(dt) + " reaches " + std::to_string(need) +
                  " cells (Courant number " + format_number(courant_) +
                  "), more than the advection halo (" + std::to_string(wide_->width()) +
                  " cells, " +
                  (set_.halo > 0 ? "-advection_halo"
                   : file_       ? "sized from the files' largest speed and the first -dt"
                                 : "sized from the velocity at the start") +
                  "); set -advection_halo " + std::to_string(need) + " (at most " +
                  std::to_string(AdvectionSettings::kMaxHalo) + ") or a smaller -dt");
}

void AdvectionStage::compute_departures(double dt) {
  const Box& ob = grid_.owned();
  const double dth[3] = {dt / grid_.spec().h(0), dt / grid_.spec().h(1), dt / grid_.spec().h(2)};
  const double* u[3] = {u_[0].data(), u_[1].data(), u_[2].data()};
  dep_.resize(3 * static_cast<size_t>(ob.size()));
  double* X = dep_.data();
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i, X += 3)
        advect::backtrace(u, geom_, i, j, k, dth, set_.backtrace, X);
  dep_dt_ = dt;
}

void AdvectionStage::transport(Vec v) {
  PetscScalar* a;
  MG_PETSC(VecGetArray(v, &a));
  wide_->fill(a, w_.data());
  const Box& ob = grid_.owned();
  const double* X = dep_.data();
  const bool cubic = set_.interp == advect::Interp::Cubic;
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j) {
      double* row = a + grid_.local_index(ob.s[0], j, k);
      for (PetscInt i = 0; i < ob.m[0]; ++i, X += 3)
        row[i] = cubic ? advect::interp_cubic(w_.data(), geom_, X)
                       : advect::interp_linear(w_.data(), geom_, X);
    }
  MG_PETSC(VecRestoreArray(v, &a));
}

void AdvectionStage::apply(std::vector<VecH>& u, double t, double dt) {
  if (source_) {
    load_velocity(t + dt);
    check_reach(dt, t + dt);
  } else if (file_ ? file_->uses_time() : velocity_->uses_time()) {
    load_velocity(t + 0.5 * dt);
    check_reach(dt, t + 0.5 * dt);
  } else if (dt != checked_dt_) {
    check_reach(dt, t);
  }
  if (dt != dep_dt_) compute_departures(dt);
  for (int s : set_.species)
    transport(u[static_cast<size_t>(s)]);
}

void AdvectionStage::owned_velocity(int d, double* out) const {
  const Box& ob = grid_.owned();
  PetscInt o = 0;
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i, ++o)
        out[o] = d < grid_.dim() ? u_[d][wide_->index(i, j, k)] : 0.0;
}

std::string AdvectionStage::describe() const {
  std::string names;
  for (const auto& n : set_.names)
    names += (names.empty() ? "" : ",") + n;
  std::string vel;
  for (int d = 0; d < grid_.dim() && velocity_; ++d)
    vel += (d ? ", " : "") + std::string("u_") + kAxis[d] + " = " + velocity_->text(d);
  if (source_) vel = "velocity of " + source_->option_text();
  if (file_) vel = file_->describe();
  return "advection of " + names + " (semi-Lagrangian, " +
         (set_.interp == advect::Interp::Cubic ? "cubic" : "linear") + ", " +
         (set_.backtrace == advect::Backtrace::Rk2 ? "rk2" : "euler") + " back-trace; " + vel +
         "; Courant number " + format_number(courant_) + ", halo " +
         std::to_string(wide_->width()) + " cells)";
}

} // namespace morphogen
