// Time-series classification: steady, periodic (autocorrelation), drifting, chaotic; and the
// verdict of a run from its sampled mean, standard deviation, change norm and point probe.
// Definitions and thresholds in time_series.hpp.
#include "analysis/time_series.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace morphogen::analysis {

const char* to_string(SeriesBehaviour b) {
  switch (b) {
  case SeriesBehaviour::insufficient:
    return "insufficient";
  case SeriesBehaviour::nonfinite:
    return "nonfinite";
  case SeriesBehaviour::steady:
    return "steady";
  case SeriesBehaviour::periodic:
    return "periodic";
  case SeriesBehaviour::drifting:
    return "drifting";
  case SeriesBehaviour::chaotic:
    return "chaotic";
  }
  return "?";
}

const char* to_string(RunBehaviour b) {
  switch (b) {
  case RunBehaviour::insufficient:
    return "insufficient";
  case RunBehaviour::blowup:
    return "blowup";
  case RunBehaviour::stationary:
    return "stationary";
  case RunBehaviour::transient:
    return "transient";
  case RunBehaviour::oscillating:
    return "oscillating";
  case RunBehaviour::chaotic:
    return "chaotic";
  }
  return "?";
}

namespace {

// Window resampled onto a uniform grid of the same number of points.
std::vector<double> resample_uniform(const double* t, const double* x, std::size_t n) {
  std::vector<double> y(n);
  const double t0 = t[0], t1 = t[n - 1];
  std::size_t s = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double tk = (k + 1 == n) ? t1 : t0 + (t1 - t0) * static_cast<double>(k) / (n - 1);
    while (s + 2 < n && t[s + 1] < tk)
      ++s;
    const double f = (tk - t[s]) / (t[s + 1] - t[s]);
    y[k] = x[s] + std::clamp(f, 0.0, 1.0) * (x[s + 1] - x[s]);
  }
  return y;
}

struct Line {
  double a = 0, b = 0; // y = a + b k
};

Line fit_line(const std::vector<double>& y) {
  const double n = static_cast<double>(y.size());
  double sk = 0, sy = 0, skk = 0, sky = 0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    const double kk = static_cast<double>(k);
    sk += kk;
    sy += y[k];
    skk += kk * kk;
    sky += kk * y[k];
  }
  const double den = n * skk - sk * sk;
  Line L;
  L.b = den != 0 ? (n * sky - sk * sy) / den : 0.0;
  L.a = (sy - L.b * sk) / n;
  return L;
}

// Pearson correlation of y[0, n - lag) with y[lag, n).
double autocorrelation(const std::vector<double>& y, std::size_t lag) {
  const std::size_t m = y.size() - lag;
  double ma = 0, mb = 0;
  for (std::size_t k = 0; k < m; ++k) {
    ma += y[k];
    mb += y[k + lag];
  }
  ma /= m;
  mb /= m;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t k = 0; k < m; ++k) {
    const double a = y[k] - ma, b = y[k + lag] - mb;
    sab += a * b;
    saa += a * a;
    sbb += b * b;
  }
  return (saa > 0 && sbb > 0) ? sab / std::sqrt(saa * sbb) : 0.0;
}

// Sign of successive differences: +1 / -1 if monotone (ignoring |d| <= tol), 0 otherwise.
int monotone_sign(const std::vector<double>& y, double tol) {
  int sign = 0;
  for (std::size_t k = 1; k < y.size(); ++k) {
    const double d = y[k] - y[k - 1];
    if (std::fabs(d) <= tol) continue;
    const int s = d > 0 ? 1 : -1;
    if (sign == 0) sign = s;
    if (s != sign) return 0;
  }
  return sign == 0 ? 1 : sign;
}

// Converging monotone window: the extrapolated remaining change, or +inf if not decaying.
double remaining_change(const std::vector<double>& y, double tol) {
  std::vector<double> k, l;
  for (std::size_t i = 1; i < y.size(); ++i) {
    const double d = std::fabs(y[i] - y[i - 1]);
    if (d > tol) {
      k.push_back(static_cast<double>(i));
      l.push_back(std::log(d));
    }
  }
  if (k.size() < 3) return 0.0; // (nearly) constant
  const double n = static_cast<double>(k.size());
  double sk = 0, sl = 0, skk = 0, skl = 0;
  for (std::size_t i = 0; i < k.size(); ++i) {
    sk += k[i];
    sl += l[i];
    skk += k[i] * k[i];
    skl += k[i] * l[i];
  }
  const double b = (n * skl - sk * sl) / (n * skk - sk * sk);
  const double a = (sl - b * sk) / n;
  if (!(b < 0)) return INFINITY;
  const double q = std::exp(b);
  const double d_last = std::exp(a + b * static_cast<double>(y.size() - 1));
  return d_last * q / (1 - q);
}

struct PeriodEstimate {
  bool found = false;
  double lag = 0, acf = 0, best = 0;
};

double parabola_offset(double rm, double r0, double rp) {
  const double den = rm - 2 * r0 + rp;
  return den < 0 ? std::clamp(0.5 * (rm - rp) / den, -0.5, 0.5) : 0.0;
}

PeriodEstimate find_period(const std::vector<double>& y) {
  PeriodEstimate e;
  const std::size_t maxlag = y.size() / 2;
  if (maxlag < 2) return e;
  std::vector<double> r(maxlag + 1, 1.0);
  for (std::size_t lag = 1; lag <= maxlag; ++lag)
    r[lag] = autocorrelation(y, lag);
  std::size_t zero = 0;
  for (std::size_t lag = 1; lag <= maxlag && zero == 0; ++lag)
    if (r[lag] <= 0) zero = lag;
  if (zero == 0) return e;
  double best = -1;
  for (std::size_t lag = zero + 1; lag <= maxlag; ++lag)
    best = std::max(best, r[lag]);
  e.best = std::max(best, 0.0);
  if (best < kPeriodicMinAcf) return e;
  auto local_max = [&](std::size_t lag) {
    return r[lag] >= r[lag - 1] && (lag == maxlag || r[lag] >= r[lag + 1]);
  };
  std::size_t first = 0;
  for (std::size_t lag = zero + 1; lag <= maxlag && first == 0; ++lag)
    if (local_max(lag) && r[lag] >= kPeriodicMinAcf) first = lag;
  auto refine = [&](std::size_t lag) {
    return lag < maxlag ? lag + parabola_offset(r[lag - 1], r[lag], r[lag + 1])
                        : static_cast<double>(lag);
  };
  // Every multiple M P of the period that fits (peak window within the lags) must still be a
  // peak >= kPeriodicMinAcf, and at least two must fit: a chaotic signal with a dominant
  // frequency loses its phase and its autocorrelation envelope decays. The highest multiple
  // gives the finest estimate, lag_M / M.
  double period = refine(first);
  e.acf = r[first];
  int multiples = 1;
  for (int M = 2;; ++M) {
    const double target = M * period;
    const double half = std::max(1.0, 0.25 * period);
    const long lo = std::lround(target - half), hi = std::lround(target + half);
    if (hi >= static_cast<long>(maxlag) || lo < 1) break;
    std::size_t at = static_cast<std::size_t>(lo);
    for (long lag = lo; lag <= hi; ++lag)
      if (r[static_cast<std::size_t>(lag)] > r[at]) at = static_cast<std::size_t>(lag);
    if (r[at] < kPeriodicMinAcf) return e; // decayed: not periodic
    period = refine(at) / M;
    multiples = M;
  }
  if (multiples < 2) return e; // too few periods in the window to tell
  e.found = true;
  e.lag = period;
  return e;
}

} // namespace

SeriesAnalysis analyse_series(const double* t, const double* x, std::size_t n, double scale) {
  SeriesAnalysis a;
  for (std::size_t k = 0; k < n; ++k)
    if (!std::isfinite(x[k]) || !std::isfinite(t[k])) {
      a.behaviour = SeriesBehaviour::nonfinite;
      return a;
    }
  for (std::size_t k = 1; k < n; ++k)
    if (!(t[k] > t[k - 1]))
      throw std::invalid_argument("analyse_series: sample times must be strictly increasing");
  double sc = std::max(scale, 1e-300);
  for (std::size_t k = 0; k < n; ++k)
    sc = std::max(sc, std::fabs(x[k]));
  a.scale = sc;
  if (n < kMinSamples) return a;

  const std::size_t w = n / 2, first = n - w;
  a.window = w;
  const std::vector<double> y = resample_uniform(t + first, x + first, w);
  const double dt = (t[n - 1] - t[first]) / static_cast<double>(w - 1);
  const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
  a.window_range = (*hi - *lo) / sc;

  const Line L = fit_line(y);
  std::vector<double> res(w);
  double ss = 0;
  for (std::size_t k = 0; k < w; ++k) {
    res[k] = y[k] - (L.a + L.b * static_cast<double>(k));
    ss += res[k] * res[k];
  }
  a.residual = std::sqrt(ss / static_cast<double>(w)) / sc;

  const double tol = 1e-12 * sc;
  const bool monotone = monotone_sign(y, tol) != 0;
  if (a.window_range <= kSteadyRelRange ||
      (monotone && remaining_change(y, tol) <= kSteadyRelRange * sc)) {
    a.behaviour = SeriesBehaviour::steady;
    return a;
  }
  const PeriodEstimate p = find_period(res);
  a.acf_peak = p.found ? p.acf : p.best;
  if (p.found) {
    a.behaviour = SeriesBehaviour::periodic;
    a.period = p.lag * dt;
    return a;
  }
  const double rise = std::fabs(L.b) * static_cast<double>(w - 1);
  if (monotone || a.residual * sc <= kDriftMaxResidual * rise) {
    a.behaviour = SeriesBehaviour::drifting;
    return a;
  }
  a.behaviour = SeriesBehaviour::chaotic;
  return a;
}

namespace {

// The samples whose time exceeds every earlier one (a repeated or earlier time, e.g. after a
// restart, is dropped). NaN times are kept (they make the run a blowup).
RunSamples increasing_times(const RunSamples& s) {
  RunSamples r;
  double last = -INFINITY;
  for (std::size_t k = 0; k < s.t.size(); ++k) {
    if (std::isfinite(s.t[k]) && !(s.t[k] > last)) continue;
    if (std::isfinite(s.t[k])) last = s.t[k];
    r.t.push_back(s.t[k]);
    for (auto [from, to] : {std::pair{&s.mean, &r.mean}, std::pair{&s.stddev, &r.stddev},
                            std::pair{&s.change, &r.change}, std::pair{&s.probe, &r.probe}})
      if (!from->empty()) to->push_back((*from)[k]);
  }
  return r;
}

} // namespace

RunVerdict classify_run(const RunSamples& samples) {
  for (const auto* ch : {&samples.mean, &samples.stddev, &samples.change, &samples.probe})
    if (!ch->empty() && ch->size() != samples.t.size())
      throw std::invalid_argument("classify_run: every non-empty channel needs one value per time");
  const RunSamples s = increasing_times(samples);
  const std::size_t n = s.t.size();
  RunVerdict v;
  auto finite = [](const std::vector<double>& c, std::size_t from) {
    for (std::size_t k = from; k < c.size(); ++k)
      if (!std::isfinite(c[k])) return false;
    return true;
  };
  if (!finite(s.t, 0) || !finite(s.mean, 0) || !finite(s.stddev, 0) || !finite(s.probe, 0) ||
      !finite(s.change, 1)) {
    v.behaviour = RunBehaviour::blowup;
    return v;
  }
  if (n < kMinSamples) return v;
  const std::size_t first = n - n / 2; // the analysis window [first, n)

  // Field magnitude per sample (0 where mean and stddev are not given).
  std::vector<double> rms(n, 0.0);
  double scale = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double m = s.mean.empty() ? 0.0 : s.mean[k], d = s.stddev.empty() ? 0.0 : s.stddev[k];
    rms[k] = std::sqrt(m * m + d * d);
    scale = std::max(scale, rms[k]);
  }
  // Spatial standard deviation over the window (median), the yardstick of change.
  if (!s.stddev.empty()) {
    std::vector<double> sd(s.stddev.begin() + static_cast<std::ptrdiff_t>(first), s.stddev.end());
    const auto mid = sd.begin() + static_cast<std::ptrdiff_t>(sd.size() / 2);
    std::nth_element(sd.begin(), mid, sd.end());
    v.spatial_std = *mid;
  }
  auto yardstick = [&](std::size_t k) {
    const double floor = std::max(1e-6 * scale, 1e-300);
    if (!s.stddev.empty()) return std::max(s.stddev[k], floor);
    return scale > 0 ? std::max(rms[k], floor) : 1.0;
  };

  std::vector<SeriesAnalysis*> channels;
  if (!s.mean.empty()) {
    v.mean = analyse_series(s.t.data(), s.mean.data(), n, scale);
    channels.push_back(&v.mean);
  }
  if (!s.stddev.empty()) {
    v.stddev = analyse_series(s.t.data(), s.stddev.data(), n, scale);
    channels.push_back(&v.stddev);
  }
  if (!s.probe.empty()) {
    v.probe = analyse_series(s.t.data(), s.probe.data(), n, scale);
    channels.push_back(&v.probe);
  }

  const bool have_change = !s.change.empty();
  if (have_change) {
    std::vector<double> c;
    for (std::size_t k = std::max<std::size_t>(first, 1); k < n; ++k) {
      c.push_back(s.change[k] / yardstick(k));
      v.path += c.back();
    }
    const auto mid = c.begin() + static_cast<std::ptrdiff_t>(c.size() / 2);
    std::nth_element(c.begin(), mid, c.end());
    v.late_change = *mid;
    v.moving = v.path >= kMovingPath;
  }
  const bool motion_ok = !have_change || v.moving;
  // A periodic channel counts when its oscillation is a sizeable fraction of the spatial
  // variation (or the field is uniform in space).
  const bool uniform_in_space = !s.stddev.empty() && v.spatial_std <= 1e-6 * scale;
  auto significant = [&](const SeriesAnalysis& a) {
    if (a.behaviour != SeriesBehaviour::periodic) return false;
    if (s.stddev.empty() || uniform_in_space) return true;
    return a.residual * a.scale >= kMinOscillation * v.spatial_std;
  };
  bool all_steady = !channels.empty(), any_chaotic = false;
  for (const auto* c : channels) {
    all_steady = all_steady && c->behaviour == SeriesBehaviour::steady;
    any_chaotic = any_chaotic || c->behaviour == SeriesBehaviour::chaotic;
  }
  const SeriesAnalysis* periodic = nullptr;
  for (const auto* c : {&v.probe, &v.mean, &v.stddev})
    if (!periodic && significant(*c)) periodic = c;

  if (motion_ok && periodic) {
    v.behaviour = RunBehaviour::oscillating;
    v.period = periodic->period;
  } else if (v.moving && all_steady) {
    v.behaviour = RunBehaviour::oscillating;
  } else if (motion_ok && any_chaotic) {
    v.behaviour = RunBehaviour::chaotic;
  } else if (v.moving || !all_steady) {
    v.behaviour = RunBehaviour::transient;
  } else {
    v.behaviour = RunBehaviour::stationary;
  }
  return v;
}

} // namespace morphogen::analysis
