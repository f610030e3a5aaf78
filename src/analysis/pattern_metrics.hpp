// Pattern metrics of one 2-D scalar field (pure functions on plain arrays: no PETSc, no MPI).
//
// Input: u[i + nx*j] (row-major, j the slow index, j = 0 the bottom row), nx x ny cells of
// spacing hx, hy, each axis periodic or not. Definitions (all documented again in README.md,
// "Pattern classes"):
//
// Statistics. min, max, mean, stddev (population). p5 / p95: the values at sorted positions
// floor(0.05 (N-1)) and floor(0.95 (N-1)). contrast = (p95 - p5) / (|mean| + 1e-12);
// range_rel = (max - min) / (|mean| + 1e-12).
//
// Spectrum. The field minus its mean is Fourier transformed (FFTW r2c). A non-periodic axis is
// first multiplied by a Hann window w_i = sin^2(pi (i + 1/2) / n) (and the window-weighted mean
// is removed instead), so the jump at the edges does not dominate; the window keeps the
// orientation of the pattern (mirroring would not). Wave vector k = 2 pi (m / Lx, q / Ly),
// L = n h. Modes are binned into rings of width dk = 2 pi / max(Lx, Ly) (ring b holds
// |k| in [(b - 1/2) dk, (b + 1/2) dk)) up to the Nyquist wavenumber of the coarser axis;
// S(b) = mean power of the modes in ring b (the radially averaged power spectrum). The peak ring
// b* maximises S over b >= 1. k_peak: the centroid C(B) = sum_B S(b) kbar(b) / sum_B S(b),
// kbar(b) the power-weighted mean |k| of ring b, first over the rings |b - b*| <= 1
// (postproc/wavelength.py's estimate, with exact ring radii), then twice over the rings with
// b dk in [k_peak / 1.25, 1.25 k_peak] about the previous value (steadier for broad, noisy
// peaks). wavelength = 2 pi / k_peak; wavelength_cells = wavelength / sqrt(hx hy).
//   peak_power_fraction: power with |k| in [k_peak / 1.25, 1.25 k_peak] over all power (DC
//     excluded): near 1 for a single sinusoidal pattern, small for broadband noise.
//   peak_sharpness: k_peak / FWHM of S around b* (half-maximum crossings interpolated
//     linearly between rings): a quality factor, about b* for a pattern that fills one ring.
//   spectral_anisotropy: |sum P e^{2 i theta}| / sum P over the same annulus (theta the angle
//     of k): 1 for parallel stripes, 0 for an isotropic ring (labyrinth) or hexagonal spots.
//   spectral_angle: arg(sum P e^{2 i theta}) / 2 in (-pi/2, pi/2]: the dominant wave vector's
//     direction (stripes run perpendicular to it).
//   gridscale_power_fraction: power at |k| > pi / (2 max(hx, hy)) (wavelengths under about
//     4 cells) over all power: about 0.8 for white noise, tiny for a resolved pattern.
//
// Structure tensor. Gradients by central differences (one-sided at non-periodic edges);
// J = (gx^2, gx gy, gy^2) box-averaged over (2r + 1) cells per axis, r = max(1, round(lambda /
// (2 h))) (half a wavelength), wrapping on periodic axes. coherence = sum sqrt((Jxx - Jyy)^2 +
// 4 Jxy^2) / sum (Jxx + Jyy) over all cells (the trace-weighted mean local coherence): near 1
// where the pattern is locally stripe-like (stripes, labyrinths), lower for spots.
//
// Phases. threshold = (min + max) / 2 (the midrange: robust for sparse spots, where p95 may be
// background). high phase: u > threshold, 4-connected; low phase: u <= threshold, 8-connected
// (the dual pair, so that the phases' topologies are consistent). Connectivity wraps across
// periodic axes. Components are found by union-find that carries each cell's displacement to
// its root in unwrapped coordinates: a component that meets itself with a nonzero displacement
// winds around the torus ("wrapping"; winding_rank 1: in one direction, a stripe; 2: in two
// independent directions, a network). For a non-wrapping component the unwrapped second
// moments (physical units, plus h^2/12 per axis for the cells' own extent) give eigenvalues
// l1 >= l2: elongation = sqrt(l1 / l2) (1 for a disc), fill = area / (4 pi sqrt(l1 l2))
// (1 for a solid ellipse, small for rings and branched shapes). Wrapping components have
// elongation = +inf and fill = 0.
//   speck: a component of at most kSpeckMaxCells cells (ignored in the fractions below).
//   spot: a non-wrapping, non-speck component with elongation <= kSpotMaxElongation,
//     fill >= kSpotMinFill and area <= kSpotMaxAreaWavelengths * wavelength^2 (a spot fits in
//     the unit cell of its pattern; this keeps a closed box's connected background, compact
//     but riddled with holes, from counting as one big spot). Spots of the low phase are
//     holes.
//   elongated: every other non-speck component (wrapping, elongated, ring-like or branched).
//
// Euler characteristic of the high phase (4-connected) as a subset of the torus (or of the
// rectangle, padded with low cells on non-periodic axes), from Gray's local 2x2 quad counts:
// euler = (n1 - n3 + 2 nd) / 4, n1 / n3 the 2x2 blocks with one / three high cells, nd those
// with two diagonal ones. On the torus: #spots for spots, -#holes for holes, 0 for wrapping
// stripes; the low phase's (8-connected) characteristic is -euler on the torus.
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

namespace morphogen::analysis {

// Components of at most this many cells are specks (noise at the threshold).
inline constexpr long kSpeckMaxCells = 2;
// A spot is compact: principal-axis ratio at most this ...
inline constexpr double kSpotMaxElongation = 2.0;
// ... and at least this fill of its moment ellipse (rings and branched shapes fall below).
inline constexpr double kSpotMinFill = 0.6;
// ... and at most this many squared wavelengths in area (a hexagonal unit cell is 1.15).
inline constexpr double kSpotMaxAreaWavelengths = 2.0;

struct FieldShape2D {
  int nx = 0, ny = 0;    // cells per axis
  double hx = 1, hy = 1; // spacing (physical units per cell)
  bool periodic_x = true, periodic_y = true;
};

// One connected component of a phase.
struct Component {
  long area = 0;         // cells
  double cx = 0, cy = 0; // centroid, physical units, in [0, L) on periodic axes
  double elongation = 1; // sqrt(l1 / l2); +inf when wrapping
  double fill = 1;       // area / (4 pi sqrt(l1 l2)); 0 when wrapping
  int winding_rank = 0;  // 0: contractible; 1: winds in one direction; 2: in two
  bool speck = false, spot = false;
};

// Summary of one phase (the cells above the threshold, or those at or below it).
struct PhaseMetrics {
  double area_fraction = 0;           // cells of this phase / all cells
  int components = 0;                 // all components, specks included
  int specks = 0;                     // components of <= kSpeckMaxCells cells
  int spots = 0;                      // compact components (spot count; holes for the low phase)
  double spot_area_cells = 0;         // mean spot area in cells (0 if no spots)
  double spot_area = 0;               // mean spot area, physical (cells hx hy)
  int elongated = 0;                  // non-speck components that are not spots
  int wrapping = 0;                   // components that wind around the torus (rank >= 1)
  int networks = 0;                   // components winding in two directions (rank 2)
  double spot_area_fraction = 0;      // area in spots / phase area without specks
  double elongated_area_fraction = 0; // area in elongated components / same
  double largest_fraction = 0;        // largest component's area / phase area
  double median_elongation = 0;       // over non-speck components (+inf for wrapping ones)
  double median_fill = 0;             // same, fill
};

struct PatternMetrics {
  int nx = 0, ny = 0;
  // Finiteness: all else is left at its default (0) when a value is NaN or infinite.
  bool finite = true;
  long nonfinite = 0;
  // Statistics.
  double min = 0, max = 0, mean = 0, stddev = 0, p5 = 0, p95 = 0;
  double contrast = 0;  // (p95 - p5) / (|mean| + 1e-12)
  double range_rel = 0; // (max - min) / (|mean| + 1e-12)
  // Spectrum (all 0 for a constant field).
  double wavelength = 0;       // physical units
  double wavelength_cells = 0; // wavelength / sqrt(hx hy)
  int peak_ring = 0;
  double peak_power_fraction = 0;
  double peak_sharpness = 0;
  double spectral_anisotropy = 0;
  double spectral_angle = 0;
  double gridscale_power_fraction = 0;
  // Structure tensor.
  double coherence = 0;
  // Phases.
  double threshold = 0;
  long euler = 0; // of the high phase
  PhaseMetrics high, low;
};

// All metrics of field u (nx*ny values, u[i + nx*j]). Throws std::invalid_argument for a
// shape with nx or ny < 1 or a spacing that is not positive and finite.
PatternMetrics compute_pattern_metrics(const double* u, const FieldShape2D& shape);

// Connected components of mask (nx*ny bytes, nonzero = member), connectivity 4 or 8, wrapping
// across periodic axes; spot/speck flags set by the rules above, with max_spot_area (physical
// units) in place of kSpotMaxAreaWavelengths * wavelength^2. Exposed for tests and tools.
std::vector<Component>
label_components(const unsigned char* mask, const FieldShape2D& shape, int connectivity,
                 double max_spot_area = std::numeric_limits<double>::infinity());

// Euler characteristic of the 4-connected set mask (see above).
long euler_characteristic_4(const unsigned char* mask, const FieldShape2D& shape);

} // namespace morphogen::analysis
