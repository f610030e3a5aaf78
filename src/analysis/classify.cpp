// Pattern classification rules (documented in classify.hpp and README.md).
#include "analysis/classify.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace morphogen::analysis {

namespace {

constexpr std::array<const char*, 9> kNames = {"uniform",     "spots",     "holes",
                                               "stripes",     "labyrinth", "mixed",
                                               "oscillating", "chaotic",   "blowup"};

std::string format(const char* fmt, double a, double b = 0, double c = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

bool spot_phase(const PhaseMetrics& p) {
  return p.spots >= kMinSpots && p.spot_area_fraction >= kSpotsMinAreaFraction;
}

} // namespace

const char* to_string(PatternClass c) {
  return kNames[static_cast<std::size_t>(c)];
}

std::optional<PatternClass> pattern_class_from_string(std::string_view name) {
  for (std::size_t k = 0; k < kNames.size(); ++k)
    if (name == kNames[k]) return static_cast<PatternClass>(k);
  return std::nullopt;
}

Classification classify(const PatternMetrics& m, const RunVerdict* run, double bound) {
  Classification c;
  c.wavelength = m.wavelength;
  auto set = [&c](PatternClass cls, std::string reason) {
    c.cls = cls;
    c.reason = std::move(reason);
    return c;
  };
  if (!m.finite)
    return set(PatternClass::blowup, format("%.0f non-finite values in the final field",
                                            static_cast<double>(m.nonfinite)));
  const double peak = std::max(std::fabs(m.min), std::fabs(m.max));
  if (peak > bound)
    return set(PatternClass::blowup, format("max |u| = %g > bound %g", peak, bound));
  if (run && run->behaviour == RunBehaviour::blowup)
    return set(PatternClass::blowup, "non-finite value in the sampled time series");
  if (run && run->behaviour == RunBehaviour::chaotic)
    return set(PatternClass::chaotic,
               format("moving (path %.3g spatial std over the window) and fluctuating without "
                      "a stable period (autocorrelation peak of mean %.2f, stddev %.2f)",
                      run->path, run->mean.acf_peak, run->stddev.acf_peak));
  if (run && run->behaviour == RunBehaviour::oscillating) {
    c.period = run->period;
    return set(PatternClass::oscillating,
               run->period > 0
                   ? format("periodic time series, period %g (path %.3g spatial std over the "
                            "window)",
                            run->period, run->path)
                   : format("field keeps moving (path %.3g spatial std over the window) while its "
                            "statistics are steady: travelling or rotating wave",
                            run->path));
  }
  if (m.range_rel <= kUniformRelRange)
    return set(PatternClass::uniform,
               format("(max - min) / |mean| = %.2g <= %g", m.range_rel, kUniformRelRange));
  if (m.gridscale_power_fraction >= kGridNoiseFraction)
    return set(PatternClass::uniform,
               format("grid-scale noise: %.2f of the power at wavelengths under 4 cells",
                      m.gridscale_power_fraction));

  const bool hi_spots = spot_phase(m.high), lo_spots = spot_phase(m.low);
  if (hi_spots && (!lo_spots || m.high.area_fraction <= m.low.area_fraction)) {
    c.spots = m.high.spots;
    c.spot_area = m.high.spot_area;
    return set(PatternClass::spots,
               format("%.0f spots of high values, %.2f of the high phase's area in spots",
                      m.high.spots, m.high.spot_area_fraction));
  }
  if (lo_spots) {
    c.spots = m.low.spots;
    c.spot_area = m.low.spot_area;
    return set(PatternClass::holes,
               format("%.0f holes (spots of low values), %.2f of the low phase's area in spots",
                      m.low.spots, m.low.spot_area_fraction));
  }
  if (m.high.spot_area_fraction <= kStripesMaxSpotFraction &&
      m.low.spot_area_fraction <= kStripesMaxSpotFraction) {
    if (m.spectral_anisotropy >= kStripesMinAnisotropy)
      return set(PatternClass::stripes,
                 format("elongated phases (spot area fractions %.2f, %.2f), spectral "
                        "anisotropy %.2f",
                        m.high.spot_area_fraction, m.low.spot_area_fraction,
                        m.spectral_anisotropy));
    return set(PatternClass::labyrinth,
               format("elongated phases (spot area fractions %.2f, %.2f), spectral anisotropy "
                      "%.2f",
                      m.high.spot_area_fraction, m.low.spot_area_fraction, m.spectral_anisotropy));
  }
  return set(PatternClass::mixed,
             format("spot area fractions %.2f (high), %.2f (low): neither spots nor stripes",
                    m.high.spot_area_fraction, m.low.spot_area_fraction));
}

} // namespace morphogen::analysis
