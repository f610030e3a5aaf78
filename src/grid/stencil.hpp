// Discrete Laplacians as weighted neighbour offsets (pure data, no PETSc).
//
//   5pt (2-D):  lap u = (u[i-1]-2u+u[i+1])/hx^2 + (u[j-1]-2u+u[j+1])/hy^2
//   7pt (3-D):  the same plus the z pair over hz^2
//   9pt (2-D, hx = hy = h): the isotropic stencil of the Garrity/Sims code,
//       lap u = (4 (N+S+E+W) + (NE+NW+SE+SW) - 20 u) / (6 h^2)
//     = (20 / (6 h^2)) (0.2 (N+S+E+W) + 0.05 (diagonals) - u); Garrity's unscaled operator
//       with diffusion rate d equals this Laplacian with D = 0.3 d h^2.
//   19pt (3-D, hx = hy = hz = h): (2 (6 faces) + (12 edges) - 24 u) / (6 h^2)
//   27pt (3-D, equal h): (14 (6 faces) + 3 (12 edges) + (8 corners) - 128 u) / (30 h^2)
//     (Patra & Karttunen 2006: isotropic leading error, lap + (h^2/12) lap^2 u for both)
// All are second-order accurate and exact on quadratics. Term 0 is always the centre.
// spectral_radius() is max |symbol| over the grid's Nyquist corners: the explicit Euler step
// is stable for dt * D_max * spectral_radius <= 2.
#pragma once

#include <array>
#include <cmath>
#include <string>

namespace morphogen {

struct Stencil {
  std::string name;
  int nterms = 0;
  std::array<std::array<int, 3>, 27> off{};
  std::array<double, 27> w{};

  void add(int dx, int dy, int dz, double weight) {
    off[nterms] = {dx, dy, dz};
    w[nterms] = weight;
    ++nterms;
  }
  // Largest |eigenvalue| of the stencil operator on a periodic grid.
  double spectral_radius() const {
    double best = 0;
    for (int c = 0; c < 8; ++c) {
      double s = 0;
      for (int t = 0; t < nterms; ++t) {
        double phase = 1;
        for (int d = 0; d < 3; ++d)
          if ((c >> d) & 1) phase *= (off[t][d] % 2 == 0) ? 1.0 : -1.0;
        s += w[t] * phase;
      }
      best = std::max(best, std::abs(s));
    }
    return best;
  }
  // Apply to a function sampled at offsets (for tests): sum_t w_t f(off_t).
  template <class F> double apply(F&& f) const {
    double s = 0;
    for (int t = 0; t < nterms; ++t)
      s += w[t] * f(off[t][0], off[t][1], off[t][2]);
    return s;
  }
};

// The same stencil grouped by grid row, the form the explicit kernel consumes: row r has offset
// (dy, dz) and x-taps w[r] = {weight at x-1, x, x+1}. Row 0 is the centre row. `box` is true
// when a row other than the centre one has x-taps (9pt, 19pt, 27pt), false for star stencils
// (5pt, 7pt).
struct RowStencil {
  int nrows = 0;
  bool box = false;
  std::array<std::array<int, 2>, 9> off{};
  std::array<double, 27> w{}; // w[3*r + (dx+1)]
};

// A box stencil by weight class, the form of the explicit kernel's fast box path: the weight of
// a tap depends only on how many of its offsets (dx, dy, dz) are non-zero (0: centre, 1: face,
// 2: edge, 3: corner), as for the isotropic 9pt (2-D: its diagonal taps are the edge class, no
// corner class), 19pt and 27pt stencils. perm lists the RowStencil's rows in class order: the
// centre row (dy = dz = 0), the face rows (one of dy, dz non-zero: 4 in 3-D, 2 in 2-D), then in
// 3-D the 4 corner rows (both non-zero).
struct BoxClasses {
  std::array<double, 4> w{}; // centre, face, edge, corner weight (2-D: corner 0)
  std::array<int, 9> perm{}; // rows in class order (2-D: the first 3)
};

// True (out filled) when `rows` is a 3-row (2-D) or 9-row (3-D) box stencil with every row of
// its 3x1 or 3x3 block whose taps have one weight per class (exactly equal values); false (out
// untouched) otherwise.
bool box_classes(const RowStencil& rows, BoxClasses& out);
// box_classes, and where it holds `rows` reordered into class order (out.perm applied).
bool to_class_order(RowStencil& rows, BoxClasses& out);

// True for the isotropic box stencils (9pt, 19pt, 27pt): equal spacings, no tensor or map form.
inline bool isotropic_box(const Stencil& s) {
  return s.name == "9pt" || s.name == "19pt" || s.name == "27pt";
}

// Group a stencil with x offsets in [-1, 1] into rows; false if it has wider x offsets.
bool to_rows(const Stencil& s, RowStencil& out);

// Names accepted by make_stencil for the given dimension: "5pt" and "9pt" in 2-D, "7pt", "19pt"
// and "27pt" in 3-D. Returns false (stencil untouched) for an unknown name or an isotropic box
// stencil (9pt, 19pt, 27pt) with unequal spacings.
bool make_stencil(const std::string& name, int dim, const double* h, Stencil& out);

} // namespace morphogen
