// Model parameters that depend on time (values using t, e.g. -params_s "1/128 + t*1e-6"):
// set_time(t) re-evaluates them into the run's ParamSet, a scalar when the value depends on t
// only, the parameter's field Vec otherwise, with the parameter's range checked at every time
// (a one-line UserError naming the key, the value and t). Parameters constant in time are not
// touched, so runs without t keep their cost. Integrators call set_time once per step (the
// explicit step at t, the split step at its midpoint) and the TS right-hand side at each stage
// time.
#pragma once

#include "fields/param_set.hpp"
#include "fields/value_spec.hpp"

#include <memory>
#include <vector>

namespace morphogen {

class TimedParams {
public:
  explicit TimedParams(const Grid& grid) : grid_(grid) {}
  // Parameter q of `params` follows `spec` (which uses t); its range is [lo, hi].
  void add(int q, std::unique_ptr<ValueSpec> spec, double lo, double hi);
  bool any() const { return !entries_.empty(); }
  // Evaluate every timed parameter at t into `params` (nothing when t is the last time).
  // Collective when a parameter is a field.
  void set_time(ParamSet& params, double t);

private:
  struct Entry {
    int q;
    std::unique_ptr<ValueSpec> spec;
    double lo, hi;
  };
  const Grid& grid_;
  std::vector<Entry> entries_;
  double last_t_ = 0;
  bool evaluated_ = false;
};

} // namespace morphogen
