// The process's handling of subnormal floating-point numbers (|x| < 2.2e-308 in double).
//
// With flushing on, the CPU treats subnormal inputs as zero and returns zero for subnormal
// results (x86: the MXCSR bits FTZ and DAZ; AArch64: FPCR.FZ) instead of gradual underflow.
// A field decaying towards zero (a species dying out, the far tail of a Gaussian) otherwise
// spends most of its arithmetic in the microcode assist that subnormals take on many CPUs
// (measured on an Intel Xeon: a Gray-Scott run whose activator dies out 21x slower per step,
// the Gray-Scott sweep deck 5x slower). Values differ only where IEEE
// arithmetic would have produced a number below 2.2e-308.
#pragma once

namespace morphogen {

// Sets flushing on or off for the calling thread (MPI ranks are processes: each sets its own).
// Returns false where the target has no such control (then arithmetic stays IEEE).
bool set_flush_subnormals(bool on);
// Whether flushing is on for the calling thread.
bool flush_subnormals();

} // namespace morphogen
