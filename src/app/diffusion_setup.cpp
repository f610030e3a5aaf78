#include "app/diffusion_setup.hpp"

#include "app/state_diffusion_setup.hpp"

#include "core/collective_error.hpp"
#include "core/user_error.hpp"
#include "fields/field_fill.hpp"
#include "fields/surface_metric.hpp"
#include "fields/value_spec.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

namespace morphogen {

namespace {

constexpr double kMaxReal = std::numeric_limits<double>::max();

struct TensorKeys {
  std::vector<std::string> keys; // option names
  std::vector<std::string> defs;
  bool components = false;
};

// The option names of species `name`'s tensor, per key with a fallback: -tensor_S_NAME if
// set, else the shared -tensor_NAME (its default when unset). Components (xx, xy, ...) and
// principal values (theta, l1, ...) cannot be mixed for one species.
TensorKeys tensor_keys(const Options& opt, int dim, const std::string& name) {
  const std::vector<std::string> principal =
      dim == 2 ? std::vector<std::string>{"theta", "l1", "l2"}
               : std::vector<std::string>{"theta", "phi", "l1", "l2", "l3"};
  const std::vector<std::string> comps =
      dim == 2 ? std::vector<std::string>{"xx", "xy", "yy"}
               : std::vector<std::string>{"xx", "xy", "xz", "yy", "yz", "zz"};
  auto key = [&](const std::string& k) {
    const std::string own = "tensor_" + name + "_" + k;
    return opt.is_set(own) ? own : "tensor_" + k;
  };
  auto first_set = [&](const std::vector<std::string>& ks) {
    for (const auto& k : ks)
      if (opt.is_set(key(k))) return key(k);
    return std::string();
  };
  const std::string c = first_set(comps), p = first_set(principal);
  if (!c.empty() && !p.empty())
    throw UserError("-" + c + " and -" + p + ": the tensor of " + name +
                    " is given either by components (xx, xy, ...) or by principal values and "
                    "angles (theta, l1, ...), not both");
  TensorKeys tk;
  tk.components = !c.empty();
  for (const auto& k : tk.components ? comps : principal) {
    tk.keys.push_back(key(k));
    tk.defs.push_back(k == "theta" || k == "xy" || k == "xz" || k == "yz" ? "0"
                      : k == "phi"                                        ? "pi/2"
                                                                          : "1");
  }
  return tk;
}

// sigma components from principal values and angles (v: theta, l1, l2 or theta, phi, l1..l3).
void principal_to_components(int dim, const double* v, double* s) {
  const double c = std::cos(v[0]), sn = std::sin(v[0]);
  if (dim == 2) {
    s[0] = v[1] * c * c + v[2] * sn * sn;
    s[1] = (v[1] - v[2]) * c * sn;
    s[2] = v[1] * sn * sn + v[2] * c * c;
    return;
  }
  const double sp = std::sin(v[1]), cp = std::cos(v[1]);
  const double e1[3] = {c * sp, sn * sp, cp}, e2[3] = {-sn, c, 0.0};
  const double e3[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                        e1[0] * e2[1] - e1[1] * e2[0]};
  const int a[6] = {0, 0, 0, 1, 1, 2}, b[6] = {0, 1, 2, 1, 2, 2};
  for (int q = 0; q < 6; ++q)
    s[q] = v[2] * e1[a[q]] * e1[b[q]] + v[3] * e2[a[q]] * e2[b[q]] + v[4] * e3[a[q]] * e3[b[q]];
}

std::string cell_text(PetscInt i, PetscInt j, PetscInt k, int dim) {
  return "(" + std::to_string(i) + "," + std::to_string(j) +
         (dim == 3 ? "," + std::to_string(k) : std::string()) + ")";
}

// The isotropic D with the same centre weight as the mean-coefficient stencil (for a tensor
// with equal spacing: its mean trace / dim).
double mean_diagonal(const DiffusionOperator& op, const Grid& grid) {
  const Stencil m = op.mean_stencil();
  double centre = 0;
  for (int t = 0; t < m.nterms; ++t)
    if (m.off[t][0] == 0 && m.off[t][1] == 0 && m.off[t][2] == 0) centre = -m.w[t];
  double iso = 0;
  for (int d = 0; d < grid.dim(); ++d)
    iso += 2.0 / (grid.spec().h(d) * grid.spec().h(d));
  return centre / iso;
}

// -surface_x/y/z: the parametric surface x(u, v) the texture is grown for (2-D).
std::shared_ptr<SurfaceMap> read_surface(Options& opt, const GridSpec& spec) {
  const char* axes[3] = {"surface_x", "surface_y", "surface_z"};
  bool any = false;
  for (const char* a : axes)
    any = any || opt.is_set(a);
  if (!any) {
    for (const char* a : axes)
      opt.known(a);
    return nullptr;
  }
  if (spec.dim != 2)
    throw UserError("-surface_x/-surface_y/-surface_z: the surface-metric correction is for 2-D "
                    "runs (a parametric surface x(u, v))");
  std::string e[3];
  const char* defs[3] = {"u", "v", "0"};
  for (int a = 0; a < 3; ++a)
    e[a] = opt.string(axes[a], defs[a],
                      std::string("parametric surface, ") + "xyz"[a] +
                          " component as an expression of u, v (the grid's x, y), Lx, Ly: the "
                          "tensor is corrected for the surface metric (Witkin-Kass section 4)");
  return std::make_shared<SurfaceMap>(e[0], e[1], e[2], spec.L[0], spec.L[1]);
}

// The tensor components D sigma at every owned cell at time t into c (ghosted arrays); an
// invalid tensor is a one-line error naming the keys, the cell, the values (and t when it
// depends on t). Collective.
struct TensorFill {
  const Grid* grid;
  std::shared_ptr<ValueSpec> D;
  std::vector<std::shared_ptr<ValueSpec>> vals;
  TensorKeys tk;
  std::shared_ptr<SurfaceMap> surface;
  std::string name;

  void operator()(double t, std::vector<std::vector<double>>& c) const {
    const int dim = grid->dim(), nc = dim == 2 ? 3 : 6;
    const Box& ob = grid->owned();
    std::string err;
    double v[6], s[6];
    try {
      for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2] && err.empty(); ++k)
        for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1] && err.empty(); ++j)
          for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
            for (size_t q = 0; q < vals.size(); ++q)
              v[q] = vals[q]->at_cell(i, j, k, t);
            if (tk.components)
              std::copy(v, v + nc, s);
            else
              principal_to_components(dim, v, s);
            if (surface) // the tensor is meant on the surface: correct it for the map's metric
              surface->corrected_tensor(grid->centre(0, i), grid->centre(1, j), s, s);
            const double d = D->at_cell(i, j, k, t);
            if (!valid(dim, d, s)) {
              err = message(i, j, k, d, v, t);
              break;
            }
            const PetscInt gi = grid->local_index(i, j, k);
            for (int q = 0; q < nc; ++q)
              c[q][gi] = d * s[q];
          }
    } catch (const UserError& e) {
      err = e.what();
    }
    throw_if_any(grid->comm(), err);
  }

  static bool valid(int dim, double d, const double* s) {
    const bool pd = dim == 2 ? tensor_positive_definite<2>(s) : tensor_positive_definite<3>(s);
    bool finite = std::isfinite(d);
    for (int q = 0; q < (dim == 2 ? 3 : 6); ++q)
      finite = finite && std::isfinite(s[q]);
    return pd && finite && d >= 0;
  }

  std::string message(PetscInt i, PetscInt j, PetscInt k, double d, const double* v,
                      double t) const {
    bool timed = D->uses_time();
    for (const auto& q : vals)
      timed = timed || q->uses_time();
    std::ostringstream m;
    m.precision(6);
    m << (d >= 0 && std::isfinite(d) ? "-" + tk.keys[0] + ".." + tk.keys.back() : "-" + D->key())
      << ": the diffusion tensor of " << name << " must be positive definite with D_" << name
      << " >= 0 at every cell; at cell " << cell_text(i, j, k, grid->dim());
    if (timed) m << " at t = " << t;
    m << " D = " << d << ", tensor (" << (tk.components ? "components" : "principal values") << ")";
    for (size_t q = 0; q < vals.size(); ++q)
      m << " " << tk.keys[q] << " = " << v[q];
    return m.str();
  }
};

} // namespace

bool read_tensor_choice(Options& opt, const std::string& name) {
  const std::string kind = read_diffusion_kind(opt, name);
  return kind == "tensor" || kind == "shaped";
}

DiffusionSetup read_diffusion(Options& opt, const Grid& grid, const Halo& halo,
                              const Stencil& stencil, const SpeciesInfo& si, bool tensor,
                              std::uint64_t seed, const std::string& base_dir) {
  const GridSpec& spec = grid.spec();
  const int dim = grid.dim();
  const std::string name = si.name;
  const std::string dkey = "D_" + name;
  const std::string dtext =
      opt.string(dkey, format_double(si.D),
                 "diffusion coefficient of " + name + " (" + si.doc +
                     "): a number, or a field (expression, 'v +- a%', png(...)); may use t "
                     "(re-evaluated once per step, or at the TS stage times)");
  {
    // A plain number (inf included) is range-checked as a number.
    char* end = nullptr;
    const double v = std::strtod(dtext.c_str(), &end);
    if (end && end != dtext.c_str() && *end == '\0' && !(v >= 0 && v <= kMaxReal))
      throw UserError("-" + dkey + " " + dtext + ": out of range, " + allowed_range(0, kMaxReal));
  }
  auto Dp = std::make_shared<ValueSpec>(dkey, dtext, spec, seed, base_dir);
  ValueSpec& D = *Dp;
  if (const std::string kind = read_diffusion_kind(opt, name);
      kind == "polar" || kind == "shaped") {
    if (D.uses_time())
      throw UserError("-" + dkey + " " + D.text() + ": a time-dependent D_" + name +
                      " is not supported with -diffusion_" + name + " " + kind +
                      " (solution-dependent coefficients); allowed with iso and tensor");
    return read_state_diffusion(opt, grid, halo, name, kind, D, seed, base_dir);
  }
  DiffusionSetup out;
  if (D.is_constant() && !tensor) {
    const double v = D.constant_value();
    if (!(v >= 0 && v <= kMaxReal))
      throw UserError("-" + dkey + " " + D.text() + ": out of range, " +
                      allowed_range(0, kMaxReal));
    out.op = std::make_unique<DiffusionOperator>(grid, stencil, v);
    out.D_mean = v;
    return out;
  }
  const size_t nghost = static_cast<size_t>(grid.ghosted().size());
  if (!tensor) {
    std::vector<std::vector<double>> c(1, std::vector<double>(nghost, 0.0));
    fill_field(grid, D, c[0].data(), ArrayLayout::Ghosted, 0.0, kMaxReal);
    out.op = std::make_unique<DiffusionOperator>(grid, halo, DiffusionScheme::IsotropicField,
                                                 std::move(c));
    out.D_mean = mean_diagonal(*out.op, grid);
    if (D.uses_time()) {
      out.components = 1;
      out.timed = [Dp, g = &grid](double t, std::vector<std::vector<double>>& coef) {
        fill_field(*g, *Dp, coef[0].data(), ArrayLayout::Ghosted, 0.0, kMaxReal, t);
      };
    }
    return out;
  }
  const std::string scheme =
      opt.choice("tensor_scheme", "second_order", {"second_order", "first_order"},
                 "tensor discretisation: second_order (conservative, with the tensor-gradient "
                 "terms; Sanderson eq. 17) or first_order (Witkin-Kass constant masks)");
  const TensorKeys tk = tensor_keys(opt, dim, name);
  TensorFill fill{&grid, Dp, {}, tk, nullptr, name};
  bool timed = D.uses_time();
  for (size_t q = 0; q < tk.keys.size(); ++q) {
    const std::string help =
        tk.components ? "diffusion tensor component (times D_S); a value (may use t)"
        : tk.keys[q].find("theta") != std::string::npos
            ? "angle of the first principal direction from the x axis (radians); a value (may "
              "use t)"
        : tk.keys[q].find("phi") != std::string::npos
            ? "polar angle of the first principal direction from the z axis (radians)"
            : "principal diffusivity (times D_S, > 0); a value (may use t)";
    fill.vals.push_back(std::make_shared<ValueSpec>(
        tk.keys[q], opt.string(tk.keys[q], tk.defs[q], help), spec, seed, base_dir));
    timed = timed || fill.vals.back()->uses_time();
  }
  const int nc = dim == 2 ? 3 : 6;
  fill.surface = read_surface(opt, spec);
  std::vector<std::vector<double>> c(static_cast<size_t>(nc), std::vector<double>(nghost, 0.0));
  fill(0.0, c);
  out.op = std::make_unique<DiffusionOperator>(
      grid, halo,
      scheme == "first_order" ? DiffusionScheme::TensorFirstOrder : DiffusionScheme::Tensor,
      std::move(c));
  out.D_mean = mean_diagonal(*out.op, grid);
  if (timed) {
    out.components = nc;
    out.timed = fill;
  }
  return out;
}

} // namespace morphogen
