// Classification of time series of cheap scalar metrics sampled during a run (pure functions
// on plain arrays: no PETSc, no MPI).
//
// One channel (analyse_series): samples x_n at strictly increasing times t_n. The analysis
// window is the last half of the samples (kMinSamples = 16 in all are needed, otherwise
// "insufficient"), resampled linearly onto a uniform grid of as many points.
// scale = max(the scale given, max_n |x_n| over all samples, 1e-300). In this order:
//   nonfinite  any sample is NaN or infinite.
//   steady     (a) max - min over the window <= kSteadyRelRange (1e-3) * scale, or
//              (b) the window is monotone and its successive differences d decay
//                  geometrically (least-squares fit log|d_n| = a + b n, b < 0) with an
//                  extrapolated remaining change |d_last| q / (1 - q), q = e^b, of at most
//                  1e-3 * scale (converging, e.g. 1 + e^-t).
//   periodic   the window minus its least-squares line has a normalised autocorrelation r
//              (Pearson correlation of x[0, N - lag) with x[lag, N), lags up to N/2) whose
//              highest value after its first zero crossing is >= kPeriodicMinAcf (0.5); the
//              period P is the first lag after that crossing where r has a local maximum
//              >= 0.5 (refined by a parabola through three values of r); and r keeps a peak
//              >= 0.5 within +-P/4 of every multiple M P that fits below N/2, of which there
//              must be at least two (the window spans >= 4 periods). A chaotic signal with a
//              dominant frequency loses its phase: its autocorrelation envelope decays below
//              0.5. The period is refined as (peak lag of the highest multiple) / M, times
//              the sample interval.
//   drifting   the window is monotone, or its detrended residual's standard deviation is at
//              most kDriftMaxResidual (0.05) times the fitted line's rise over the window
//              (a transient: growth or slow relaxation still under way).
//   chaotic    everything else: fluctuating without a dominant, phase-stable period.
//
// A run (classify_run): channels sampled at the same times t_n for one species u:
//   mean    the spatial mean of u (or the mean over part of the domain),
//   stddev  the spatial standard deviation of u,
//   change  the RMS over cells of u(t_n) - u(t_{n-1}) (change[0] is ignored),
//   probe   u at one fixed cell.
// Any channel may be empty; a probe is needed to see a rigidly rotating spiral as periodic
// (its mean and standard deviation barely move). mean, stddev and probe are analysed with
// scale = max_n sqrt(mean_n^2 + stddev_n^2) (the field's magnitude, so a mean near 0 is not
// mistaken for a large relative fluctuation). sigma = median of stddev over the window.
//   path    sum over the window of change_n / stddev_n: how far the field travelled, in
//           spatial standard deviations (sampling-independent while the sampling resolves
//           the motion). moving: path >= kMovingPath (10). A settled pattern that only
//           relaxes or rearranges slowly travels ~0.2-4; a spiral or travelling wave hundreds.
//   significant oscillation: a periodic channel whose detrended standard deviation is
//           >= kMinOscillation (0.1) sigma, or any periodic channel when the field is uniform
//           in space (sigma <= 1e-6 scale), or when stddev is not given.
// Verdict, the first rule that holds (rules needing "moving" drop that condition when change
// is not given):
//   blowup       a sample of any channel is NaN or infinite.
//   insufficient fewer than kMinSamples samples.
//   oscillating  moving, and a significant oscillation (period from the first of probe, mean,
//                stddev that has one); or moving while every channel is steady (a rigidly
//                travelling or rotating pattern; period 0 = unknown).
//   chaotic      moving, and a channel is chaotic.
//   transient    moving, or a channel is not steady (drifting, weakly periodic, ...): the
//                final field decides the class.
//   stationary   every channel steady and not moving.
// Sample often enough to resolve the motion (>= ~20 samples per period): a stroboscopic
// sampling interval hides an oscillation.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace morphogen::analysis {

inline constexpr std::size_t kMinSamples = 16;
inline constexpr double kSteadyRelRange = 1e-3;
inline constexpr double kPeriodicMinAcf = 0.5;
inline constexpr double kDriftMaxResidual = 0.05;
inline constexpr double kMovingPath = 10.0;
inline constexpr double kMinOscillation = 0.1;

enum class SeriesBehaviour { insufficient, nonfinite, steady, periodic, drifting, chaotic };
const char* to_string(SeriesBehaviour b);

struct SeriesAnalysis {
  SeriesBehaviour behaviour = SeriesBehaviour::insufficient;
  double scale = 0;        // the scale the tolerances refer to
  double window_range = 0; // (max - min) over the window / scale
  double residual = 0;     // std of the detrended window / scale
  double period = 0;       // time units; periodic only
  double acf_peak = 0;     // autocorrelation at the period's lag (periodic), else the best found
  std::size_t window = 0;  // samples in the analysis window
};

// t, x: n samples, t strictly increasing (std::invalid_argument otherwise). scale: 0 for
// automatic (max |x|), else a lower bound for it.
SeriesAnalysis analyse_series(const double* t, const double* x, std::size_t n, double scale = 0);

struct RunSamples {
  std::vector<double> t, mean, stddev, change, probe;
};

enum class RunBehaviour { insufficient, blowup, stationary, transient, oscillating, chaotic };
const char* to_string(RunBehaviour b);

struct RunVerdict {
  RunBehaviour behaviour = RunBehaviour::insufficient;
  double period = 0;                  // oscillating: time units (0 when unknown)
  bool moving = false;                // path >= kMovingPath (false when change is empty)
  double path = 0;                    // sum of change_n / stddev_n over the window
  double late_change = 0;             // median of change_n / stddev_n over the window
  double spatial_std = 0;             // median stddev over the window (0 when not given)
  SeriesAnalysis mean, stddev, probe; // per channel (probe: insufficient when empty)
};

// Samples whose time does not exceed every earlier one are dropped (a restart may repeat
// times). Throws std::invalid_argument when a non-empty channel's length differs from t's.
RunVerdict classify_run(const RunSamples& s);

} // namespace morphogen::analysis
