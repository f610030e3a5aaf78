// Explicit (forward Euler) integrator: diffusion and reaction fused in one sweep.
//
//   u_s^{n+1} = max( u_s^n + dt (D_s L u_s^n + R_s(u^n; p)), floor_s )
//
// The driver owns communication: halo update of every species (begin all, end all, then the
// physical boundaries), then one pass over the owned box calling the model's fused row kernel
// (explicit_kernel.hpp) for each grid row. With a star stencil and x periodic and unsplit, the
// sweep sets each row's two x ghosts itself just before the row's kernel (fills_x()), and the
// halo update leaves them out. State lives in ghosted local Vecs. The fast path
// updates them in place where a rank's state is large (set_in_place). In 3-D the box is swept in
// blocks of bh y rows (all planes of a block, then the next block: L2 reuse of the three planes
// a row reads), in 2-D as one block; within a block rows go in the order t = (k - k0) bh + j - jb,
// and the old row t is last read by row t + R_z bh + R_y (R: the stencil's reach in y and z), so
// each new row waits in a ring of R_z bh + R_y + 1 row buffers (2-D: R_y + 1 rows) until the rows
// reading it are done; the old values of a block's last row are kept (one row per plane) for the
// next block, which reads them as its row jb - 1. There is no second state set (8 bytes per cell
// and species less) and the sweep moves 16 bytes per cell and species (no write-allocate
// of a second array). Otherwise (small states, the general path, fused steps) the new state is
// written into a second set, and the two are swapped (no global-to-local
// copy). The step is stable for dt <= 2 / (D_max * spectral_radius(L)) (the diffusion bound, dt <=
// h^2 / (2 dim D_max) for the 5/7-point Laplacian). General path (any species with a diffusion
// field or tensor): per grid row, each species' diffusion (DiffusionOperator::apply_row) goes into
// a row buffer, then the model's explicit_row_pre adds the reaction and writes the row, so the tile
// stays in cache; stable for dt <= 2 / max_s radius_s (lambda_max of the tensors over the grid).
// Other terms of the run (sources, ...: use_terms) are evaluated on u^n after the halo update,
// and dt times their rates is added after the sweep, followed by the run's constraints:
//   u^{n+1} = C( sweep(u^n) + dt sum_k T_k(u^n, t) )
// Diffusion coefficients and Dirichlet values using t are set at the step's start t^n
// (TermList::set_time) before the halo update, so the ghosts carry g(t^n).
// Temporal blocking (-explicit_fuse_steps k, integrators/fused_sweep.hpp): steps(u, t, dt, n)
// advances n <= k steps in one pass with a k r wide halo exchanged once; bitwise the same as n
// calls of step(). Only the fast path on a 2-D grid periodic on both axes, with no terms or
// constraints besides the kernel's floor (fuse_unsupported() says which condition fails; then
// fuse_steps() is 1); parameters must not change between steps (the caller's check). A pass
// updates the state in place where single steps do (in_place()).
#pragma once

#include "core/prefetch.hpp"

#include "fields/param_set.hpp"
#include "grid/halo.hpp"
#include "grid/stencil.hpp"
#include "integrators/explicit_kernel.hpp"
#include "integrators/fused_sweep.hpp"
#include "integrators/integrator.hpp"
#include "integrators/kernel_choice.hpp"
#include "operators/diffusion_operator.hpp"
#include "operators/term_list.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace morphogen {

class ExplicitIntegrator : public Integrator {
public:
  using RowFn = void (*)(const ExplicitRow&);
  // The general path's row update (a std::function: a model built at run time carries state).
  using PreFn = std::function<void(const ExplicitRow&)>;
  // row_fn must match (nspecies, nparams, the stencil's row form, params.field_mask()).
  ExplicitIntegrator(const Grid& grid, const Halo& halo, RowFn row_fn, int nspecies,
                     const Stencil& stencil, std::vector<double> D, std::vector<double> floor,
                     const ParamSet& params, const std::vector<FaceValues>* dirichlet);

  // Refresh the ghosts of `u` (ghosted local Vecs, one per species).
  void update_ghosts(std::vector<VecH>& u) const;
  // One step: u <- u + dt (D L u + R(u)); `work` is a second set of ghosted local Vecs.
  void step(std::vector<VecH>& u, std::vector<VecH>& work, double dt) const;
  // One step of the whole run: the sweep, the other terms and the constraints (use_terms).
  void step(std::vector<VecH>& u, double t, double dt, PetscInt step) override;
  // The run's terms besides diffusion and reaction (evaluated through Term::add_rates) and its
  // constraints; keeps a reference to `terms`.
  void use_terms(const TermList& terms);

  // Largest stable dt for this stencil and these diffusion coefficients (inf if D = 0).
  static double stable_dt(const Stencil& stencil, const std::vector<double>& D);

  // Switch to the general path: each species' diffusion from its operator (into a row buffer),
  // then pre_fn adds the reaction and writes the row (explicit_row_pre of the model). Used when
  // any operator is not constant isotropic; the fused fast path is kept otherwise.
  void use_operators(std::vector<const DiffusionOperator*> ops, PreFn pre_fn);
  bool general() const { return !ops_.empty(); }

  // The fast path's in-place update (see the header comment): Auto where a rank's state is
  // at least kInPlaceBytes (2-D) or kInPlaceBytes3d (3-D: at 128^3 on 2 ranks, in cache, the
  // second set measured faster for the 7-point stencil), where the memory matters and the row
  // copies hide behind the memory traffic; else a second state set. Always and Never force it
  // (the same results).
  enum class InPlace { Auto, Always, Never };
  static constexpr double kInPlaceBytes = 8.0 * 1024 * 1024;
  static constexpr double kInPlaceBytes3d = 64.0 * 1024 * 1024;
  void set_in_place(InPlace mode) { in_place_ = mode; }

  // Software prefetch, in the single-step sweep, of the row read from memory kPrefetchRows rows
  // after the stencil's leading row (in 3-D blocks, near a block's last row, the row of the next
  // plane read first two rows later). Box stencils: issued by the row kernel one cache line at
  // a time between its cells (ExplicitRow::prefetch_ahead; 4096^2 9pt 25-30 % faster than the
  // whole row before the call, which stalls on the core's miss buffers); the 5/7-point tap loop
  // gets the whole row before its call (faster there, docs/performance.md). Auto where a rank's
  // state is at least kPrefetchBytes (out of the per-core caches; in cache the prefetches only
  // cost instructions); Always and Never force it. Nothing read changes, so neither do the results.
  // (Fused passes do not prefetch: their rows take k times the arithmetic, which hides the loads
  // already; prefetching there measured 1-5 % slower at 4096^2, k = 8.)
  enum class Prefetch { Auto, Always, Never };
  static constexpr double kPrefetchBytes = kPrefetchMinBytes;
  static constexpr int kPrefetchRows = kPrefetchRowsAhead;
  void set_prefetch(Prefetch mode) { prefetch_ = mode; }
  bool prefetch() const;

  // The fast path's second compile of the row kernel (512-bit vectors, the same results) and
  // how to choose between the two (-explicit_vector_width: timed in the first passes, or forced).
  void set_vector_width(KernelChoice::Mode mode, RowFn wide_fn) {
    sweep_choice_ = KernelChoice(row_fn_, wide_fn, mode);
    fused_choice_ = KernelChoice(row_fn_, wide_fn, mode);
  }
  // The kernel the single-step sweeps and the fused passes run ("256-bit", "512-bit", with the
  // timings where they were chosen by timing).
  std::string vector_width() const;

  // Temporal blocking: up to k >= 1 steps per pass (1: one step per pass).
  void set_fuse_steps(int k) { fuse_request_ = k; }
  // The automatic depth (-explicit_fuse_steps 0): kAutoFuseSteps where fused steps apply and the
  // state averages at least kAutoFuseBytes per rank (out of the per-core caches, where a pass's
  // single read and write of the state pays; the same on every rank), else 1.
  static constexpr int kAutoFuseSteps = 8;
  static constexpr double kAutoFuseBytes = kInPlaceBytes;
  int auto_fuse_steps() const;
  // Owned columns per tile of the fused sweep (0: automatic, FusedSweep::tile_width).
  void set_fuse_tile(PetscInt columns) { fuse_tile_ = columns; }
  // Why this run cannot fuse steps ("" when it can).
  std::string fuse_unsupported() const;
  // Steps steps() may fuse: the requested k where supported, else 1.
  int fuse_steps() const {
    return fuse_request_ > 1 && fuse_unsupported().empty() ? fuse_request_ : 1;
  }
  // n steps (1 <= n <= fuse_steps()) from t with step dt: bitwise n calls of step(). Collective.
  void steps(std::vector<VecH>& u, double t, double dt, int n);

private:
  // work == nullptr: in place (in_place()).
  void sweep(std::vector<VecH>& u, std::vector<VecH>* work, double dt) const;
  bool in_place() const;
  int reach(int axis) const;   // the stencil's reach in y (axis 0) or z (axis 1)
  PetscInt block_rows() const; // y rows per block of the sweep
  // Offset from a row's first cell to the first cell of the row to prefetch (-1: none): the
  // stencil's leading row (largest offset in `delta`) kPrefetchRows rows further in y.
  PetscInt prefetch_offset(const std::vector<PetscInt>& delta) const;
  // Ring slot of row t of a block (order within the block: t = (k - k0) bh + j - jb).
  double* ring_row(int s, PetscInt t) const {
    return ring_.data() + (static_cast<size_t>(s) * ring_depth_ +
                           static_cast<size_t>(t) % static_cast<size_t>(ring_depth_)) *
                              ring_n_;
  }
  // Old ghosted row just outside a block, plane k (b = 0: above this block, 1: for the next).
  double* edge_row(int b, int s, PetscInt k) const {
    const Box& gb = grid_.ghosted();
    return edge_[b].data() + (static_cast<size_t>(s) * gb.m[2] + (k - gb.s[2])) * gb.m[0];
  }
  void commit_row(const std::vector<PetscScalar*>& u, PetscInt t, PetscInt jb, PetscInt bh,
                  bool save_edge) const;
  void save_ghost_plane_edges(const std::vector<PetscScalar*>& u, PetscInt jend) const;
  void add_other_terms(std::vector<VecH>& u, double t, double dt);
  void step_general(std::vector<VecH>& u, std::vector<VecH>& work, double dt) const;

  // The halo update of a step: without the x ghosts where the sweep fills them (fills_x()).
  void exchange(std::vector<VecH>& u, const Halo& halo) const;
  // Whether the sweep fills the periodic x ghosts of each row it computes (the centre row: in
  // cache then), and the step's halo update leaves them out (x_halo_): a star stencil (no
  // other row's x ghosts are read), x periodic and not split between ranks, one ghost layer,
  // the fast path without other terms. Each row's two x ghosts lie in their own cache lines,
  // which the halo update would fetch from memory once more.
  bool fills_x() const { return x_fill_ && ops_.empty() && others_.empty(); }
  // p[-1] = p[n - 1], p[n] = p[0] for `rows` rows of every species from cell c (stride gx).
  void wrap_x(const std::vector<PetscScalar*>& u, PetscInt c, int rows, PetscInt gx) const;

  const Grid& grid_;
  const Halo& halo_;
  bool x_fill_ = false;          // the grid and stencil conditions of fills_x()
  std::unique_ptr<Halo> x_halo_; // halo_ without the x ghosts (built by the first such step)
  RowFn row_fn_;
  int ns_;
  Stencil stencil_;
  RowStencil rows_;
  BoxClasses classes_;    // box stencils by weight class (the kernel's fast form)
  bool by_class_ = false; // rows_ has that form: rows passed in classes_.perm order
  std::vector<double> D_, floor_;
  const ParamSet& params_;
  const std::vector<FaceValues>* dirichlet_;
  mutable std::vector<std::vector<double>> const_rows_; // scalar params as rows (field mode)
  std::vector<const DiffusionOperator*> ops_;           // general path (empty: fused fast path)
  PreFn pre_fn_;
  mutable std::vector<std::vector<double>> div_; // per species row buffer of the general path
  const TermList* terms_ = nullptr;
  std::vector<const Term*> others_;     // terms evaluated through add_rates
  bool constrain_after_sweep_ = false;  // constraints other than the kernel's clamp floor
  std::vector<VecH> work_;              // second state set (created when first needed)
  mutable std::vector<double> ring_;    // in-place sweeps: [ns][depth][nx] new rows
  int ring_depth_ = 2;                  // R_z bh + R_y + 1 (bh: block_rows())
  mutable std::vector<double> edge_[2]; // in-place 3-D blocks: [ns][ghosted z][ghosted x]
  // Pointer and offset tables of sweep() and update_ghosts(), kept between calls so that a step
  // of a small grid (a sweep point) allocates nothing.
  struct SweepTables {
    std::vector<PetscScalar*> in, out;
    std::vector<const PetscScalar*> pf;
    std::vector<PetscInt> delta, dy, dz;
    std::vector<const double*> src, prow, div, cin; // cin, div: the general path
    std::vector<double*> dst;
    // Every table sized for ns species, np parameters and nr stencil rows, entries null.
    void reset(size_t ns, size_t np, size_t nr) {
      for (auto* v : {&in, &out, &dst})
        v->assign(ns, nullptr);
      for (auto* v : {&cin, &div})
        v->assign(ns, nullptr);
      pf.assign(np, nullptr);
      prow.assign(np, nullptr);
      src.assign(ns * nr, nullptr);
    }
  };
  mutable SweepTables tab_;
  size_t ring_n_ = 0; // owned cells per row
  InPlace in_place_ = InPlace::Auto;
  Prefetch prefetch_ = Prefetch::Auto;
  std::vector<std::vector<double>> rates_; // owned layout, per species (other terms)
  int fuse_request_ = 1;
  PetscInt fuse_tile_ = 0;
  std::unique_ptr<FusedSweep> fused_; // built on the first fused call
  mutable KernelChoice sweep_choice_{row_fn_, row_fn_, KernelChoice::Mode::Narrow};
  KernelChoice fused_choice_{row_fn_, row_fn_, KernelChoice::Mode::Narrow};
};

} // namespace morphogen
