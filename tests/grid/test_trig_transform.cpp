// TrigTransform (cosine and sine rows through one real FFT) against FFTW's own r2r transforms of
// the same kinds (REDFT10/01, RODFT10/01): the same values to 1e-14 of the row's largest, for
// even and odd lengths from 1 to 1024, from unaligned input and into unaligned output; and
// backward(forward(x)) = 2n x; interleaved columns (howmany > 1) as separate rows.
#include "grid/trig_transform.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fftw3.h>
#include <random>
#include <vector>

using namespace morphogen;

namespace {

std::vector<double> fftw_r2r(const std::vector<double>& in, fftw_r2r_kind kind) {
  const int n = static_cast<int>(in.size());
  std::vector<double> a(in), b(in.size());
  fftw_plan p = fftw_plan_r2r_1d(n, a.data(), b.data(), kind, FFTW_ESTIMATE);
  fftw_execute(p);
  fftw_destroy_plan(p);
  return b;
}

double max_abs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v)
    m = std::max(m, std::abs(x));
  return m;
}

// Largest |a - b| relative to max |b|.
double rel_error(const double* a, const std::vector<double>& b) {
  double e = 0.0;
  for (size_t i = 0; i < b.size(); ++i)
    e = std::max(e, std::abs(a[i] - b[i]));
  return e / std::max(max_abs(b), 1e-300);
}

void check_length(int n, bool odd) {
  std::mt19937_64 gen(static_cast<unsigned>(1000 * n + odd));
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> x(static_cast<size_t>(n));
  for (double& v : x)
    v = u(gen);
  TrigTransform t(n, odd, FFTW_ESTIMATE);
  // Offset by one double: rows of a ghosted array are not FFTW-aligned.
  std::vector<double> xin(static_cast<size_t>(n) + 1), y(static_cast<size_t>(n) + 1),
      back(static_cast<size_t>(n) + 1);
  std::copy(x.begin(), x.end(), xin.begin() + 1);
  t.forward(xin.data() + 1, y.data() + 1);
  const auto ref = fftw_r2r(x, odd ? FFTW_RODFT10 : FFTW_REDFT10);
  EXPECT_LT(rel_error(y.data() + 1, ref), 1e-14) << "forward, n = " << n << ", odd = " << odd;
  std::vector<double> spec(y.begin() + 1, y.end());
  const auto ref_b = fftw_r2r(spec, odd ? FFTW_RODFT01 : FFTW_REDFT01);
  t.backward(y.data() + 1, back.data() + 1);
  EXPECT_LT(rel_error(back.data() + 1, ref_b), 1e-14) << "backward, n = " << n << ", odd = " << odd;
  std::vector<double> twice_n_x(x);
  for (double& v : twice_n_x)
    v *= 2.0 * n;
  EXPECT_LT(rel_error(back.data() + 1, twice_n_x), 1e-14) << "round trip, n = " << n;
}

} // namespace

TEST(TrigTransform, CosinesMatchFftw) {
  for (int n : {1, 2, 3, 4, 5, 6, 7, 8, 9, 15, 16, 17, 31, 64, 100, 127, 128, 255, 512, 1000, 1024})
    check_length(n, false);
}

TEST(TrigTransform, SinesMatchFftw) {
  for (int n : {1, 2, 3, 4, 5, 6, 7, 8, 9, 15, 16, 17, 31, 64, 100, 127, 128, 255, 512, 1000, 1024})
    check_length(n, true);
}

// A cosine mode transforms to a single spike, exactly where FFTW puts it.
TEST(TrigTransform, SingleModeIsOneCoefficient) {
  const int n = 48, k = 5;
  const double pi = std::acos(-1.0);
  std::vector<double> x(n), y(n);
  for (int j = 0; j < n; ++j)
    x[j] = std::cos(pi * (j + 0.5) * k / n);
  TrigTransform t(n, false, FFTW_ESTIMATE);
  t.forward(x.data(), y.data());
  for (int q = 0; q < n; ++q)
    EXPECT_NEAR(y[q], q == k ? static_cast<double>(n) : 0.0, 1e-12) << "coefficient " << q;
}

// Several interleaved sequences (a plane's columns: entry j of column i at j * howmany + i),
// in place: each column as its own row transform (an odd count: real FFTs; an even one: the
// columns paired as complex sequences).
TEST(TrigTransform, InterleavedColumnsAreRowTransforms) {
  for (int hm : {5, 6, 2})
    for (bool odd : {false, true})
      for (int n : {1, 2, 7, 16, 33}) {
        std::mt19937_64 gen(static_cast<unsigned>(7 * n + odd));
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        std::vector<double> plane(static_cast<size_t>(n * hm));
        for (double& v : plane)
          v = u(gen);
        const std::vector<double> start(plane);
        TrigTransform cols(n, odd, FFTW_ESTIMATE, hm), row(n, odd, FFTW_ESTIMATE);
        cols.forward(plane.data(), plane.data());
        for (int i = 0; i < hm; ++i) {
          std::vector<double> x(static_cast<size_t>(n)), y(static_cast<size_t>(n));
          for (int j = 0; j < n; ++j)
            x[j] = start[static_cast<size_t>(j * hm + i)];
          row.forward(x.data(), y.data());
          for (int j = 0; j < n; ++j)
            EXPECT_NEAR(plane[static_cast<size_t>(j * hm + i)], y[j], 1e-13)
                << "n = " << n << ", howmany = " << hm << ", odd = " << odd << ", column " << i
                << ", entry " << j;
        }
        cols.backward(plane.data(), plane.data());
        for (size_t q = 0; q < plane.size(); ++q)
          EXPECT_NEAR(plane[q], 2.0 * n * start[q], 1e-12 * n)
              << "round trip, n = " << n << ", howmany = " << hm;
      }
}
