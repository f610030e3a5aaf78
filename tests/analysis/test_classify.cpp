// Serial tests for src/analysis/time_series and src/analysis/classify: synthetic fields and
// time series with a known class.
//
// Fields: hexagonal spots (three cosines on a 128 x 148 torus, 64 spots, wavelength 16 cells:
// see synthetic_fields.hpp), their negative (holes), stripes along and oblique to the axes,
// a labyrinth (hash noise band-passed to |k| within 15 % of 16 cycles per 256 cells, then
// tanh), a half-spots half-stripes mixture, a uniform field with and without tiny noise, and
// a NaN. Series: a travelling wave cos(kx - wt) (point probe, mean of half the domain),
// the logistic map at r = 3.9, relaxing exponentials, a linear drift, a NaN.
// Tolerances: wavelength 3 %, spot counts exact, periods 5 % (the estimator is far better).
#include "analysis/classify.hpp"
#include "core/hash_rng.hpp"
#include "synthetic_fields.hpp"

#include <fftw3.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace morphogen::analysis;
using namespace morphogen::testing;

namespace {

// Hash noise band-passed to |k| in [0.85, 1.15] * 16 cycles per 256 cells, then tanh(3 u / std).
Field labyrinth(std::uint64_t seed) {
  const int n = 256, nc = n / 2 + 1;
  Field f = make(n, n);
  std::vector<double> re(static_cast<std::size_t>(n) * n);
  std::vector<fftw_complex> spec(static_cast<std::size_t>(nc) * n);
  for (std::size_t c = 0; c < re.size(); ++c)
    re[c] = morphogen::rng::uniform(seed, 7, c) - 0.5;
  fftw_plan fwd = fftw_plan_dft_r2c_2d(n, n, re.data(), spec.data(), FFTW_ESTIMATE);
  fftw_execute(fwd);
  fftw_destroy_plan(fwd);
  for (int q = 0; q < n; ++q)
    for (int m = 0; m < nc; ++m) {
      const double k = std::hypot(m, q <= n / 2 ? q : q - n);
      if (k < 0.85 * 16 || k > 1.15 * 16) spec[m + nc * q][0] = spec[m + nc * q][1] = 0;
    }
  fftw_plan inv = fftw_plan_dft_c2r_2d(n, n, spec.data(), re.data(), FFTW_ESTIMATE);
  fftw_execute(inv);
  fftw_destroy_plan(inv);
  double ss = 0;
  for (double v : re)
    ss += v * v;
  const double sd = std::sqrt(ss / re.size());
  for (std::size_t c = 0; c < re.size(); ++c)
    f.u[c] = std::tanh(3 * re[c] / sd);
  return f;
}

Classification classify_field(const Field& f, const RunVerdict* run = nullptr) {
  return classify(compute_pattern_metrics(f.u.data(), f.shape), run);
}

// Samples t_n = n dt of a travelling wave u = cos(k x - w t) on 64 cells (k: 3 waves per
// domain), with the mean over the left half as "mean", the full std, the RMS change since the
// previous sample and a point probe.
RunSamples travelling_wave(double period, double dt, int samples) {
  const int n = 64;
  const double k = 2 * kPi * 3 / n, w = 2 * kPi / period;
  RunSamples s;
  std::vector<double> prev(n), cur(n);
  for (int s_i = 0; s_i < samples; ++s_i) {
    const double t = s_i * dt;
    double half = 0, sum = 0, sumsq = 0, dsq = 0;
    for (int i = 0; i < n; ++i) {
      cur[i] = std::cos(k * (i + 0.5) - w * t);
      if (i < n / 2) half += cur[i];
      sum += cur[i];
      sumsq += cur[i] * cur[i];
      dsq += (cur[i] - prev[i]) * (cur[i] - prev[i]);
    }
    const double mean = sum / n;
    s.t.push_back(t);
    s.mean.push_back(half / (n / 2));
    s.stddev.push_back(std::sqrt(sumsq / n - mean * mean));
    s.change.push_back(s_i == 0 ? 0.0 : std::sqrt(dsq / n));
    s.probe.push_back(cur[10]);
    prev = cur;
  }
  return s;
}

} // namespace

// ---- Fields ------------------------------------------------------------------------------

TEST(Classify, HexagonalSpots) {
  const Classification c = classify_field(hexagonal());
  EXPECT_EQ(c.cls, PatternClass::spots) << c.reason;
  EXPECT_EQ(c.spots, 64);
  EXPECT_NEAR(c.wavelength, 16.0, 0.03 * 16.0);
  Field binary = hexagonal();
  for (double& v : binary.u)
    v = v > 0.75 ? 1.0 : 0.0;
  const Classification cb = classify_field(binary);
  EXPECT_EQ(cb.cls, PatternClass::spots) << cb.reason;
  EXPECT_EQ(cb.spots, 64);
  EXPECT_NEAR(cb.wavelength, 16.0, 0.03 * 16.0);
}

TEST(Classify, HexagonalSpotsInAClosedBox) {
  Field f = hexagonal();
  f.shape.periodic_x = f.shape.periodic_y = false;
  const Classification c = classify_field(f);
  EXPECT_EQ(c.cls, PatternClass::spots) << c.reason;
  EXPECT_NEAR(c.wavelength, 16.0, 0.03 * 16.0);
}

TEST(Classify, NegatedSpotsAreHoles) {
  Field f = hexagonal();
  for (double& v : f.u)
    v = 5.0 - v; // positive mean, like a concentration
  const Classification c = classify_field(f);
  EXPECT_EQ(c.cls, PatternClass::holes) << c.reason;
  EXPECT_EQ(c.spots, 64);
  EXPECT_NEAR(c.wavelength, 16.0, 0.03 * 16.0);
}

TEST(Classify, Stripes) {
  for (auto [a, b] : {std::pair{8, 0}, std::pair{0, 8}, std::pair{3, 4}, std::pair{5, -5}}) {
    const Classification c = classify_field(stripes(128, a, b));
    EXPECT_EQ(c.cls, PatternClass::stripes) << a << "," << b << ": " << c.reason;
    const double lambda = 128 / std::hypot(a, b);
    EXPECT_NEAR(c.wavelength, lambda, 0.03 * lambda) << a << "," << b;
  }
}

TEST(Classify, Labyrinth) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const Field f = labyrinth(seed);
    const PatternMetrics m = compute_pattern_metrics(f.u.data(), f.shape);
    const Classification c = classify(m);
    EXPECT_EQ(c.cls, PatternClass::labyrinth) << "seed " << seed << ": " << c.reason;
    EXPECT_NEAR(m.wavelength_cells, 16.0, 0.03 * 16.0) << "seed " << seed;
    EXPECT_GT(m.coherence, 0.3) << "seed " << seed; // locally stripe-like (spots: < 0.1)
  }
}

TEST(Classify, UniformAndTinyNoise) {
  Field f = make(64, 64);
  for (double& v : f.u)
    v = 0.42;
  EXPECT_EQ(classify_field(f).cls, PatternClass::uniform);
  for (std::size_t c = 0; c < f.u.size(); ++c)
    f.u[c] = 0.42 * (1 + 1e-6 * (morphogen::rng::uniform(5, 1, c) - 0.5));
  EXPECT_EQ(classify_field(f).cls, PatternClass::uniform) << classify_field(f).reason;
  // Larger, but unstructured (cell-to-cell) noise: no pattern either.
  for (std::size_t c = 0; c < f.u.size(); ++c)
    f.u[c] = 0.42 * (1 + 0.05 * (morphogen::rng::uniform(5, 2, c) - 0.5));
  const Classification c = classify_field(f);
  EXPECT_EQ(c.cls, PatternClass::uniform) << c.reason;
}

TEST(Classify, HalfSpotsHalfStripesIsMixed) {
  Field f = hexagonal();
  for (int j = 0; j < 148; ++j)
    for (int i = 64; i < 128; ++i)
      f.at(i, j) = 0.75 + 2.25 * std::cos(2 * kPi * 8 * (i + 0.5) / 128); // same range
  const Classification c = classify_field(f);
  EXPECT_EQ(c.cls, PatternClass::mixed) << c.reason;
  EXPECT_NEAR(c.wavelength, 16.0, 0.03 * 16.0);
}

TEST(Classify, NonFiniteOrUnboundedFieldIsBlowup) {
  Field f = hexagonal();
  f.at(3, 4) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(classify_field(f).cls, PatternClass::blowup);
  f.at(3, 4) = 1e12;
  EXPECT_EQ(classify_field(f).cls, PatternClass::blowup);
  EXPECT_NE(classify(compute_pattern_metrics(f.u.data(), f.shape), nullptr, 1e13).cls,
            PatternClass::blowup);
}

TEST(Classify, ClassNamesRoundTrip) {
  const char* names[] = {"uniform", "spots",       "holes",   "stripes", "labyrinth",
                         "mixed",   "oscillating", "chaotic", "blowup"};
  for (const char* name : names) {
    const auto c = pattern_class_from_string(name);
    ASSERT_TRUE(c.has_value()) << name;
    EXPECT_EQ(std::string(to_string(*c)), name);
  }
  EXPECT_FALSE(pattern_class_from_string("spirals").has_value());
}

// ---- Single time series --------------------------------------------------------------------

TEST(TimeSeries, SineGivesItsPeriod) {
  std::vector<double> t(400), x(400);
  for (int n = 0; n < 400; ++n) {
    t[n] = 0.5 * n;
    x[n] = 3 + std::sin(2 * kPi * t[n] / 10.185) + 0.01 * t[n]; // with a slow linear drift
  }
  const SeriesAnalysis a = analyse_series(t.data(), x.data(), t.size());
  EXPECT_EQ(a.behaviour, SeriesBehaviour::periodic) << to_string(a.behaviour);
  EXPECT_NEAR(a.period, 10.185, 0.05 * 10.185);
  EXPECT_NEAR(a.period, 10.185, 0.005 * 10.185); // the estimator does better than the spec
  EXPECT_GT(a.acf_peak, 0.95);
}

TEST(TimeSeries, RelaxingExponentialsAreSteady) {
  std::vector<double> t(100), x(100), y(100);
  for (int n = 0; n < 100; ++n) {
    t[n] = 0.1 * n;
    x[n] = 1 + std::exp(-t[n]); // window range 3e-3 of the scale: steady by convergence
    y[n] = std::exp(-t[n]);     // decays to 0
  }
  EXPECT_EQ(analyse_series(t.data(), x.data(), 100).behaviour, SeriesBehaviour::steady);
  EXPECT_EQ(analyse_series(t.data(), y.data(), 100).behaviour, SeriesBehaviour::steady);
}

TEST(TimeSeries, LogisticMapIsChaotic) {
  std::vector<double> t(500), x(500);
  double v = 0.3;
  for (int n = 0; n < 500; ++n) {
    t[n] = n;
    x[n] = v;
    v = 3.9 * v * (1 - v);
  }
  const SeriesAnalysis a = analyse_series(t.data(), x.data(), t.size());
  EXPECT_EQ(a.behaviour, SeriesBehaviour::chaotic) << to_string(a.behaviour);
  EXPECT_LT(a.acf_peak, kPeriodicMinAcf);
}

TEST(TimeSeries, LinearRampIsDrifting) {
  std::vector<double> t(50), x(50);
  for (int n = 0; n < 50; ++n) {
    t[n] = n;
    x[n] = 1 + 0.01 * n;
  }
  EXPECT_EQ(analyse_series(t.data(), x.data(), 50).behaviour, SeriesBehaviour::drifting);
}

TEST(TimeSeries, TooShortOrNonFinite) {
  std::vector<double> t(10), x(10, 1.0);
  for (int n = 0; n < 10; ++n)
    t[n] = n;
  EXPECT_EQ(analyse_series(t.data(), x.data(), 10).behaviour, SeriesBehaviour::insufficient);
  x[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(analyse_series(t.data(), x.data(), 10).behaviour, SeriesBehaviour::nonfinite);
  t[4] = t[3];
  x[4] = 1;
  EXPECT_THROW(analyse_series(t.data(), x.data(), 10), std::invalid_argument);
}

// ---- Runs ----------------------------------------------------------------------------------

TEST(ClassifyRun, TravellingWaveOscillatesWithItsPeriod) {
  const double period = 7.3;
  const RunSamples s = travelling_wave(period, 0.25, 1200);
  const RunVerdict v = classify_run(s);
  EXPECT_EQ(v.behaviour, RunBehaviour::oscillating) << to_string(v.behaviour);
  EXPECT_TRUE(v.moving);
  EXPECT_NEAR(v.period, period, 0.05 * period);
  EXPECT_EQ(v.probe.behaviour, SeriesBehaviour::periodic);
  EXPECT_EQ(v.mean.behaviour, SeriesBehaviour::periodic);
  EXPECT_NEAR(v.mean.period, period, 0.05 * period);
  EXPECT_EQ(v.stddev.behaviour, SeriesBehaviour::steady);
  const Classification c =
      classify(compute_pattern_metrics(hexagonal().u.data(), hexagonal().shape), &v);
  EXPECT_EQ(c.cls, PatternClass::oscillating) << c.reason;
  EXPECT_NEAR(c.period, period, 0.05 * period);

  // Without the probe and with the whole-domain mean (constant): the field still moves
  // rigidly, so it is a travelling wave of unknown period.
  RunSamples rigid = s;
  rigid.probe.clear();
  for (double& m : rigid.mean)
    m = 0.0;
  const RunVerdict vr = classify_run(rigid);
  EXPECT_EQ(vr.behaviour, RunBehaviour::oscillating) << to_string(vr.behaviour);
  EXPECT_EQ(vr.period, 0.0);
}

TEST(ClassifyRun, LogisticMapIsChaotic) {
  RunSamples s;
  double v = 0.3, prev = 0.3;
  for (int n = 0; n < 500; ++n) {
    s.t.push_back(n);
    s.mean.push_back(v);
    s.stddev.push_back(0.2 + 0.1 * std::fabs(v - 0.5));
    s.change.push_back(n == 0 ? 0.0 : std::fabs(v - prev));
    prev = v;
    v = 3.9 * v * (1 - v);
  }
  const RunVerdict r = classify_run(s);
  EXPECT_EQ(r.behaviour, RunBehaviour::chaotic) << to_string(r.behaviour);
  const Classification c =
      classify(compute_pattern_metrics(hexagonal().u.data(), hexagonal().shape), &r);
  EXPECT_EQ(c.cls, PatternClass::chaotic) << c.reason;
}

TEST(ClassifyRun, RelaxationIsStationaryAndTheFieldDecides) {
  RunSamples s;
  for (int n = 0; n < 200; ++n) {
    const double t = 0.1 * n;
    s.t.push_back(t);
    s.mean.push_back(1 + 0.5 * std::exp(-t / 2));
    s.stddev.push_back(0.3 * (1 - std::exp(-t / 2)));
    s.change.push_back(n == 0 ? 0.0 : 0.5 * std::exp(-t / 2) * (std::exp(0.05) - 1));
  }
  const RunVerdict r = classify_run(s);
  EXPECT_EQ(r.behaviour, RunBehaviour::stationary) << to_string(r.behaviour);
  EXPECT_FALSE(r.moving);
  const Classification c =
      classify(compute_pattern_metrics(hexagonal().u.data(), hexagonal().shape), &r);
  EXPECT_EQ(c.cls, PatternClass::spots) << c.reason;
}

TEST(ClassifyRun, DriftIsTransientAndTheFieldDecides) {
  RunSamples s;
  for (int n = 0; n < 100; ++n) {
    s.t.push_back(n);
    s.mean.push_back(1 + 0.01 * n); // a pattern still invading the domain
    s.stddev.push_back(0.5);
    s.change.push_back(n == 0 ? 0.0 : 0.01);
  }
  const RunVerdict r = classify_run(s);
  EXPECT_EQ(r.behaviour, RunBehaviour::transient) << to_string(r.behaviour);
  EXPECT_EQ(classify_field(stripes(64, 4, 0), &r).cls, PatternClass::stripes);
}

TEST(ClassifyRun, NonFiniteSampleIsBlowup) {
  RunSamples s = travelling_wave(5.0, 0.25, 100);
  s.stddev[60] = std::numeric_limits<double>::infinity();
  const RunVerdict r = classify_run(s);
  EXPECT_EQ(r.behaviour, RunBehaviour::blowup);
  EXPECT_EQ(classify_field(hexagonal(), &r).cls, PatternClass::blowup);
  s.stddev.pop_back();
  EXPECT_THROW(classify_run(s), std::invalid_argument);
}

TEST(ClassifyRun, RepeatedTimesAreDropped) {
  RunSamples s = travelling_wave(7.3, 0.25, 1200);
  // A restart repeats the samples from t = 100 to 150.
  for (auto* ch : {&s.t, &s.mean, &s.stddev, &s.change, &s.probe})
    ch->insert(ch->begin() + 600, ch->begin() + 400, ch->begin() + 600);
  const RunVerdict v = classify_run(s);
  EXPECT_EQ(v.behaviour, RunBehaviour::oscillating) << to_string(v.behaviour);
  EXPECT_NEAR(v.period, 7.3, 0.05 * 7.3);
}
