// Pure kernels of the 2-D stable-fluids solver (operators/fluid_solver.hpp; Stam 1999, used by
// the stable-ARD paper section 5): the face rules of the cell-centred approximate projection
// and of the implicit viscosity, per cell face. No PETSc, MPI, allocation or exceptions.
//
// Velocity (u, v) lives at cell centres. A face between cell c and its neighbour n along axis
// d (side s = +1: the face at i + 1/2, s = -1: at i - 1/2) is one of
//   Open     both cells fluid:     normal velocity (u_c + u_n)/2, pressure gradient
//                                   s (p_n - p_c)/h
//   Closed   wall, solid or inflow: prescribed normal velocity g, pressure gradient 0
//                                   (homogeneous Neumann for p)
//   Outflow  open boundary:         normal velocity u_c (zero gradient), p = 0 on the face
//                                   (p_ghost = -p_c): gradient -2 s p_c / h
// The projection solves A p = -div(u_f) with the rows of A = -(D G) from these rules
// (A p)_c = sum_faces w_diag p_c + w_nb p_n / h^2, so the corrected face velocities
// u_f - G p have discrete divergence div - D G p = 0 up to the solver's residual.
// Cell velocities are corrected by the mean of the gradients of their non-closed faces along
// each axis (Almgren-Bell-Szymczak's approximate projection).
//
// Viscosity (I - dt nu L) u = u* per component, cell-centred 5-point L with face rules
//   Interior   neighbour coupling; Dirichlet g: u_ghost = 2 g - u_c (no-slip, lid, inflow);
//   Neumann    du/dn = 0 (outflow, free-slip tangential component).
#pragma once

#include "models/model.hpp" // MG_HD

namespace morphogen::fluid {

enum class Kind { Cavity, Channel, Periodic };
enum class ProjFace : unsigned char { Open, Closed, Outflow };
enum class ViscFace : unsigned char { Interior, Dirichlet, Neumann };

// One face of a cell: its projection rule with the prescribed normal velocity g (Closed), and
// its viscous rule per velocity component with the wall value gv[component] (Dirichlet).
struct Face {
  ProjFace proj = ProjFace::Open;
  double g = 0.0;
  ViscFace visc[2] = {ViscFace::Interior, ViscFace::Interior};
  double gv[2] = {0.0, 0.0};
};

// A face between two fluid cells.
MG_HD inline Face open_face() {
  return Face{};
}

// A face touching a solid cell: no-slip, no flux.
MG_HD inline Face solid_face() {
  Face f;
  f.proj = ProjFace::Closed;
  f.visc[0] = f.visc[1] = ViscFace::Dirichlet;
  return f;
}

// A face on the domain boundary along axis d (0: x, 1: y), side s (-1: low, +1: high).
//   cavity   no-slip walls, the top wall (d = 1, s = +1) moves with u = lid
//   channel  inflow u = inflow, v = 0 on the left; outflow on the right; free-slip bottom/top
MG_HD inline Face boundary_face(Kind kind, int d, int s, double lid, double inflow) {
  Face f = solid_face();
  if (kind == Kind::Cavity) {
    if (d == 1 && s > 0) f.gv[0] = lid;
    return f;
  }
  if (d == 0 && s < 0) { // inflow
    f.g = inflow;
    f.gv[0] = inflow;
    return f;
  }
  if (d == 0) { // outflow
    f.proj = ProjFace::Outflow;
    f.visc[0] = f.visc[1] = ViscFace::Neumann;
    return f;
  }
  f.visc[0] = ViscFace::Neumann; // free slip: tangential u free, normal v = 0
  return f;
}

// Normal velocity on the face from the cell value uc and the neighbour's un.
MG_HD inline double face_velocity(const Face& f, double uc, double un) {
  return f.proj == ProjFace::Open ? 0.5 * (uc + un) : (f.proj == ProjFace::Closed ? f.g : uc);
}

// d p / dx_d on the face at side s (pc: the cell's p, pn: the neighbour's; h: spacing).
MG_HD inline double face_gradient(const Face& f, int s, double pc, double pn, double h) {
  if (f.proj == ProjFace::Open) return s * (pn - pc) / h;
  if (f.proj == ProjFace::Outflow) return -2.0 * s * pc / h;
  return 0.0;
}

// Weights of the face in row c of A = -(D G): A_cc += diag, A_cn += nb (h: spacing).
MG_HD inline void poisson_weights(const Face& f, double h, double& diag, double& nb) {
  const double w = 1.0 / (h * h);
  diag = f.proj == ProjFace::Open ? w : (f.proj == ProjFace::Outflow ? 2.0 * w : 0.0);
  nb = f.proj == ProjFace::Open ? -w : 0.0;
}

// Weights of the face in row c of (I - c L) for component q (c = dt nu): A_cc += diag,
// A_cn += nb, rhs_c += rhs.
MG_HD inline void viscous_weights(const Face& f, int q, double c, double h, double& diag,
                                  double& nb, double& rhs) {
  const double w = c / (h * h);
  diag = nb = rhs = 0.0;
  if (f.visc[q] == ViscFace::Interior) {
    diag = w;
    nb = -w;
  } else if (f.visc[q] == ViscFace::Dirichlet) {
    diag = 2.0 * w;
    rhs = 2.0 * w * f.gv[q];
  }
}

} // namespace morphogen::fluid
