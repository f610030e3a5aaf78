// Models built at run time (models/runtime_model.hpp) and their generic kernels
// (integrators/runtime_kernels.hpp), against the compiled models:
//   - custom kinetics written as the Brusselator's expressions give its rates to 1e-14 and its
//     Jacobian to 1e-8 (central differences, error ~ eps^(2/3));
//   - L coupled layers: rates and Jacobian = the layers' blocks + the coupling (exact),
//     species/parameter names a1, b1, a2, ..., alpha1, ..., couple_a; steady state;
//   - the runtime kernels' explicit row and backward-Euler reaction row equal the compiled
//     model's kernels (bitwise for the layer-free model, tolerance 1e-13 otherwise);
//   - bad names and expressions are one-line UserErrors naming the option;
//   - a Jacobian by expressions (Gray-Scott's) equals the compiled one to round-off and the
//     central differences to 1e-8, and is what the model returns; the central differences are
//     exactly the textbook formula (bitwise); a partial Jacobian or 17 species are refused;
//   - the custom model's row rates (ModelInfo::rates_row: muParser's bytecode evaluated per row)
//     equal its per-cell rates bitwise, for rows of several lengths, scalar and per-cell
//     parameters, every kind of token, and the cell-by-cell fallback (if-then-else); the
//     explicit row with them equals the per-cell explicit row bitwise.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/user_error.hpp"
#include "integrators/runtime_kernels.hpp"
#include "models/brusselator.hpp"
#include "models/gray_scott.hpp"
#include "models/model_info.hpp"
#include "models/runtime_model.hpp"

namespace {

using namespace morphogen;
using Bruss = models::Brusselator;

const ModelInfo& brusselator() {
  static const ModelInfo m = model_info<Bruss>();
  return m;
}

ModelInfo custom_brusselator() {
  return custom_model({{"a", "b"},
                       {"s*(alpha - (1 + beta)*a + a^2*b)", "s*(beta*a - a^2*b)"},
                       {"-rate_a", "-rate_b"}});
}

TEST(CustomModel, BrusselatorExpressionsGiveItsRatesAndJacobian) {
  const ModelInfo m = custom_brusselator();
  ASSERT_EQ(m.nspecies, 2);
  ASSERT_EQ(m.nparams, 3); // alphabetical: alpha, beta, s
  EXPECT_STREQ(m.params[0].name, "alpha");
  EXPECT_STREQ(m.params[1].name, "beta");
  EXPECT_STREQ(m.params[2].name, "s");
  const double pc[3] = {3.0, 9.0, 0.7}, pb[3] = {3.0, 9.0, 0.7};
  for (const auto& u : std::vector<std::vector<double>>{{3, 3}, {0.5, 2.5}, {4.2, 0.1}}) {
    double rc[2], rb[2], Jc[4], Jb[4];
    m.rates(u.data(), pc, rc);
    Bruss::rates(u.data(), pb, rb);
    Bruss::jacobian(u.data(), pb, Jb);
    m.jacobian(u.data(), pc, Jc);
    for (int s = 0; s < 2; ++s)
      EXPECT_NEAR(rc[s], rb[s], 1e-14 * (1 + std::fabs(rb[s])));
    for (int q = 0; q < 4; ++q)
      EXPECT_NEAR(Jc[q], Jb[q], 1e-8 * (1 + std::fabs(Jb[q])));
  }
  double u[2];
  EXPECT_FALSE(m.steady_state(pc, u));
}

TEST(CustomModel, BadNamesAndExpressionsAreUserErrors) {
  auto msg = [](CustomKinetics k) {
    try {
      custom_model(k);
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(msg({{"a", "a"}, {"1", "1"}, {"-rate_a", "-rate_a"}}).find("twice"), std::string::npos);
  EXPECT_NE(msg({{"1a"}, {"1"}, {"-rate_1a"}}).find("-species 1a"), std::string::npos);
  EXPECT_NE(msg({{"t"}, {"1"}, {"-rate_t"}}).find("-species t"), std::string::npos);
  EXPECT_NE(msg({{"a"}, {"a*("}, {"-rate_a"}}).find("-rate_a a*("), std::string::npos);
  EXPECT_NE(msg({{"a"}, {" "}, {"-rate_a"}}).find("-rate_a: empty"), std::string::npos);
  EXPECT_NE(msg({{"a"}, {"a*(b"}, {"-rate_a"}}).find("-rate_a a*(b"), std::string::npos);
}

TEST(CustomModel, CoordinatesAndTimeAreParametersWithExpressionDefaults) {
  const ModelInfo m = custom_model({{"a"}, {"-k*t*a + x"}, {"-rate_a"}});
  ASSERT_EQ(m.nparams, 3); // k, t, x
  EXPECT_STREQ(m.params[1].name, "t");
  EXPECT_STREQ(m.params[1].def_text, "t");
  EXPECT_STREQ(m.params[2].def_text, "x");
  EXPECT_EQ(m.params[0].def_text, nullptr);
  const double u = 2, p[3] = {0.5, 3, 0.25};
  double r;
  m.rates(&u, p, &r);
  EXPECT_DOUBLE_EQ(r, -0.5 * 3 * 2 + 0.25);
}

// Gray-Scott (models/gray_scott.hpp) as expressions, with its Jacobian by expressions or not.
CustomKinetics gray_scott_expressions(bool with_jacobian) {
  CustomKinetics k{
      {"a", "b"}, {"s*(a^2*b - (F + k)*a)", "s*(-a^2*b + F*(1 - b))"}, {"-rate_a", "-rate_b"}};
  if (with_jacobian) {
    k.jac = {"s*(2*a*b - (F + k))", "s*a^2", "-2*s*a*b", "-s*(a^2 + F)"};
    k.jac_keys = {"-jac_a_a", "-jac_a_b", "-jac_b_a", "-jac_b_b"};
  }
  return k;
}

// The Jacobian by expressions equals the compiled model's analytic one to round-off (the same
// formulas, evaluated by muParser) and the central differences of the same rates to 1e-8
// (their error ~ eps^(2/3)); the parameters are those of the rates (F, k, s).
TEST(CustomModel, JacobianByExpressionsMatchesAnalyticAndFiniteDifferences) {
  const ModelInfo ex = custom_model(gray_scott_expressions(true));
  const ModelInfo fd = custom_model(gray_scott_expressions(false));
  ASSERT_EQ(ex.nparams, 3);
  const double p[3] = {0.037, 0.06, 1.3};
  for (const auto& u : std::vector<std::vector<double>>{{0.25, 0.5}, {0, 1}, {0.9, 0.02}}) {
    double Je[4], Jf[4], Jc[4];
    ex.jacobian(u.data(), p, Je);
    fd.jacobian(u.data(), p, Jf);
    models::GrayScott::jacobian(u.data(), p, Jc);
    for (int q = 0; q < 4; ++q) {
      EXPECT_NEAR(Je[q], Jc[q], 1e-14 * (1 + std::fabs(Jc[q]))) << q;
      EXPECT_NEAR(Je[q], Jf[q], 1e-8 * (1 + std::fabs(Jc[q]))) << q;
    }
  }
  // The expressions are what the model returns (not differences): a deliberately other one.
  CustomKinetics odd = gray_scott_expressions(true);
  odd.jac[1] = "7 + q";
  const ModelInfo m = custom_model(odd);
  ASSERT_EQ(m.nparams, 4); // F, k, q, s: a name only in the Jacobian is a parameter too
  const double u[2] = {0.3, 0.4}, pq[4] = {0.04, 0.06, 0.5, 1.0};
  double J[4];
  m.jacobian(u, pq, J);
  EXPECT_EQ(J[1], 7.5);
}

// The central differences (stack buffers) are exactly (R(u + h e_q) - R(u - h e_q)) / 2h with
// h = cbrt(eps) (1 + |u_q|), computed here from the model's own rates: bitwise.
TEST(CustomModel, FiniteDifferenceJacobianIsCentralDifferencesBitwise) {
  const ModelInfo m = custom_model({{"a", "b", "c"},
                                    {"a*b - c^3", "sin(a)*exp(b) + c", "a/(1 + b^2) - 2*c*k"},
                                    {"-rate_a", "-rate_b", "-rate_c"}});
  const double u[3] = {0.7, -1.3, 2.1}, p[1] = {0.4};
  double J[9];
  m.jacobian(u, p, J);
  const double c = std::cbrt(std::numeric_limits<double>::epsilon());
  for (int q = 0; q < 3; ++q) {
    const double h = c * (1.0 + std::fabs(u[q]));
    double x[3] = {u[0], u[1], u[2]}, rp[3], rm[3];
    x[q] = u[q] + h;
    m.rates(x, p, rp);
    x[q] = u[q] - h;
    m.rates(x, p, rm);
    for (int s = 0; s < 3; ++s)
      EXPECT_EQ(J[s * 3 + q], (rp[s] - rm[s]) / (2 * h)) << s << "," << q;
  }
}

TEST(CustomModel, PartialJacobianAndTooManySpeciesAreUserErrors) {
  CustomKinetics k = gray_scott_expressions(true);
  k.jac.pop_back();
  k.jac_keys.pop_back();
  EXPECT_THROW(custom_model(k), UserError);
  k = gray_scott_expressions(true);
  k.jac[2] = "a*(";
  try {
    custom_model(k);
    ADD_FAILURE() << "no error";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("-jac_b_a a*("), std::string::npos) << e.what();
  }
  CustomKinetics many;
  for (int s = 0; s <= kMaxModelSpecies; ++s) {
    many.species.push_back("s" + std::to_string(s));
    many.rates.push_back("0");
    many.keys.push_back("-rate_s" + std::to_string(s));
  }
  EXPECT_THROW(custom_model(many), UserError);
}

// Bitwise equality of doubles (NaN == NaN of the same payload).
bool same_bits(double x, double y) {
  return std::bit_cast<std::uint64_t>(x) == std::bit_cast<std::uint64_t>(y);
}

TEST(CustomModel, RowRatesEqualPerCellRatesBitwise) {
  const std::vector<CustomKinetics> specs = {
      {{"a", "b"},
       {"s*(alpha - (1 + beta)*a + a^2*b)", "s*(beta*a - a^2*b)"},
       {"-rate_a", "-rate_b"}},
      // Gray-Scott; powers 3 and 4, x*c + d, fractional powers, functions of 1, 2 and n
      // arguments, unary minus, comparisons and logic, division, pi, x*c + d with d != 0
      // (cmVARMUL: an FMA would change its rounding).
      {{"a", "b", "c"},
       {"s*(a^2*b - (F + k)*a) + 3*c - 0.5 + b^3 - c^4/7",
        "-a^1.5*exp(-b) + sin(pi*c)/(1 + b^2) + atan2(a, b) + max(a, b, c, 0.3) + sum(a, b)",
        "(a > b) + (b <= c)*2 + (a > 0.1 && c < 2) + sqrt(abs(a - c)) - 2 + "
        "(0.7*c + 0.3)*(1.1*a - 0.2)"},
       {"-rate_a", "-rate_b", "-rate_c"}},
      // if-then-else: rows go cell by cell (still the same results).
      {{"a", "b"}, {"a > b ? a*k : b - k", "k"}, {"-rate_a", "-rate_b"}},
  };
  for (const auto& spec : specs) {
    const ModelInfo m = custom_model(spec);
    ASSERT_TRUE(static_cast<bool>(m.rates_row));
    const int ns = m.nspecies, np = m.nparams;
    // Lengths growing past the scratch's first size, then shorter again.
    for (const int n : {1, 3, 7, 64, 65, 200, 5, 130}) {
      std::vector<std::vector<double>> u(static_cast<size_t>(ns)), p(static_cast<size_t>(np)),
          r(static_cast<size_t>(ns));
      std::vector<double> pconst(static_cast<size_t>(np));
      std::vector<const double*> up, pp;
      std::vector<double*> rp;
      for (int s = 0; s < ns; ++s) {
        for (int i = 0; i < n; ++i)
          u[s].push_back(0.3 + 0.9 * std::sin(1.3 * i + 2.1 * s) + 0.01 * n);
        r[s].assign(static_cast<size_t>(n), -7.0);
        up.push_back(u[s].data()), rp.push_back(r[s].data());
      }
      for (int q = 0; q < np; ++q) {
        pconst[q] = 0.05 + 0.7 * q;
        for (int i = 0; i < n; ++i)
          p[q].push_back(pconst[q] * (1 + 0.1 * std::cos(0.7 * i + q)));
        pp.push_back(p[q].data());
      }
      for (const bool field : {false, true}) {
        m.rates_row(n, up.data(), field ? pp.data() : nullptr, pconst.data(), rp.data());
        for (int i = 0; i < n; ++i) {
          std::vector<double> uc(static_cast<size_t>(ns)), pc(static_cast<size_t>(np)),
              rc(static_cast<size_t>(ns));
          for (int s = 0; s < ns; ++s)
            uc[s] = u[s][i];
          for (int q = 0; q < np; ++q)
            pc[q] = field ? p[q][i] : pconst[q];
          m.rates(uc.data(), pc.data(), rc.data());
          for (int s = 0; s < ns; ++s)
            EXPECT_TRUE(same_bits(r[s][i], rc[s]))
                << spec.rates[s] << " n=" << n << " i=" << i << " field=" << field << ": "
                << r[s][i] << " vs " << rc[s];
        }
      }
    }
  }
}

// The explicit row through rates_row equals the per-cell explicit row bitwise.
TEST(RuntimeKernels, RowRatesExplicitRowEqualsPerCell) {
  const ModelInfo m = custom_model(
      {{"a", "b"}, {"s*(a^2*b - (F + k)*a)", "s*(-a^2*b + F*(1 - b))"}, {"-rate_a", "-rate_b"}});
  ModelInfo per_cell = m;
  per_cell.rates_row = nullptr;
  const ModelKernels bulk = runtime_model_kernels(m), cell = runtime_model_kernels(per_cell);
  for (const int n : {1, 9, 128, 33}) {
    std::vector<double> a(n), b(n), da(n), db(n), F(n), k(n), s(n, 1.0);
    for (int i = 0; i < n; ++i) {
      a[i] = 0.25 + 0.2 * std::sin(0.9 * i), b[i] = 0.5 + 0.3 * std::cos(1.7 * i);
      da[i] = 1e-3 * std::sin(2.3 * i), db[i] = -2e-3 * std::cos(0.4 * i);
      F[i] = 0.04 + 0.001 * i, k[i] = 0.06 - 0.0002 * i;
    }
    const double pc[3] = {0.04, 0.06, 1.0}, floor[2] = {0.0, -1e300};
    const double* prow[3] = {F.data(), k.data(), s.data()};
    const double* src[2] = {a.data(), b.data()};
    const double* div[2] = {da.data(), db.data()};
    for (const int field : {0, 1}) {
      std::vector<double> oa(n), ob(n), ea(n), eb(n);
      double* dst[2] = {oa.data(), ob.data()};
      double* edst[2] = {ea.data(), eb.data()};
      ExplicitRow row;
      row.n = n, row.src = src, row.div = div, row.floor = floor, row.dt = 0.7;
      row.pconst = pc, row.prow = field ? prow : nullptr;
      row.dst = dst;
      bulk.explicit_pre[field](row);
      row.dst = edst;
      cell.explicit_pre[field](row);
      for (int i = 0; i < n; ++i) {
        EXPECT_TRUE(same_bits(oa[i], ea[i])) << "n=" << n << " i=" << i << " field=" << field;
        EXPECT_TRUE(same_bits(ob[i], eb[i])) << "n=" << n << " i=" << i << " field=" << field;
      }
    }
  }
}

TEST(LayeredModel, NamesRatesJacobianAndSteadyState) {
  const ModelInfo m = layered_model(brusselator(), 3);
  ASSERT_EQ(m.nspecies, 6);
  ASSERT_EQ(m.nparams, 3 * 3 + 2);
  EXPECT_STREQ(m.species[0].name, "a1");
  EXPECT_STREQ(m.species[3].name, "b2");
  EXPECT_STREQ(m.species[5].name, "b3");
  EXPECT_STREQ(m.params[4].name, "beta2");
  EXPECT_STREQ(m.params[9].name, "couple_a");
  EXPECT_STREQ(m.params[10].name, "couple_b");
  EXPECT_DOUBLE_EQ(m.species[2].D, Bruss::species[0].D);
  // Layers with different parameters; coupling mu = 0.3 (a), nu = 0.05 (b).
  const std::vector<double> p = {3, 9, 1, 2, 7, 0.5, 4, 11, 2, 0.3, 0.05};
  const std::vector<double> u = {3.1, 2.9, 2.2, 3.4, 4.1, 2.7};
  std::vector<double> r(6), J(36);
  m.rates(u.data(), p.data(), r.data());
  m.jacobian(u.data(), p.data(), J.data());
  const double k[2] = {0.3, 0.05};
  for (int l = 0; l < 3; ++l) {
    double rl[2], Jl[4];
    Bruss::rates(&u[2 * l], &p[3 * l], rl);
    Bruss::jacobian(&u[2 * l], &p[3 * l], Jl);
    for (int s = 0; s < 2; ++s) {
      double expect = rl[s], diag = Jl[s * 2 + s];
      for (int m2 : {l - 1, l + 1})
        if (m2 >= 0 && m2 < 3) expect += k[s] * (u[2 * m2 + s] - u[2 * l + s]), diag -= k[s];
      EXPECT_DOUBLE_EQ(r[2 * l + s], expect) << "layer " << l << " species " << s;
      EXPECT_DOUBLE_EQ(J[(2 * l + s) * 6 + 2 * l + s], diag);
      EXPECT_DOUBLE_EQ(J[(2 * l + s) * 6 + 2 * l + 1 - s], Jl[s * 2 + 1 - s]);
      if (l > 0) {
        EXPECT_DOUBLE_EQ(J[(2 * l + s) * 6 + 2 * (l - 1) + s], k[s]);
      }
      if (l == 2) { // only neighbouring layers
        EXPECT_DOUBLE_EQ(J[(2 * l + s) * 6 + s], 0.0);
      }
    }
  }
  // Equal layers: the common steady state; different layers with coupling: none claimed.
  const std::vector<double> same = {3, 9, 1, 3, 9, 1, 3, 9, 1, 0.1, 0.1};
  std::vector<double> us(6);
  ASSERT_TRUE(m.steady_state(same.data(), us.data()));
  m.rates(us.data(), same.data(), r.data());
  for (double x : r)
    EXPECT_NEAR(x, 0.0, 1e-13);
  EXPECT_FALSE(m.steady_state(p.data(), us.data()));
  EXPECT_THROW(layered_model(brusselator(), 17), UserError);
  // The composite Jacobian against central differences of the composite rates.
  std::vector<double> x = u, rp(6), rm(6);
  for (int q = 0; q < 6; ++q) {
    const double h = 1e-6 * (1 + std::fabs(u[q]));
    x[q] = u[q] + h;
    m.rates(x.data(), p.data(), rp.data());
    x[q] = u[q] - h;
    m.rates(x.data(), p.data(), rm.data());
    x[q] = u[q];
    for (int s = 0; s < 6; ++s)
      EXPECT_NEAR(J[s * 6 + q], (rp[s] - rm[s]) / (2 * h), 1e-6 * (1 + std::fabs(J[s * 6 + q])));
  }
}

// The runtime kernels against the compiled Brusselator's, on one row of 7 cells.
TEST(RuntimeKernels, MatchCompiledKernels) {
  const ModelInfo m = custom_brusselator();
  const ModelInfo layered = layered_model(brusselator(), 2);
  const ModelKernels rk = runtime_model_kernels(m), lk = runtime_model_kernels(layered);
  EXPECT_FALSE(rk.fused);
  constexpr int n = 7;
  std::vector<double> a(n), b(n), da(n, 0.01), db(n, -0.02);
  for (int i = 0; i < n; ++i)
    a[i] = 3 + 0.1 * i, b[i] = 3 - 0.07 * i;
  const double pb[3] = {3, 9, 1}, pc[3] = {3, 9, 1}, floor[4] = {-1e300, -1e300, -1e300, -1e300};
  std::vector<double> oa(n), ob(n), ra(n), rb(n);
  const double* src[2] = {a.data(), b.data()};
  const double* div[2] = {da.data(), db.data()};
  double* dst[2] = {oa.data(), ob.data()};
  ExplicitRow row;
  row.n = n, row.src = src, row.div = div, row.dst = dst, row.floor = floor, row.dt = 0.01;
  row.pconst = pb;
  explicit_row_pre<Bruss, false>(row);
  const std::vector<double> ea = oa, eb = ob;
  row.pconst = pc;
  rk.explicit_pre[0](row);
  for (int i = 0; i < n; ++i) {
    EXPECT_NEAR(oa[i], ea[i], 1e-14);
    EXPECT_NEAR(ob[i], eb[i], 1e-14);
  }
  // Backward Euler reaction rows, dt = 0.5: compiled vs custom vs two uncoupled layers.
  double* out[2] = {ra.data(), rb.data()};
  CellSolve w{};
  ASSERT_EQ((reaction_row<Bruss, false>(ReactionScheme::BackwardEuler, n, src, nullptr, pb, nullptr,
                                        nullptr, 0.5, 1e-12, 20, floor, out, &w)),
            -1);
  const std::vector<double> xa = ra, xb = rb;
  ASSERT_EQ(rk.reaction_row[0](ReactionScheme::BackwardEuler, n, src, nullptr, pc, nullptr, nullptr,
                               0.5, 1e-12, 20, floor, out, &w),
            -1);
  for (int i = 0; i < n; ++i) {
    EXPECT_NEAR(ra[i], xa[i], 1e-10 * (1 + std::fabs(xa[i])));
    EXPECT_NEAR(rb[i], xb[i], 1e-10 * (1 + std::fabs(xb[i])));
  }
  std::vector<double> l2a(n), l2b(n);
  const double* src4[4] = {a.data(), b.data(), a.data(), b.data()};
  double* out4[4] = {ra.data(), rb.data(), l2a.data(), l2b.data()};
  const double p4[8] = {3, 9, 1, 3, 9, 1, 0, 0}; // couple_a = couple_b = 0
  ASSERT_EQ(lk.reaction_row[0](ReactionScheme::BackwardEuler, n, src4, nullptr, p4, nullptr,
                               nullptr, 0.5, 1e-12, 20, floor, out4, &w),
            -1);
  for (int i = 0; i < n; ++i) {
    EXPECT_NEAR(ra[i], xa[i], 1e-13 * (1 + std::fabs(xa[i])));
    EXPECT_NEAR(l2b[i], xb[i], 1e-13 * (1 + std::fabs(xb[i])));
  }
}

} // namespace
