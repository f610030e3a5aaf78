// The three-layer Oregonator deck (input/oregonator_three_layer.yaml, Sanderson eqs. 22-28) without
// diffusion: its kinetics, read from the deck and built as a custom model, stepped by the
// runtime reaction kernel with the deck's scheme and dt (explicit Euler, 2e-4, negatives
// clamped: what the explicit integrator does per cell when D = 0), oscillate with the period of
// a high-accuracy reference (classical RK4 at dt 2e-5 on the same rates) within 1 %. The period
// is the mean interval between the last three upward crossings of d = 0.3 before t = 40.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "integrators/runtime_kernels.hpp"
#include "models/runtime_model.hpp"

namespace {

using namespace morphogen;

struct Deck {
  ModelInfo model;
  std::vector<double> params;
  double dt = 0;
};

Deck load_deck() {
  const auto path =
      std::filesystem::path(__FILE__).parent_path() / "../../input" / "oregonator_three_layer.yaml";
  const YAML::Node d = YAML::LoadFile(path.string());
  CustomKinetics spec;
  std::string list = d["species"].as<std::string>();
  for (size_t at = 0; at <= list.size();) {
    const size_t comma = std::min(list.find(',', at), list.size());
    spec.species.push_back(list.substr(at, comma - at));
    at = comma + 1;
  }
  for (const auto& s : spec.species) {
    spec.rates.push_back(d["rate"][s].as<std::string>());
    spec.keys.push_back("-rate_" + s);
  }
  Deck out{custom_model(spec), {}, d["dt"].as<double>()};
  for (int q = 0; q < out.model.nparams; ++q)
    out.params.push_back(d["params"][out.model.params[q].name].as<double>());
  return out;
}

// Upward crossings of species s through `level` by a stepper u -> u(t + dt), up to t_end.
template <class Step>
std::vector<double> crossings(std::vector<double> u, double dt, double t_end, int s, double level,
                              Step step) {
  std::vector<double> times;
  std::vector<double> next(u.size());
  for (long n = 0; n * dt < t_end; ++n) {
    step(u, next);
    if (u[s] < level && next[s] >= level)
      times.push_back((n + (level - u[s]) / (next[s] - u[s])) * dt);
    u.swap(next);
  }
  return times;
}

double late_period(const std::vector<double>& t) {
  EXPECT_GE(t.size(), 4u);
  if (t.size() < 4) return 0;
  return (t.back() - t[t.size() - 4]) / 3;
}

TEST(ThreeLayerOregonator, PeriodMatchesHighAccuracyReference) {
  const Deck deck = load_deck();
  const ModelInfo& m = deck.model;
  ASSERT_EQ(m.nspecies, 5);
  const double* p = deck.params.data();
  const std::vector<double> u0 = {0.2, 0.1, 0.05, 0.1, 0.2};
  const int d = 3;
  const double href = 2e-5;
  auto rk4 = [&](const std::vector<double>& u, std::vector<double>& v) {
    double k[4][5], w[5];
    m.rates(u.data(), p, k[0]);
    for (int stage = 1; stage < 4; ++stage) {
      const double c = stage == 3 ? href : 0.5 * href;
      for (int s = 0; s < 5; ++s)
        w[s] = u[s] + c * k[stage - 1][s];
      m.rates(w, p, k[stage]);
    }
    for (int s = 0; s < 5; ++s)
      v[s] = u[s] + href / 6 * (k[0][s] + 2 * k[1][s] + 2 * k[2][s] + k[3][s]);
  };
  const double ref = late_period(crossings(u0, href, 40.0, d, 0.3, rk4));

  const ModelKernels k = runtime_model_kernels(m);
  const double floor[5] = {0, 0, 0, 0, 0};
  auto euler = [&](const std::vector<double>& u, std::vector<double>& v) {
    const double* in[5];
    double* out[5];
    for (int s = 0; s < 5; ++s)
      in[s] = &u[s], out[s] = &v[s];
    CellSolve w{};
    ASSERT_EQ(k.reaction_row[0](ReactionScheme::Euler, 1, in, nullptr, p, nullptr, nullptr, deck.dt,
                                1e-10, 1, floor, out, &w),
              -1);
  };
  const double got = late_period(crossings(u0, deck.dt, 40.0, d, 0.3, euler));
  std::printf("three-layer Oregonator period: reference %.6f, kernel %.6f (relative %.2e)\n", ref,
              got, std::fabs(got - ref) / ref);
  EXPECT_GT(ref, 1.0);
  EXPECT_NEAR(got, ref, 0.01 * ref) << "reference period " << ref << ", kernel " << got;
}

} // namespace
