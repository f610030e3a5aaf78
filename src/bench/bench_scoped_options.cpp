#include "bench/bench_scoped_options.hpp"

#include "core/petsc_handle.hpp"

#include <petscsys.h>

#include <string>
#include <vector>

namespace morphogen {

namespace {

struct HeldOption {
  const char* key;
  const char* integrator;
  bool set = false;
  std::string value;
};

std::vector<HeldOption>& held() {
  static std::vector<HeldOption> options = [] {
    std::vector<HeldOption> v;
    for (const char* k : {"-explicit_in_place", "-explicit_vector_width", "-explicit_fuse_tile",
                          "-explicit_fuse_steps", "-explicit_prefetch"})
      v.push_back({k, "explicit", false, {}});
    for (const char* k : {"-ts_diffusion", "-ts_diffusion_solver"})
      v.push_back({k, "ts", false, {}});
    return v;
  }();
  return options;
}

} // namespace

void hold_integrator_options() {
  for (HeldOption& h : held()) {
    char buf[256] = {};
    PetscBool set = PETSC_FALSE;
    MG_PETSC(PetscOptionsGetString(nullptr, nullptr, h.key, buf, sizeof buf, &set));
    h.set = set == PETSC_TRUE;
    h.value = buf;
    MG_PETSC(PetscOptionsClearValue(nullptr, h.key));
  }
}

void apply_integrator_options() {
  char buf[64] = "explicit";
  PetscBool set = PETSC_FALSE;
  MG_PETSC(PetscOptionsGetString(nullptr, nullptr, "-integrator", buf, sizeof buf, &set));
  const std::string integrator = buf;
  for (const HeldOption& h : held()) {
    if (!h.set) continue; // the bench's own value, if any (e.g. the fused section's k)
    if (integrator == h.integrator)
      MG_PETSC(PetscOptionsSetValue(nullptr, h.key, h.value.empty() ? nullptr : h.value.c_str()));
    else
      MG_PETSC(PetscOptionsClearValue(nullptr, h.key));
  }
}

} // namespace morphogen
