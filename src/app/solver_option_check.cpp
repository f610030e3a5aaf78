#include "app/solver_option_check.hpp"

#include "core/options.hpp"
#include "core/petsc_handle.hpp"
#include "core/user_error.hpp"

#include <petscsys.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace morphogen {

namespace {

struct Rule {
  const char* suffix;
  double lo, hi;
  bool lo_open, hi_open, integer;
  const char* allowed;
};

constexpr double kBig = 1e300;
const Rule kRules[] = {
    {"ksp_rtol", 0, 1, false, true, false, "allowed [0, 1)"},
    {"ksp_atol", 0, kBig, false, false, false, "allowed a finite number >= 0"},
    {"ksp_divtol", 0, kBig, true, false, false, "allowed a finite number > 0"},
    {"ksp_max_it", 0, kBig, false, false, true, "allowed an integer >= 0"},
    {"pc_mg_levels", 1, kBig, false, false, true, "allowed an integer >= 1"},
    {"ts_rtol", 0, kBig, false, false, false, "allowed a finite number >= 0"},
    {"ts_atol", 0, kBig, false, false, false, "allowed a finite number >= 0"},
    {"snes_rtol", 0, kBig, false, false, false, "allowed a finite number >= 0"},
    {"snes_atol", 0, kBig, false, false, false, "allowed a finite number >= 0"},
    {"snes_stol", 0, kBig, false, false, false, "allowed a finite number >= 0"},
    {"snes_max_it", 0, kBig, false, false, true, "allowed an integer >= 0"},
    {"ts_theta_theta", 0, 1, false, false, false, "allowed [0, 1]"},
    {"ts_max_snes_failures", -1, kBig, false, false, true, "allowed an integer >= -1 (-1: any)"},
    {"ts_max_reject", -1, kBig, false, false, true, "allowed an integer >= -1 (-1: any)"},
};

bool ends_with(const std::string& a, const std::string& e) {
  return a.size() >= e.size() && a.compare(a.size() - e.size(), e.size(), e) == 0;
}

// True when `v` (a number PETSc would read) breaks the rule; text PETSc cannot read is its own.
bool breaks(const Rule& r, const std::string& v) {
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || end == v.c_str() || *end != '\0') return false; // PETSc names it
  if (!std::isfinite(x)) return true;
  if (r.integer && x != std::floor(x)) return false; // PETSc: "not an integer"
  return x < r.lo || x > r.hi || (r.lo_open && x == r.lo) || (r.hi_open && x == r.hi);
}

} // namespace

void check_solver_option_values() {
  for (const auto& [name, value] : all_petsc_options())
    for (const Rule& r : kRules)
      if ((name == r.suffix || ends_with(name, std::string("_") + r.suffix)) && breaks(r, value))
        throw UserError("-" + name + " " + shown(value) + ": out of range, " + r.allowed);
}

} // namespace morphogen
