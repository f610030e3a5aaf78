// Coefficient rules of solution-dependent diffusion (operators/state_diffusion.hpp):
//
//   PolarRule   K = D(x) a(theta + theta0(x)) (scalar; the face coefficient is the mean of the
//               two cells', stable-ARD eq. 17), theta the angle of grad u (polar_kernel.hpp)
//   ShapedRule  K = D(x) (l1 + dl) e1 e1^T + (l2 - dl) e2 e2^T [+ l3 e3 e3^T],
//               dl = I (grad u/|grad u|).(v/|v|) (Sanderson eqs. 18-19), second-order tensor
//               scheme (or Witkin-Kass's first-order masks)
// The per-cell inputs are arrays in the grid's ghosted layout (owned cells set), fixed for the
// run; max_eigenvalue() is their collective bound over every state.
#pragma once

#include "operators/polar_kernel.hpp"
#include "operators/state_diffusion.hpp"

namespace morphogen {

class PolarRule : public CoefficientRule {
public:
  // D, theta0: ghosted-layout arrays. Collective (the bound).
  PolarRule(const Grid& grid, const PolarLobes& lobes, std::vector<double> D,
            std::vector<double> theta0);
  DiffusionScheme scheme() const override { return DiffusionScheme::IsotropicField; }
  int components() const override { return 1; }
  double max_eigenvalue() const override { return lmax_; }
  std::string describe() const override;
  void at(PetscInt c, const double* g, double* coef) const override {
    coef[0] = D_[c] * lobes_(gradient_angle(g) + theta0_[c]);
  }

private:
  PolarLobes lobes_;
  std::vector<double> D_, theta0_;
  double lmax_ = 0;
};

class ShapedRule : public CoefficientRule {
public:
  // Per cell (ghosted layout): frame[c * 9 + 3 n + a] = component a of e_{n+1};
  // l[c * dim + n] = D l_{n+1}; v[c * dim + a]; I (times D at the cell). Collective.
  ShapedRule(const Grid& grid, DiffusionScheme scheme, std::vector<double> frame,
             std::vector<double> l, std::vector<double> D, std::vector<double> v, double I);
  DiffusionScheme scheme() const override { return scheme_; }
  int components() const override { return dim_ == 2 ? 3 : 6; }
  double max_eigenvalue() const override { return lmax_; }
  std::string describe() const override;
  void at(PetscInt c, const double* g, double* coef) const override;

private:
  int dim_;
  DiffusionScheme scheme_;
  std::vector<double> frame_, l_, D_, v_;
  double I_, lmax_ = 0;
};

} // namespace morphogen
