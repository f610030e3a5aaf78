#include "app/state_diffusion_setup.hpp"

#include "core/collective_error.hpp"
#include "core/user_error.hpp"
#include "fields/field_fill.hpp"
#include "operators/polar_diffusion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace morphogen {

namespace {

constexpr double kMaxReal = std::numeric_limits<double>::max();

// -NAME_S_KEY when set, else the shared -NAME_KEY.
std::string species_key(const Options& opt, const std::string& base, const std::string& name,
                        const std::string& k) {
  const std::string own = base + "_" + name + "_" + k;
  return opt.is_set(own) ? own : base + "_" + k;
}

// A value (no t) into a ghosted-layout array.
std::vector<double> read_field(Options& opt, const Grid& grid, const std::string& key,
                               const std::string& def, const std::string& help, double lo,
                               double hi, std::uint64_t seed, const std::string& base_dir) {
  ValueSpec v(key, opt.string(key, def, help), grid.spec(), seed, base_dir);
  if (v.uses_time())
    throw UserError("-" + key + " " + v.text() + ": time-dependent values are not supported here");
  std::vector<double> a(static_cast<size_t>(grid.ghosted().size()), 0.0);
  fill_field(grid, v, a.data(), ArrayLayout::Ghosted, lo, hi);
  return a;
}

PolarLobes read_lobes(Options& opt, const std::string& name) {
  PolarLobes lobes;
  const std::string fkey = species_key(opt, "polar", name, "form");
  lobes.witkin_kass =
      opt.choice(fkey, "cosine", {"cosine", "witkin_kass"},
                 "polar anisotropy a(theta): cosine (stable-ARD eq. 16, j lobes, "
                 "a speed per lobe) or witkin_kass (eq. 15, a1 and a2)") == "witkin_kass";
  const std::string jkey = species_key(opt, "polar", name, "lobes");
  if (lobes.witkin_kass && opt.is_set(jkey))
    throw UserError("-" + jkey + ": the Witkin-Kass form has four lobes; -" + jkey +
                    " applies to -polar_form cosine");
  lobes.j = lobes.witkin_kass
                ? 4
                : static_cast<int>(opt.integer(jkey, 4, 1, kMaxPolarLobes,
                                               "number of cosine lobes j of a(theta)"));
  const std::string skey = species_key(opt, "polar", name, "speeds");
  const size_t want = lobes.witkin_kass ? 2 : static_cast<size_t>(lobes.j);
  const auto sp = opt.list(skey, {"1"}, 1, kMaxPolarLobes,
                           "lobe speeds a_n >= 0 of a(theta) (j values, or one for every lobe; "
                           "witkin_kass: a1,a2), times D_S");
  if (sp.size() != 1 && sp.size() != want)
    throw UserError("-" + skey + ": " + std::to_string(sp.size()) + " values, allowed 1 or " +
                    std::to_string(want) + (lobes.witkin_kass ? " (a1,a2)" : " (one per lobe)"));
  for (size_t n = 0; n < want; ++n) {
    const std::string& t = sp[sp.size() == 1 ? 0 : n];
    const double a = Options::parse_real(skey, t);
    if (!(a >= 0 && a <= kMaxReal))
      throw UserError("-" + skey + " " + t + ": out of range, " + allowed_range(0, kMaxReal));
    lobes.a[n] = a;
  }
  return lobes;
}

DiffusionSetup read_polar(Options& opt, const Grid& grid, const Halo& halo, const std::string& name,
                          ValueSpec& Dv, std::uint64_t seed, const std::string& base_dir) {
  if (grid.dim() != 2)
    throw UserError("-diffusion_" + name +
                    " polar: the a(theta) lobes are 2-D (theta is the angle in the x-y plane); "
                    "use a 2-D grid or -diffusion_" +
                    name + " shaped");
  const PolarLobes lobes = read_lobes(opt, name);
  const std::string tkey = species_key(opt, "polar", name, "theta0");
  std::vector<double> theta0 =
      read_field(opt, grid, tkey, "0",
                 "rotation theta0 of a(theta + theta0) (radians): a number or a field value",
                 -kMaxReal, kMaxReal, seed, base_dir);
  std::vector<double> D(theta0.size(), 0.0);
  fill_field(grid, Dv, D.data(), ArrayLayout::Ghosted, 0.0, kMaxReal);
  std::vector<std::vector<double>> c(1, std::vector<double>(theta0.size(), 0.0));
  auto rule = std::make_unique<PolarRule>(grid, lobes, std::move(D), std::move(theta0));
  const double g0[2] = {0.0, 0.0};
  const Box& ob = grid.owned();
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
      rule->at(grid.local_index(i, j, 0), g0, &c[0][grid.local_index(i, j, 0)]);
  DiffusionSetup out;
  out.op = std::make_unique<DiffusionOperator>(grid, halo, DiffusionScheme::IsotropicField,
                                               std::move(c));
  // Mean over theta of a: the cosine lobes' mean speed / 2; Witkin-Kass (a1 + a2) / 2 ... as
  // sampled (used for linear stability and the banner only).
  double mean = 0;
  for (int q = 0; q < 360; ++q)
    mean += lobes(q * M_PI / 180.0) / 360.0;
  out.D_mean = Dv.is_constant() ? Dv.constant_value() * mean : mean;
  out.rule = std::move(rule);
  return out;
}

// The frame, D l_n and v per cell of species `name`'s shaped tensor; the error names the cell.
DiffusionSetup read_shaped(Options& opt, const Grid& grid, const Halo& halo,
                           const std::string& name, ValueSpec& Dv, std::uint64_t seed,
                           const std::string& base_dir) {
  const int dim = grid.dim();
  const std::vector<std::string> comps =
      dim == 2 ? std::vector<std::string>{"xx", "xy", "yy"}
               : std::vector<std::string>{"xx", "xy", "xz", "yy", "yz", "zz"};
  for (const auto& k : comps)
    if (opt.is_set(species_key(opt, "tensor", name, k)))
      throw UserError("-" + species_key(opt, "tensor", name, k) + ": -diffusion_" + name +
                      " shaped takes the tensor by principal values and angles (-tensor_theta, "
                      "-tensor_l1, -tensor_l2; 3-D also -tensor_phi, -tensor_l3), not components");
  const std::string scheme =
      opt.choice("tensor_scheme", "second_order", {"second_order", "first_order"},
                 "tensor discretisation: second_order (conservative, with the tensor-gradient "
                 "terms; Sanderson eq. 17) or first_order (Witkin-Kass constant masks)");
  const std::vector<std::string> keys =
      dim == 2 ? std::vector<std::string>{"theta", "l1", "l2"}
               : std::vector<std::string>{"theta", "phi", "l1", "l2", "l3"};
  std::vector<std::vector<double>> v;
  std::vector<std::string> names;
  for (const auto& k : keys) {
    names.push_back(species_key(opt, "tensor", name, k));
    const bool angle = k == "theta" || k == "phi";
    v.push_back(read_field(opt, grid, names.back(),
                           k == "phi" ? "pi/2"
                           : angle    ? "0"
                                      : "1",
                           angle ? "principal direction angle (radians); a value"
                                 : "principal diffusivity (times D_S, > 0); a value",
                           angle ? -kMaxReal : 0.0, kMaxReal, seed, base_dir));
  }
  const std::string ikey = species_key(opt, "shaped", name, "I");
  const double I = opt.real(ikey, 0.25, 0.0, kMaxReal,
                            "gradient-shaped tensor: scaling constant I of dl = I (grad u/|grad "
                            "u|).(v/|v|) (Sanderson eq. 18), 0 <= I < min(l1, l2)");
  std::vector<std::vector<double>> vdir;
  for (int a = 0; a < dim; ++a) {
    const std::string vkey = species_key(opt, "shaped", name, std::string("v") + "xyz"[a]);
    const auto text =
        opt.get(vkey, std::string("gradient-shaped tensor: ") + "xyz"[a] +
                          " component of the direction field v (a value; default e1, the "
                          "tensor's first principal direction)");
    if (text)
      vdir.push_back(read_field(opt, grid, vkey, *text, "", -kMaxReal, kMaxReal, seed, base_dir));
  }
  if (!vdir.empty() && static_cast<int>(vdir.size()) != dim)
    throw UserError("-shaped_vx/-shaped_vy" + std::string(dim == 3 ? "/-shaped_vz" : "") +
                    ": give every component of v or none (default: the first principal direction)");
  const size_t ng = static_cast<size_t>(grid.ghosted().size()), d = static_cast<size_t>(dim);
  std::vector<double> frame(9 * ng, 0.0), l(d * ng, 0.0), D(ng, 0.0), vv(d * ng, 0.0);
  fill_field(grid, Dv, D.data(), ArrayLayout::Ghosted, 0.0, kMaxReal);
  const Box& ob = grid.owned();
  std::string err;
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2] && err.empty(); ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1] && err.empty(); ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0] && err.empty(); ++i) {
        const size_t c = static_cast<size_t>(grid.local_index(i, j, k));
        double e[3][3];
        principal_frame(v[0][c], dim == 3 ? v[1][c] : M_PI / 2, e);
        std::copy(&e[0][0], &e[0][0] + 9, frame.begin() + 9 * c);
        for (size_t n = 0; n < d; ++n) {
          const double ln = v[(dim == 3 ? 2 : 1) + n][c];
          l[d * c + n] = D[c] * ln;
          if (!(ln - (n < 2 ? I : 0.0) > 0)) {
            std::ostringstream m;
            m << "-" << ikey << " " << I << ": the shaped tensor of " << name
              << " needs l1 - I > 0 and l2 - I > 0 at every cell; at cell (" << i << "," << j
              << (dim == 3 ? "," + std::to_string(k) : "") << ") -" << names[(dim == 3 ? 2 : 1) + n]
              << " = " << ln;
            err = m.str();
          }
        }
        for (size_t a = 0; a < d; ++a)
          vv[d * c + a] = vdir.empty() ? e[0][a] : vdir[a][c];
      }
  throw_if_any(grid.comm(), err);
  const DiffusionScheme sch =
      scheme == "first_order" ? DiffusionScheme::TensorFirstOrder : DiffusionScheme::Tensor;
  auto rule = std::make_unique<ShapedRule>(grid, sch, std::move(frame), std::move(l), std::move(D),
                                           std::move(vv), I);
  const int nc = rule->components();
  std::vector<std::vector<double>> coef(static_cast<size_t>(nc), std::vector<double>(ng, 0.0));
  const double g0[3] = {0, 0, 0};
  double cv[6];
  double trace = 0;
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
        const PetscInt c = grid.local_index(i, j, k);
        rule->at(c, g0, cv);
        for (int q = 0; q < nc; ++q)
          coef[q][c] = cv[q];
        trace += dim == 2 ? cv[0] + cv[2] : cv[0] + cv[3] + cv[5];
      }
  MPI_Allreduce(MPI_IN_PLACE, &trace, 1, MPI_DOUBLE, MPI_SUM, grid.comm());
  DiffusionSetup out;
  out.op = std::make_unique<DiffusionOperator>(grid, halo, sch, std::move(coef));
  out.D_mean = trace / (dim * static_cast<double>(grid.global_cells()));
  out.rule = std::move(rule);
  return out;
}

} // namespace

std::string read_diffusion_kind(Options& opt, const std::string& name) {
  const std::vector<std::string> kinds = {"iso", "tensor", "polar", "shaped"};
  const std::string all = opt.choice(
      "diffusion", "iso", kinds,
      "diffusion of every species: iso (D_S, a number or a field), tensor (D_S times the "
      "-tensor_* tensor), polar (D_S a(theta), -polar_*) or shaped (the tensor with "
      "gradient-shaped principal values, -shaped_*)");
  return opt.choice("diffusion_" + name, all, kinds,
                    "diffusion of species " + name + " (overrides -diffusion)");
}

DiffusionSetup read_state_diffusion(Options& opt, const Grid& grid, const Halo& halo,
                                    const std::string& name, const std::string& kind, ValueSpec& D,
                                    std::uint64_t seed, const std::string& base_dir) {
  if (kind == "polar") return read_polar(opt, grid, halo, name, D, seed, base_dir);
  return read_shaped(opt, grid, halo, name, D, seed, base_dir);
}

} // namespace morphogen
