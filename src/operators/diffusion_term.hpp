// The diffusion term of one species, div(K_s grad u_s) (operators/diffusion_operator.hpp),
// as a term of the run: linear, halo of width 1 (box corners for tensors and the 9pt stencil),
// stable for dt <= 2 / radius. Explicit rates need the state's ghosts filled, boundary values
// included (the Dirichlet ghosts carry the boundary data).
#pragma once

#include "operators/diffusion_operator.hpp"
#include "operators/term.hpp"

namespace morphogen {

class DiffusionTerm : public Term {
public:
  // Keeps a reference to `op` (owned by the run).
  DiffusionTerm(int species, std::string name, const DiffusionOperator& op);

  Kind kind() const override { return Kind::Diffusion; }
  std::string describe() const override;
  HaloNeed halo() const override { return {1, op_.box()}; }
  double stable_dt() const override;
  bool linear() const override { return true; }
  void add_rates(const StateArrays& state, double t, const RateArrays& rates) const override;

  int species() const { return s_; }
  const DiffusionOperator& op() const { return op_; }

private:
  int s_;
  std::string name_;
  const DiffusionOperator& op_;
  mutable std::vector<double> row_, plain_; // row buffer; de-interlaced state (stride > 1)
};

} // namespace morphogen
