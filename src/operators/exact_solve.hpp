// A direct (non-iterative) implicit diffusion substep with a constant-coefficient operator M,
// exact to rounding (no tolerance):
//   step:           u <- (I - theta c M)^-1 (I + (1 - theta) c M) u
//   solve_shifted:  x  = (I - theta c M)^-1 r
// Implementations: operators/spectral_solver.hpp (transform on every axis),
// operators/tridiagonal_solver.hpp (transform across, tridiagonal along the slowest axis).
#pragma once

#include <petscvec.h>
#include <stdexcept>
#include <string>

namespace morphogen {

class ExactSolve {
public:
  virtual ~ExactSolve() = default;
  virtual void step(Vec u, double c, double theta) = 0;
  virtual void solve_shifted(Vec r, Vec x, double c, double theta) = 0;
  // step on the owned cells of a ghosted local vector (ghosts untouched), where the method can
  // read and write it in place (steps_local()); elsewhere the caller copies the owned cells to
  // a global vector and calls step.
  virtual bool steps_local() const { return false; }
  virtual void step_local(Vec /*ulocal*/, double /*c*/, double /*theta*/) {
    throw std::logic_error("ExactSolve::step_local: not offered by " + method());
  }
  // step_local in two halves, so that one species' wait for the other ranks overlaps the next
  // species' work: begin does what needs no other rank's result yet, end the rest; ulocal is not
  // to be touched between them. Default: all of it in begin.
  virtual void step_local_begin(Vec ulocal, double c, double theta) {
    step_local(ulocal, c, theta);
  }
  virtual void step_local_end(Vec /*ulocal*/) {}
  // For the setup log, e.g. "spectral (FFT/DCT, exact)".
  virtual std::string method() const = 0;
};

} // namespace morphogen
