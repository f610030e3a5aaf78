#include "grid/trig_transform.hpp"

#include <cmath>
#include <cstddef>
#include <fftw3.h>
#include <new>

namespace morphogen {

TrigTransform::TrigTransform(int n, bool odd, unsigned flags, int howmany)
    : n_(n), hm_(howmany), odd_(odd) {
  const int nc = n / 2 + 1;
  const size_t hm = static_cast<size_t>(howmany);
  cos_ = fftw_alloc_real(static_cast<size_t>(nc));
  sin_ = fftw_alloc_real(static_cast<size_t>(nc));
  v_ = fftw_alloc_real(static_cast<size_t>(n) * hm);
  c_ = fftw_alloc_real(2 * static_cast<size_t>(nc) * hm); // >= n * hm: the pairs' spectra
  if (!cos_ || !sin_ || !v_ || !c_) throw std::bad_alloc();
  const double pi = std::acos(-1.0);
  for (int k = 0; k < nc; ++k) {
    cos_[k] = std::cos(pi * k / (2.0 * n));
    sin_[k] = std::sin(pi * k / (2.0 * n));
  }
  auto* c = reinterpret_cast<fftw_complex*>(c_);
  if (howmany % 2 == 0) { // column pairs as complex sequences (FFTW's SIMD complex codelets)
    const int hp = howmany / 2;
    auto* v = reinterpret_cast<fftw_complex*>(v_);
    fwd_ = fftw_plan_many_dft(1, &n, hp, v, nullptr, hp, 1, c, nullptr, hp, 1, FFTW_FORWARD, flags);
    bwd_ =
        fftw_plan_many_dft(1, &n, hp, c, nullptr, hp, 1, v, nullptr, hp, 1, FFTW_BACKWARD, flags);
  } else {
    fwd_ = fftw_plan_many_dft_r2c(1, &n, howmany, v_, nullptr, howmany, 1, c, nullptr, howmany, 1,
                                  flags);
    bwd_ = fftw_plan_many_dft_c2r(1, &n, howmany, c, nullptr, howmany, 1, v_, nullptr, howmany, 1,
                                  flags);
  }
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

// One sequence (a row) compiled apart (with howmany a run-time value the row's loops run about
// 2x slower); an even number of sequences in complex pairs, an odd one through real FFTs.
void TrigTransform::forward(const double* x, double* y) {
  (this->*pick(&TrigTransform::forward_impl<true>, &TrigTransform::forward_pairs,
               &TrigTransform::forward_impl<false>))(x, y);
}

void TrigTransform::backward(const double* y, double* x) {
  (this->*pick(&TrigTransform::backward_impl<true>, &TrigTransform::backward_pairs,
               &TrigTransform::backward_impl<false>))(y, x);
}

// The permutation (before the forward FFT) and its inverse (after the backward one) of
// sequences interleaved `hm` wide; odd kind: the odd entries negated.
template <bool Row> void TrigTransform::permute(const double* x, double* v) const {
  const int n = n_, h = (n + 1) / 2, m = n / 2, hm = Row ? 1 : hm_;
  const double sg = odd_ ? -1.0 : 1.0;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < hm; ++i)
      v[j * hm + i] = x[2 * j * hm + i];
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < hm; ++i)
      v[(n - 1 - j) * hm + i] = sg * x[(2 * j + 1) * hm + i];
}

template <bool Row> void TrigTransform::unpermute(const double* v, double* x) const {
  const int n = n_, h = (n + 1) / 2, m = n / 2, hm = Row ? 1 : hm_;
  const double sg = odd_ ? -1.0 : 1.0;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < hm; ++i)
      x[2 * j * hm + i] = v[j * hm + i];
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < hm; ++i)
      x[(2 * j + 1) * hm + i] = sg * v[(n - 1 - j) * hm + i];
}

// Columns 2p and 2p+1 as one complex sequence z = a + i b: Z = DFT(z), and the real sequences'
// spectra A_k = (Z_k + conj Z_{n-k}) / 2, B_k = (Z_k - conj Z_{n-k}) / 2i, each twiddled as in
// forward_impl (the factors 1/2 and 2 cancel).
void TrigTransform::forward_pairs(const double* x, double* y) {
  const int n = n_, hm = hm_;
  permute<false>(x, v_);
  fftw_execute(static_cast<fftw_plan>(fwd_));
  auto row = [&](int k) { return y + (odd_ ? n - 1 - k : k) * hm; };
  for (int k = 0; 2 * k <= n; ++k) {
    const double ck = cos_[k], sk = sin_[k];
    const double *zk = c_ + k * hm, *zn = c_ + ((n - k) % n) * hm;
    double *yk = row(k), *yn = row(n - k == n ? 0 : n - k);
    const bool mirror = k > 0 && 2 * k < n;
    for (int p = 0; p < hm / 2; ++p) {
      const double zr = zk[2 * p], zi = zk[2 * p + 1], nr = zn[2 * p], ni = zn[2 * p + 1];
      const double ar = zr + nr, ai = zi - ni, br = zi + ni, bi = nr - zr;
      yk[2 * p] = ar * ck + ai * sk;
      yk[2 * p + 1] = br * ck + bi * sk;
      if (mirror) {
        yn[2 * p] = ar * sk - ai * ck;
        yn[2 * p + 1] = br * sk - bi * ck;
      }
    }
  }
}

// The inverse: each column's twiddled spectrum W (as in backward_impl), then the pair's
// Z_k = A_k + i B_k over the whole period (A_{n-k} = conj A_k), one complex inverse DFT.
void TrigTransform::backward_pairs(const double* y, double* x) {
  const int n = n_, hm = hm_;
  auto row = [&](int k) { return y + (odd_ ? n - 1 - k : k) * hm; };
  for (int k = 0; 2 * k <= n; ++k) {
    const double ck = cos_[k], sk = sin_[k];
    const bool real = k == 0 || 2 * k == n; // W_0 = X_0, W_{n/2} = 2 cos(pi/4) X_{n/2}
    const double *xk = row(k), *xn = row(real ? k : n - k);
    double *zk = c_ + k * hm, *zn = c_ + ((n - k) % n) * hm;
    for (int p = 0; p < hm / 2; ++p) {
      double ar, ai, br, bi;
      if (real) {
        const double f = k == 0 ? 1.0 : 2.0 * ck;
        ar = f * xk[2 * p], br = f * xk[2 * p + 1], ai = bi = 0.0;
      } else {
        ar = ck * xk[2 * p] + sk * xn[2 * p], ai = sk * xk[2 * p] - ck * xn[2 * p];
        br = ck * xk[2 * p + 1] + sk * xn[2 * p + 1], bi = sk * xk[2 * p + 1] - ck * xn[2 * p + 1];
      }
      zk[2 * p] = ar - bi;
      zk[2 * p + 1] = ai + br;
      if (!real) {
        zn[2 * p] = ar + bi;
        zn[2 * p + 1] = br - ai;
      }
    }
  }
  fftw_execute(static_cast<fftw_plan>(bwd_));
  unpermute<false>(v_, x);
}

template <bool Row> void TrigTransform::forward_impl(const double* x, double* y) {
  const int n = n_, m = n / 2, hm = Row ? 1 : hm_;
  permute<Row>(x, v_);
  fftw_execute(static_cast<fftw_plan>(fwd_));
  // Z_k = 2 Re(e^{-i pi k/2n} V_k), Z_{n-k} = 2 Re(e^{-i pi (n-k)/2n} conj(V_k)); odd: y reversed.
  const double* c = c_;
  auto row = [&](int k) { return y + (odd_ ? n - 1 - k : k) * hm; };
  for (int i = 0; i < hm; ++i)
    row(0)[i] = 2.0 * c[2 * i];
  for (int k = 1; 2 * k < n; ++k) {
    const double ck = cos_[k], sk = sin_[k];
    const double* ck_row = c + 2 * k * hm;
    double *zk = row(k), *zn = row(n - k);
    for (int i = 0; i < hm; ++i) {
      const double a = ck_row[2 * i], b = ck_row[2 * i + 1];
      zk[i] = 2.0 * (a * ck + b * sk);
      zn[i] = 2.0 * (a * sk - b * ck);
    }
  }
  if (n % 2 == 0 && n > 0)
    for (int i = 0; i < hm; ++i)
      row(m)[i] = 2.0 * c[2 * (m * hm + i)] * cos_[m];
}

template <bool Row> void TrigTransform::backward_impl(const double* y, double* x) {
  const int n = n_, m = n / 2, hm = Row ? 1 : hm_;
  auto row = [&](int k) { return y + (odd_ ? n - 1 - k : k) * hm; };
  double* c = c_;
  // W_k = e^{i pi k/2n} (X_k - i X_{n-k}) (X_n = 0): the spectrum of the permuted sequence.
  for (int i = 0; i < hm; ++i) {
    c[2 * i] = row(0)[i];
    c[2 * i + 1] = 0.0;
  }
  for (int k = 1; 2 * k < n; ++k) {
    const double ck = cos_[k], sk = sin_[k];
    const double *xk = row(k), *xn = row(n - k);
    double* wk = c + 2 * k * hm;
    for (int i = 0; i < hm; ++i) {
      wk[2 * i] = ck * xk[i] + sk * xn[i];
      wk[2 * i + 1] = sk * xk[i] - ck * xn[i];
    }
  }
  if (n % 2 == 0 && n > 0)
    for (int i = 0; i < hm; ++i) {
      c[2 * (m * hm + i)] = 2.0 * cos_[m] * row(m)[i];
      c[2 * (m * hm + i) + 1] = 0.0;
    }
  fftw_execute(static_cast<fftw_plan>(bwd_));
  unpermute<Row>(v_, x);
}

} // namespace morphogen
