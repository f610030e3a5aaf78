// Optional source terms S_s(x, t) added to the reaction of each species:
//   du_s/dt = D_s lap u_s + R_s(u; p) + S_s(x, t)
// given per species by -source_<species> VALUE (a value specification that may use t). Used by
// manufactured-solution verification and for forcing. Sources that do not use t are evaluated
// once; the others at every requested time, into owned-layout arrays (x fastest).
#pragma once

#include "core/options.hpp"
#include "fields/value_spec.hpp"

#include <memory>
#include <string>
#include <vector>

namespace morphogen {

class SourceTerms {
public:
  SourceTerms(const Grid& grid, Options& opt, const std::vector<std::string>& species,
              std::uint64_t seed, const std::string& base_dir);

  bool any() const { return any_; }
  bool has(int s) const { return spec_[s] != nullptr; }
  // Values of species s at time t, owned layout; nullptr when species s has no source. Two
  // slots (0 and 1) hold two times at once (start and end of a step).
  const double* at(int s, double t, int slot = 0);

private:
  const Grid& grid_;
  bool any_ = false;
  std::vector<std::unique_ptr<ValueSpec>> spec_;
  std::vector<std::vector<double>> value_[2];
  std::vector<double> time_[2];
};

} // namespace morphogen
