// Pattern metrics of one 2-D field: statistics, radially averaged power spectrum (FFTW),
// structure-tensor coherence, periodic connected components and the Euler characteristic.
// Definitions in pattern_metrics.hpp.
#include "analysis/pattern_metrics.hpp"

#include <fftw3.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

namespace morphogen::analysis {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kContrastEps = 1e-12;
constexpr double kAnnulus = 1.25; // peak annulus: |k| in [k_peak / 1.25, 1.25 k_peak]

// ---------------------------------------------------------------------------------------------
// Statistics.

double quantile_sorted_position(std::vector<double>& v, double p) {
  const std::size_t k = static_cast<std::size_t>(std::floor(p * static_cast<double>(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

void compute_statistics(const double* u, std::size_t n, PatternMetrics& m) {
  double lo = u[0], hi = u[0], sum = 0;
  for (std::size_t c = 0; c < n; ++c) {
    lo = std::min(lo, u[c]);
    hi = std::max(hi, u[c]);
    sum += u[c];
  }
  const double mean = sum / static_cast<double>(n);
  double var = 0;
  for (std::size_t c = 0; c < n; ++c)
    var += (u[c] - mean) * (u[c] - mean);
  std::vector<double> copy(u, u + n);
  m.min = lo;
  m.max = hi;
  m.mean = mean;
  m.stddev = std::sqrt(var / static_cast<double>(n));
  m.p5 = quantile_sorted_position(copy, 0.05);
  m.p95 = quantile_sorted_position(copy, 0.95);
  m.contrast = (m.p95 - m.p5) / (std::fabs(mean) + kContrastEps);
  m.range_rel = (hi - lo) / (std::fabs(mean) + kContrastEps);
}

// ---------------------------------------------------------------------------------------------
// Spectrum.

struct FftwFree {
  void operator()(void* p) const { fftw_free(p); }
};

std::vector<double> hann(int n) {
  std::vector<double> w(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double s = std::sin(kPi * (i + 0.5) / n);
    w[static_cast<std::size_t>(i)] = s * s;
  }
  return w;
}

void compute_spectrum(const double* u, const FieldShape2D& s, PatternMetrics& m) {
  const int nx = s.nx, ny = s.ny;
  const std::size_t n = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  const int nxc = nx / 2 + 1;
  std::unique_ptr<double, FftwFree> in(fftw_alloc_real(n));
  std::unique_ptr<fftw_complex, FftwFree> out(
      fftw_alloc_complex(static_cast<std::size_t>(nxc) * static_cast<std::size_t>(ny)));
  if (!in || !out) throw std::bad_alloc();

  // Window (1 on periodic axes) and the window-weighted mean.
  const std::vector<double> wx = s.periodic_x ? std::vector<double>(nx, 1.0) : hann(nx);
  const std::vector<double> wy = s.periodic_y ? std::vector<double>(ny, 1.0) : hann(ny);
  double sw = 0, swu = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double w = wx[i] * wy[j];
      sw += w;
      swu += w * u[i + static_cast<std::size_t>(nx) * j];
    }
  const double wmean = swu / sw;
  double* a = in.get();
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::size_t c = i + static_cast<std::size_t>(nx) * j;
      a[c] = (u[c] - wmean) * wx[i] * wy[j];
    }

  fftw_plan plan = fftw_plan_dft_r2c_2d(ny, nx, a, out.get(), FFTW_ESTIMATE);
  if (!plan) throw std::runtime_error("pattern metrics: FFTW could not plan the transform");
  fftw_execute(plan);
  fftw_destroy_plan(plan);

  const double Lx = nx * s.hx, Ly = ny * s.hy;
  const double dk = 2 * kPi / std::max(Lx, Ly);
  const double knyq = kPi / std::max(s.hx, s.hy);
  const int nring = static_cast<int>(std::floor(knyq / dk + 0.5)) + 1;
  std::vector<double> ring_power(nring, 0.0), ring_count(nring, 0.0), ring_kpower(nring, 0.0);
  double total = 0, grid_power = 0;
  const double k_grid = 0.5 * knyq;

  struct Mode {
    double k, theta, p;
  };
  // Visit every nonzero mode of the half spectrum with its multiplicity weight.
  auto for_each_mode = [&](auto&& f) {
    const fftw_complex* F = out.get();
    for (int q = 0; q < ny; ++q) {
      const int qs = (q <= ny / 2) ? q : q - ny;
      const double ky = 2 * kPi * qs / Ly;
      for (int mm = 0; mm < nxc; ++mm) {
        if (mm == 0 && q == 0) continue;
        const double w = (mm == 0 || (nx % 2 == 0 && mm == nx / 2)) ? 1.0 : 2.0;
        const double kx = 2 * kPi * mm / Lx;
        const fftw_complex& z = F[mm + static_cast<std::size_t>(nxc) * q];
        const double p = w * (z[0] * z[0] + z[1] * z[1]);
        f(Mode{std::hypot(kx, ky), std::atan2(ky, kx), p}, w);
      }
    }
  };

  for_each_mode([&](const Mode& md, double w) {
    total += md.p;
    if (md.k > k_grid) grid_power += md.p;
    const int b = static_cast<int>(std::floor(md.k / dk + 0.5));
    if (b < nring) {
      ring_power[b] += md.p;
      ring_count[b] += w;
      ring_kpower[b] += md.p * md.k;
    }
  });
  if (!(total > 0)) return; // constant field: no spectrum

  std::vector<double> S(nring, 0.0);
  for (int b = 1; b < nring; ++b)
    S[b] = ring_count[b] > 0 ? ring_power[b] / ring_count[b] : 0.0;
  int bstar = 1;
  for (int b = 1; b < nring; ++b)
    if (S[b] > S[bstar]) bstar = b;
  // S-weighted mean of the rings' mean radii: first over the peak ring and its neighbours,
  // then twice over the rings within the annulus about the current estimate.
  auto centroid = [&](double klo, double khi) {
    double num = 0, den = 0;
    for (int b = 1; b < nring; ++b) {
      if (b * dk < klo || b * dk > khi) continue;
      const double kbar = ring_power[b] > 0 ? ring_kpower[b] / ring_power[b] : b * dk;
      num += S[b] * kbar;
      den += S[b];
    }
    return den > 0 ? num / den : bstar * dk;
  };
  double kpeak = centroid((bstar - 1) * dk, (bstar + 1) * dk);
  for (int it = 0; it < 2; ++it)
    kpeak = centroid(kpeak / kAnnulus, kpeak * kAnnulus);

  // Half-maximum width of S around the peak ring.
  const double half = 0.5 * S[bstar];
  double left = 0.5, right = nring - 0.5; // ring coordinates where S crosses half
  for (int b = bstar; b > 1; --b)
    if (S[b - 1] < half) {
      left = (b - 1) + (half - S[b - 1]) / (S[b] - S[b - 1]);
      break;
    }
  for (int b = bstar; b + 1 < nring; ++b)
    if (S[b + 1] < half) {
      right = b + (S[b] - half) / (S[b] - S[b + 1]);
      break;
    }
  const double fwhm = std::max(right - left, 1e-12) * dk;

  double annulus = 0;
  std::complex<double> orient(0, 0);
  for_each_mode([&](const Mode& md, double) {
    if (md.k >= kpeak / kAnnulus && md.k <= kpeak * kAnnulus) {
      annulus += md.p;
      orient += md.p * std::polar(1.0, 2 * md.theta);
    }
  });

  m.wavelength = 2 * kPi / kpeak;
  m.wavelength_cells = m.wavelength / std::sqrt(s.hx * s.hy);
  m.peak_ring = bstar;
  m.peak_power_fraction = annulus / total;
  m.peak_sharpness = kpeak / fwhm;
  m.spectral_anisotropy = annulus > 0 ? std::abs(orient) / annulus : 0.0;
  m.spectral_angle = annulus > 0 ? 0.5 * std::arg(orient) : 0.0;
  m.gridscale_power_fraction = grid_power / total;
}

// ---------------------------------------------------------------------------------------------
// Structure tensor.

// In-place moving average of n values a[0], a[stride], ... over 2r+1 neighbours (wrapping, or
// truncated and renormalised at the ends).
void box_line(double* a, int n, std::ptrdiff_t stride, int r, bool periodic,
              std::vector<double>& prefix) {
  prefix.resize(static_cast<std::size_t>(n) + 1);
  prefix[0] = 0.0;
  for (int i = 0; i < n; ++i)
    prefix[i + 1] = prefix[i] + a[i * stride];
  const double total = prefix[n];
  auto S = [&](long x) { // sum of the periodic extension over [0, x)
    // q = floor(x / n); no division for x in [-n, 2n) (r < n: every call of the loop below)
    const long q = x >= 0    ? (x < n        ? 0
                                : x < 2L * n ? 1
                                             : x / n)
                   : x >= -n ? -1
                             : -((-x + n - 1) / n);
    return static_cast<double>(q) * total + prefix[static_cast<std::size_t>(x - q * n)];
  };
  for (int i = 0; i < n; ++i) {
    if (periodic) {
      a[i * stride] = (S(i + r + 1L) - S(static_cast<long>(i) - r)) / (2.0 * r + 1.0);
    } else {
      const int lo = std::max(0, i - r), hi = std::min(n - 1, i + r);
      a[i * stride] = (prefix[hi + 1] - prefix[lo]) / (hi - lo + 1);
    }
  }
}

void box_filter(std::vector<double>& f, const FieldShape2D& s, int rx, int ry) {
  std::vector<double> prefix;
  const std::size_t nx = static_cast<std::size_t>(s.nx), ny = static_cast<std::size_t>(s.ny);
  for (std::size_t j = 0; j < ny; ++j)
    box_line(f.data() + nx * j, s.nx, 1, rx, s.periodic_x, prefix);
  // Columns in blocks of kBlock, copied to contiguous lines and back (row-wise memory access;
  // the same operations per column as filtering it in place).
  constexpr std::size_t kBlock = 16;
  std::vector<double> cols(kBlock * ny);
  for (std::size_t i0 = 0; i0 < nx; i0 += kBlock) {
    const std::size_t b = std::min(kBlock, nx - i0);
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t c = 0; c < b; ++c)
        cols[c * ny + j] = f[i0 + c + nx * j];
    for (std::size_t c = 0; c < b; ++c)
      box_line(cols.data() + c * ny, s.ny, 1, ry, s.periodic_y, prefix);
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t c = 0; c < b; ++c)
        f[i0 + c + nx * j] = cols[c * ny + j];
  }
}

void compute_coherence(const double* u, const FieldShape2D& s, PatternMetrics& m) {
  const int nx = s.nx, ny = s.ny;
  const std::size_t n = static_cast<std::size_t>(nx) * ny;
  std::vector<double> jxx(n), jyy(n), jxy(n);
  auto at = [&](int i, int j) { return u[i + static_cast<std::size_t>(nx) * j]; };
  auto deriv = [](int i, int len, bool periodic, double h, auto&& get) {
    if (len < 2) return 0.0;
    if (periodic) return (get(i + 1 == len ? 0 : i + 1) - get(i == 0 ? len - 1 : i - 1)) / (2 * h);
    if (i == 0) return (get(1) - get(0)) / h;
    if (i == len - 1) return (get(len - 1) - get(len - 2)) / h;
    return (get(i + 1) - get(i - 1)) / (2 * h);
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double gx = deriv(i, nx, s.periodic_x, s.hx, [&](int ii) { return at(ii, j); });
      const double gy = deriv(j, ny, s.periodic_y, s.hy, [&](int jj) { return at(i, jj); });
      const std::size_t c = i + static_cast<std::size_t>(nx) * j;
      jxx[c] = gx * gx;
      jyy[c] = gy * gy;
      jxy[c] = gx * gy;
    }
  const double lambda = m.wavelength > 0 ? m.wavelength : 4 * std::max(s.hx, s.hy);
  const int rx = std::max(1, static_cast<int>(std::lround(0.5 * lambda / s.hx)));
  const int ry = std::max(1, static_cast<int>(std::lround(0.5 * lambda / s.hy)));
  box_filter(jxx, s, rx, ry);
  box_filter(jyy, s, rx, ry);
  box_filter(jxy, s, rx, ry);
  double aniso = 0, trace = 0;
  for (std::size_t c = 0; c < n; ++c) {
    aniso += std::sqrt((jxx[c] - jyy[c]) * (jxx[c] - jyy[c]) + 4 * jxy[c] * jxy[c]);
    trace += jxx[c] + jyy[c];
  }
  m.coherence = trace > 0 ? aniso / trace : 0.0;
}

// ---------------------------------------------------------------------------------------------
// Connected components: union-find with displacements in unwrapped coordinates.

class DisplacedUnionFind {
public:
  // n singletons; reset reuses the arrays' memory (no new pages for a second labelling).
  explicit DisplacedUnionFind(std::size_t n = 0) { reset(n); }
  void reset(std::size_t n) {
    parent_.resize(n);
    for (std::size_t c = 0; c < n; ++c)
      parent_[c] = static_cast<std::int32_t>(c);
    size_.assign(n, 1);
    offx_.assign(n, 0);
    offy_.assign(n, 0);
    rank_.assign(n, 0);
    w1x_.assign(n, 0);
    w1y_.assign(n, 0);
  }

  // Root of x; afterwards offset(x) = u(x) - u(root) in unwrapped cells.
  std::int32_t find(std::int32_t x) {
    std::int32_t r = x;
    long sx = 0, sy = 0;
    while (parent_[r] != r) {
      sx += offx_[r];
      sy += offy_[r];
      r = parent_[r];
    }
    std::int32_t cur = x;
    while (parent_[cur] != cur) {
      const std::int32_t next = parent_[cur];
      const long ox = offx_[cur], oy = offy_[cur];
      parent_[cur] = r;
      offx_[cur] = static_cast<std::int32_t>(sx);
      offy_[cur] = static_cast<std::int32_t>(sy);
      sx -= ox;
      sy -= oy;
      cur = next;
    }
    return r;
  }
  long offx(std::int32_t x) const { return offx_[x]; }
  long offy(std::int32_t x) const { return offy_[x]; }
  int winding_rank(std::int32_t root) const { return rank_[root]; }

  // Cells a and b are neighbours with u(b) = u(a) + (dx, dy); nx, ny convert a closed loop's
  // displacement into a winding vector in periods.
  void unite(std::int32_t a, std::int32_t b, int dx, int dy, int nx, int ny) {
    std::int32_t ra = find(a), rb = find(b);
    const long ax = offx_[a] * (a != ra), ay = offy_[a] * (a != ra);
    const long bx = offx_[b] * (b != rb), by = offy_[b] * (b != rb);
    if (ra == rb) {
      const long wx = ax + dx - bx, wy = ay + dy - by;
      if (wx != 0 || wy != 0) add_winding(ra, wx / nx, wy / ny); // (a closed loop: usually 0)
      return;
    }
    // u(rb) - u(ra) = (u(b) - bx) - (u(a) - ax) = dx - bx + ax.
    long rx = dx - bx + ax, ry = dy - by + ay;
    if (size_[ra] < size_[rb]) {
      std::swap(ra, rb);
      rx = -rx;
      ry = -ry;
    }
    parent_[rb] = ra;
    offx_[rb] = static_cast<std::int32_t>(rx);
    offy_[rb] = static_cast<std::int32_t>(ry);
    size_[ra] += size_[rb];
    if (rank_[rb] >= 1) add_winding(ra, w1x_[rb], w1y_[rb]);
    if (rank_[rb] == 2) rank_[ra] = 2;
  }

private:
  void add_winding(std::int32_t root, long a, long b) {
    if (a == 0 && b == 0) return;
    if (rank_[root] == 0) {
      rank_[root] = 1;
      w1x_[root] = static_cast<std::int32_t>(a);
      w1y_[root] = static_cast<std::int32_t>(b);
    } else if (rank_[root] == 1 && w1x_[root] * b - w1y_[root] * a != 0) {
      rank_[root] = 2;
    }
  }

  std::vector<std::int32_t> parent_, size_, offx_, offy_;
  std::vector<std::uint8_t> rank_;
  std::vector<std::int32_t> w1x_, w1y_;
};

struct Moments {
  long area = 0;
  double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  std::int32_t root = 0;
};

void summarise_phase(const std::vector<Component>& comps, long phase_cells, long total_cells,
                     PhaseMetrics& p) {
  p.area_fraction = static_cast<double>(phase_cells) / static_cast<double>(total_cells);
  p.components = static_cast<int>(comps.size());
  long spot_area = 0, elongated_area = 0, largest = 0;
  std::vector<double> el, fill;
  for (const auto& c : comps) {
    largest = std::max(largest, c.area);
    if (c.speck) {
      ++p.specks;
      continue;
    }
    el.push_back(c.elongation);
    fill.push_back(c.fill);
    if (c.winding_rank >= 1) ++p.wrapping;
    if (c.winding_rank == 2) ++p.networks;
    if (c.spot) {
      ++p.spots;
      spot_area += c.area;
    } else {
      ++p.elongated;
      elongated_area += c.area;
    }
  }
  const double sized = static_cast<double>(spot_area + elongated_area);
  p.spot_area_fraction = sized > 0 ? spot_area / sized : 0.0;
  p.elongated_area_fraction = sized > 0 ? elongated_area / sized : 0.0;
  p.largest_fraction = phase_cells > 0 ? static_cast<double>(largest) / phase_cells : 0.0;
  p.spot_area_cells = p.spots > 0 ? static_cast<double>(spot_area) / p.spots : 0.0;
  auto median = [](std::vector<double>& v) {
    if (v.empty()) return 0.0;
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
  };
  p.median_elongation = median(el);
  p.median_fill = median(fill);
}

void validate(const FieldShape2D& s) {
  if (s.nx < 1 || s.ny < 1)
    throw std::invalid_argument("pattern metrics: grid " + std::to_string(s.nx) + " x " +
                                std::to_string(s.ny) + ": need at least 1 x 1 cells");
  if (static_cast<long long>(s.nx) * s.ny > INT32_MAX / 2)
    throw std::invalid_argument("pattern metrics: grid too large for 32-bit cell indices");
  if (!(s.hx > 0) || !(s.hy > 0) || !std::isfinite(s.hx) || !std::isfinite(s.hy))
    throw std::invalid_argument("pattern metrics: spacing must be positive and finite");
}

// The labelling's per-cell arrays, kept between the two phases' labellings.
struct LabelWorkspace {
  DisplacedUnionFind uf;
  std::vector<std::int32_t> comp_of;
};

std::vector<Component> label_components_in(const unsigned char* mask, const FieldShape2D& s,
                                           int connectivity, double max_spot_area,
                                           LabelWorkspace& ws) {
  validate(s);
  if (connectivity != 4 && connectivity != 8)
    throw std::invalid_argument("pattern metrics: connectivity must be 4 or 8");
  const int nx = s.nx, ny = s.ny;
  const std::size_t n = static_cast<std::size_t>(nx) * ny;
  DisplacedUnionFind& uf = ws.uf;
  uf.reset(n);
  auto idx = [nx](int i, int j) { return static_cast<std::int32_t>(i + nx * j); };
  // Link (i, j) with its neighbour at (i + dx, j + dy) if both are members.
  auto link = [&](int i, int j, int dx, int dy) {
    int ii = i + dx, jj = j + dy;
    if (ii < 0 || ii >= nx) {
      if (!s.periodic_x) return;
      ii = (ii + nx) % nx;
    }
    if (jj < 0 || jj >= ny) {
      if (!s.periodic_y) return;
      jj = (jj + ny) % ny;
    }
    if (mask[idx(ii, jj)]) uf.unite(idx(i, j), idx(ii, jj), dx, dy, nx, ny);
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (!mask[idx(i, j)]) continue;
      link(i, j, 1, 0);
      link(i, j, 0, 1);
      if (connectivity == 8) {
        link(i, j, 1, 1);
        link(i, j, -1, 1);
      }
    }

  std::vector<std::int32_t>& comp_of = ws.comp_of;
  comp_of.assign(n, -1);
  std::vector<Moments> mom;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::int32_t c = idx(i, j);
      if (!mask[c]) continue;
      const std::int32_t r = uf.find(c);
      if (comp_of[r] < 0) {
        comp_of[r] = static_cast<std::int32_t>(mom.size());
        mom.push_back(Moments{});
        mom.back().root = r;
      }
      Moments& M = mom[comp_of[r]];
      const double x = (c == r ? 0 : uf.offx(c)) * s.hx, y = (c == r ? 0 : uf.offy(c)) * s.hy;
      ++M.area;
      M.sx += x;
      M.sy += y;
      M.sxx += x * x;
      M.syy += y * y;
      M.sxy += x * y;
    }

  const double Lx = nx * s.hx, Ly = ny * s.hy;
  std::vector<Component> out;
  out.reserve(mom.size());
  for (const auto& M : mom) {
    Component c;
    c.area = M.area;
    const double a = static_cast<double>(M.area);
    const double mx = M.sx / a, my = M.sy / a;
    const int ri = M.root % nx, rj = M.root / nx;
    c.cx = (ri + 0.5) * s.hx + mx;
    c.cy = (rj + 0.5) * s.hy + my;
    if (s.periodic_x) c.cx -= Lx * std::floor(c.cx / Lx);
    if (s.periodic_y) c.cy -= Ly * std::floor(c.cy / Ly);
    c.winding_rank = uf.winding_rank(M.root);
    if (c.winding_rank > 0) {
      c.elongation = std::numeric_limits<double>::infinity();
      c.fill = 0;
    } else {
      const double cxx = M.sxx / a - mx * mx + s.hx * s.hx / 12;
      const double cyy = M.syy / a - my * my + s.hy * s.hy / 12;
      const double cxy = M.sxy / a - mx * my;
      const double tr = cxx + cyy, det = cxx * cyy - cxy * cxy;
      const double disc = std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
      const double l1 = 0.5 * tr + disc, l2 = std::max(0.5 * tr - disc, 1e-300);
      c.elongation = std::sqrt(l1 / l2);
      c.fill = a * s.hx * s.hy / (4 * kPi * std::sqrt(l1 * l2));
    }
    c.speck = c.area <= kSpeckMaxCells;
    c.spot = !c.speck && c.winding_rank == 0 && c.elongation <= kSpotMaxElongation &&
             c.fill >= kSpotMinFill && c.area * s.hx * s.hy <= max_spot_area;
    out.push_back(c);
  }
  return out;
}

} // namespace

std::vector<Component> label_components(const unsigned char* mask, const FieldShape2D& s,
                                        int connectivity, double max_spot_area) {
  LabelWorkspace ws;
  return label_components_in(mask, s, connectivity, max_spot_area, ws);
}

long euler_characteristic_4(const unsigned char* mask, const FieldShape2D& s) {
  validate(s);
  const int nx = s.nx, ny = s.ny;
  auto at = [&](int i, int j) -> int {
    if (i < 0 || i >= nx) {
      if (!s.periodic_x) return 0;
      i = (i + nx) % nx;
    }
    if (j < 0 || j >= ny) {
      if (!s.periodic_y) return 0;
      j = (j + ny) % ny;
    }
    return mask[i + static_cast<std::size_t>(nx) * j] ? 1 : 0;
  };
  // Blocks with lower-left corner (i, j): every block that touches the set.
  const int i0 = s.periodic_x ? 0 : -1, j0 = s.periodic_y ? 0 : -1;
  long n1 = 0, n3 = 0, nd = 0;
  for (int j = j0; j < ny; ++j)
    for (int i = i0; i < nx; ++i) {
      const int a = at(i, j), b = at(i + 1, j), c = at(i, j + 1), d = at(i + 1, j + 1);
      const int k = a + b + c + d;
      if (k == 1) ++n1;
      if (k == 3) ++n3;
      if (k == 2 && a == d) ++nd;
    }
  return (n1 - n3 + 2 * nd) / 4;
}

PatternMetrics compute_pattern_metrics(const double* u, const FieldShape2D& s) {
  validate(s);
  PatternMetrics m;
  m.nx = s.nx;
  m.ny = s.ny;
  const std::size_t n = static_cast<std::size_t>(s.nx) * s.ny;
  for (std::size_t c = 0; c < n; ++c)
    if (!std::isfinite(u[c])) ++m.nonfinite;
  if (m.nonfinite > 0) {
    m.finite = false;
    return m;
  }
  compute_statistics(u, n, m);
  compute_spectrum(u, s, m);
  compute_coherence(u, s, m);

  m.threshold = 0.5 * (m.min + m.max);
  std::vector<unsigned char> hi(n), lo(n);
  long nhi = 0;
  for (std::size_t c = 0; c < n; ++c) {
    hi[c] = u[c] > m.threshold;
    lo[c] = !hi[c];
    nhi += hi[c];
  }
  const long total = static_cast<long>(n);
  const double max_spot_area = m.wavelength > 0
                                   ? kSpotMaxAreaWavelengths * m.wavelength * m.wavelength
                                   : std::numeric_limits<double>::infinity();
  LabelWorkspace ws;
  summarise_phase(label_components_in(hi.data(), s, 4, max_spot_area, ws), nhi, total, m.high);
  summarise_phase(label_components_in(lo.data(), s, 8, max_spot_area, ws), total - nhi, total,
                  m.low);
  m.high.spot_area = m.high.spot_area_cells * s.hx * s.hy;
  m.low.spot_area = m.low.spot_area_cells * s.hx * s.hy;
  m.euler = euler_characteristic_4(hi.data(), s);
  return m;
}

} // namespace morphogen::analysis
