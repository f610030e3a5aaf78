#include "grid/trig_transform.hpp"

#include <cmath>
#include <fftw3.h>
#include <new>

namespace morphogen {

TrigTransform::TrigTransform(int n, bool odd, unsigned flags) : n_(n), odd_(odd) {
  const int nc = n / 2 + 1;
  cos_ = fftw_alloc_real(static_cast<size_t>(nc));
  sin_ = fftw_alloc_real(static_cast<size_t>(nc));
  v_ = fftw_alloc_real(static_cast<size_t>(n));
  c_ = fftw_alloc_real(2 * static_cast<size_t>(nc));
  if (!cos_ || !sin_ || !v_ || !c_) throw std::bad_alloc();
  const double pi = std::acos(-1.0);
  for (int k = 0; k < nc; ++k) {
    cos_[k] = std::cos(pi * k / (2.0 * n));
    sin_[k] = std::sin(pi * k / (2.0 * n));
  }
  auto* c = reinterpret_cast<fftw_complex*>(c_);
  fwd_ = fftw_plan_dft_r2c_1d(n, v_, c, flags);
  bwd_ = fftw_plan_dft_c2r_1d(n, c, v_, flags);
  if (!fwd_ || !bwd_) throw std::bad_alloc();
}

TrigTransform::~TrigTransform() {
  if (fwd_) fftw_destroy_plan(static_cast<fftw_plan>(fwd_));
  if (bwd_) fftw_destroy_plan(static_cast<fftw_plan>(bwd_));
  fftw_free(cos_);
  fftw_free(sin_);
  fftw_free(v_);
  fftw_free(c_);
}

void TrigTransform::forward(const double* x, double* y) {
  const int n = n_, h = (n + 1) / 2, m = n / 2;
  const double sg = odd_ ? -1.0 : 1.0;
  double* v = v_;
  for (int j = 0; j < h; ++j)
    v[j] = x[2 * j];
  for (int j = 0; j < m; ++j)
    v[n - 1 - j] = sg * x[2 * j + 1];
  fftw_execute(static_cast<fftw_plan>(fwd_));
  // Z_k = 2 Re(e^{-i pi k/2n} V_k), Z_{n-k} = 2 Re(e^{-i pi (n-k)/2n} conj(V_k)); odd: y reversed.
  const double* c = c_;
  const int last = n - 1;
  auto put = [&](int k, double z) { y[odd_ ? last - k : k] = z; };
  put(0, 2.0 * c[0]);
  for (int k = 1; 2 * k < n; ++k) {
    const double a = c[2 * k], b = c[2 * k + 1];
    put(k, 2.0 * (a * cos_[k] + b * sin_[k]));
    put(n - k, 2.0 * (a * sin_[k] - b * cos_[k]));
  }
  if (n % 2 == 0 && n > 0) put(m, 2.0 * c[2 * m] * cos_[m]);
}

void TrigTransform::backward(const double* y, double* x) {
  const int n = n_, h = (n + 1) / 2, m = n / 2;
  const int last = n - 1;
  auto X = [&](int k) { return y[odd_ ? last - k : k]; };
  double* c = c_;
  // W_k = e^{i pi k/2n} (X_k - i X_{n-k}) (X_n = 0): the spectrum of the permuted row.
  c[0] = X(0);
  c[1] = 0.0;
  for (int k = 1; 2 * k < n; ++k) {
    const double xa = X(k), xb = X(n - k);
    c[2 * k] = cos_[k] * xa + sin_[k] * xb;
    c[2 * k + 1] = sin_[k] * xa - cos_[k] * xb;
  }
  if (n % 2 == 0 && n > 0) {
    c[2 * m] = 2.0 * cos_[m] * X(m);
    c[2 * m + 1] = 0.0;
  }
  fftw_execute(static_cast<fftw_plan>(bwd_));
  const double sg = odd_ ? -1.0 : 1.0;
  const double* v = v_;
  for (int j = 0; j < h; ++j)
    x[2 * j] = v[j];
  for (int j = 0; j < m; ++j)
    x[2 * j + 1] = sg * v[n - 1 - j];
}

} // namespace morphogen
