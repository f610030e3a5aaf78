#include "core/float_env.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace morphogen {

namespace {
#if defined(__SSE2__)
constexpr unsigned kFtzDaz = 0x8040u; // MXCSR: flush to zero (bit 15), denormals are zero (bit 6)
#elif defined(__aarch64__)
constexpr unsigned long kFz = 1ul << 24; // FPCR.FZ
unsigned long read_fpcr() {
  unsigned long r;
  __asm__ volatile("mrs %0, fpcr" : "=r"(r));
  return r;
}
#endif
} // namespace

bool set_flush_subnormals(bool on) {
#if defined(__SSE2__)
  const unsigned csr = _mm_getcsr();
  _mm_setcsr(on ? (csr | kFtzDaz) : (csr & ~kFtzDaz));
  return true;
#elif defined(__aarch64__)
  const unsigned long r = on ? (read_fpcr() | kFz) : (read_fpcr() & ~kFz);
  __asm__ volatile("msr fpcr, %0" : : "r"(r));
  return true;
#else
  (void)on;
  return false;
#endif
}

bool flush_subnormals() {
#if defined(__SSE2__)
  return (_mm_getcsr() & kFtzDaz) == kFtzDaz;
#elif defined(__aarch64__)
  return (read_fpcr() & kFz) != 0;
#else
  return false;
#endif
}

} // namespace morphogen
