// Solution-dependent diffusion of one species from the options database
// (operators/state_diffusion.hpp, operators/polar_diffusion.hpp):
//
//   -diffusion_S polar    D_S a(theta + theta0), theta the angle of grad u_S (2-D runs)
//     -polar_form cosine|witkin_kass    eq. 16 (j cosine lobes) or eq. 15 (four lobes a1, a2)
//     -polar_lobes j                    cosine lobes, 1..16 (default 4)
//     -polar_speeds a1,..,aj            lobe speeds >= 0 (one value: every lobe); Witkin-Kass a1,a2
//     -polar_theta0 VALUE               rotation (radians): a number or any field value
//   -diffusion_S shaped   D_S times the -tensor_theta/l1/l2 (3-D: phi, l3) tensor with l1 + dl,
//                         l2 - dl, dl = I (grad u/|grad u|).(v/|v|)
//     -shaped_I I                       scaling constant, 0 <= I < min(l1, l2) at every cell
//     -shaped_vx, -shaped_vy, -shaped_vz  the direction field v (values; default e1, the
//                                       tensor's first principal direction)
// Every key also per species (-polar_S_form, -shaped_S_I, ...), overriding the shared one.
#pragma once

#include "app/diffusion_setup.hpp"
#include "fields/value_spec.hpp"

namespace morphogen {

// -diffusion / -diffusion_S: iso, tensor, polar or shaped.
std::string read_diffusion_kind(Options& opt, const std::string& name);

// Species `name`'s polar or shaped diffusion (D: its -D_S value). Collective.
DiffusionSetup read_state_diffusion(Options& opt, const Grid& grid, const Halo& halo,
                                    const std::string& name, const std::string& kind, ValueSpec& D,
                                    std::uint64_t seed, const std::string& base_dir);

} // namespace morphogen
