// Automatic pattern classification of a run from the metrics of its final field
// (pattern_metrics.hpp) and, when sampled, the verdict on its time series (time_series.hpp).
// Pure functions: no PETSc, no MPI.
//
// Classes, with the names written to CSV / JSON: "uniform", "spots", "holes", "stripes",
// "labyrinth", "mixed", "oscillating", "chaotic", "blowup". The rules, applied in this order
// (the first that holds gives the class; the same text is in README.md, "Pattern classes"):
//
//  1. blowup       the final field has a NaN or infinite value, or max |u| > bound (default
//                  kBlowupBound = 1e10), or a sampled channel has a NaN or infinite value.
//  2. chaotic      the run's time series (time_series.hpp) is chaotic: the field keeps moving
//                  (its accumulated change over the last half of the samples is >= 10
//                  spatial standard deviations) and a sampled channel fluctuates without a
//                  phase-stable period.
//  3. oscillating  the run's time series oscillates: the field keeps moving and a sampled
//                  channel is periodic (autocorrelation >= 0.5 at every multiple of the
//                  period, over >= 4 periods) with an amplitude >= 0.1 of the field's spatial
//                  standard deviation (period reported), or the field keeps moving while its
//                  sampled statistics stay constant (a travelling or rotating wave).
//  4. uniform      (max - min) <= kUniformRelRange = 1e-3 (|mean| + 1e-12), or at least
//                  kGridNoiseFraction = 0.5 of the spectral power is at wavelengths under
//                  about 4 cells (unstructured grid-scale noise, no pattern).
//  5. spots        at least kSpotsMinAreaFraction = 0.8 of the high phase's area (specks of
//                  <= 2 cells excluded) lies in spots: compact components that do not wrap
//                  around the torus, with principal-axis ratio <= 2 and fill of their moment
//                  ellipse >= 0.6 and area <= 2 wavelength^2 (rings, arcs and branched shapes
//                  are not spots), and there are at least kMinSpots = 2 of them. If the low
//                  phase also qualifies, the phase with the smaller area is the spot phase.
//  6. holes        the same for the low phase (spots of low values in a high network).
//  7. stripes      neither phase has more than kStripesMaxSpotFraction = 0.2 of its area in
//                  spots (both are elongated, wrapping or branched), and the spectral
//                  anisotropy |sum P e^{2i theta}| / sum P over the annulus of the dominant
//                  wavelength is >= kStripesMinAnisotropy = 0.5 (one orientation dominates).
//  8. labyrinth    as stripes, but anisotropy < 0.5 (meandering bands of all orientations).
//  9. mixed        any other pattern (e.g. spots and stripes side by side, spots among worms,
//                  rings).
//
// Without a time series (run == nullptr, or a verdict of stationary, transient or
// insufficient) rules 2-3 do not apply: the final field alone decides. "spots" / "holes"
// refer to the field given: in a species that is low where the other is high the same pattern
// is "holes".
#pragma once

#include "analysis/pattern_metrics.hpp"
#include "analysis/time_series.hpp"

#include <optional>
#include <string>
#include <string_view>

namespace morphogen::analysis {

inline constexpr double kBlowupBound = 1e10;
inline constexpr double kUniformRelRange = 1e-3;
inline constexpr double kGridNoiseFraction = 0.5;
inline constexpr double kSpotsMinAreaFraction = 0.8;
inline constexpr int kMinSpots = 2;
inline constexpr double kStripesMaxSpotFraction = 0.2;
inline constexpr double kStripesMinAnisotropy = 0.5;

enum class PatternClass {
  uniform,
  spots,
  holes,
  stripes,
  labyrinth,
  mixed,
  oscillating,
  chaotic,
  blowup
};

// "uniform", "spots", ...; and back (nullopt for an unknown name).
const char* to_string(PatternClass c);
std::optional<PatternClass> pattern_class_from_string(std::string_view name);

struct Classification {
  PatternClass cls = PatternClass::uniform;
  std::string reason;    // one line: the rule that decided and its numbers
  double wavelength = 0; // dominant wavelength, physical units (0 if none)
  double period = 0;     // oscillating: period in time units (0 if unknown)
  int spots = 0;         // spots: spot count of the spot phase; holes: hole count
  double spot_area = 0;  // spots/holes: mean spot area, physical units
};

// final_field: metrics of the run's last field; run: its time-series verdict or nullptr.
Classification classify(const PatternMetrics& final_field, const RunVerdict* run = nullptr,
                        double bound = kBlowupBound);

} // namespace morphogen::analysis
