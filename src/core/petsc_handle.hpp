// RAII owners for PETSc objects (Vec, DM, ...): destroy on scope exit, so an exception
// (UserError) unwinding through morphogen's own code leaks nothing. Destroy errors are ignored
// (a destructor cannot report them; PETSc prints its own trace).
#pragma once

#include <petscdm.h>
#include <petscksp.h>
#include <petscmat.h>
#include <petscsf.h>
#include <petscts.h>
#include <petscvec.h>
#include <string>
#include <utility>

namespace morphogen {

template <class T, PetscErrorCode (*Destroy)(T*)> class PetscHandle {
public:
  PetscHandle() = default;
  explicit PetscHandle(T obj) : obj_(obj) {}
  PetscHandle(const PetscHandle&) = delete;
  PetscHandle& operator=(const PetscHandle&) = delete;
  PetscHandle(PetscHandle&& o) noexcept : obj_(std::exchange(o.obj_, nullptr)) {}
  PetscHandle& operator=(PetscHandle&& o) noexcept {
    if (this != &o) {
      reset();
      obj_ = std::exchange(o.obj_, nullptr);
    }
    return *this;
  }
  ~PetscHandle() { reset(); }
  void reset() {
    if (obj_) (void)Destroy(&obj_);
    obj_ = nullptr;
  }
  T get() const { return obj_; }
  T* out() {
    reset();
    return &obj_;
  }
  operator T() const { return obj_; }

private:
  T obj_ = nullptr;
};

using VecH = PetscHandle<Vec, VecDestroy>;
using DMH = PetscHandle<DM, DMDestroy>;
using SFH = PetscHandle<PetscSF, PetscSFDestroy>;
using MatH = PetscHandle<Mat, MatDestroy>;
using KSPH = PetscHandle<KSP, KSPDestroy>;
using TSH = PetscHandle<TS, TSDestroy>;

// Throwing wrapper for PETSc calls made from code that cannot return PetscErrorCode
// (constructors, destructors' callers). PETSc has already printed its trace when this fires.
struct PetscFailure : std::exception {
  PetscErrorCode code;
  explicit PetscFailure(PetscErrorCode c) : code(c) {}
  const char* what() const noexcept override { return "PETSc error (trace above)"; }
};

} // namespace morphogen

namespace morphogen {
// Run PETSc calls with errors returned instead of printed as a trace, for errors caused by
// user input (an unparsable deck, a grid too small for the rank count). Returns PETSc's
// message, or "" on success.
// PETSc error handler that keeps the innermost error's message (ctx: std::string*).
inline PetscErrorCode petsc_capture_error(MPI_Comm, int, const char*, const char*, PetscErrorCode n,
                                          PetscErrorType, const char* mess, void* ctx) {
  auto* out = static_cast<std::string*>(ctx);
  if (out->empty() && mess) {
    *out = mess;
    while (!out->empty() && (out->back() == '\n' || out->back() == ' '))
      out->pop_back();
  }
  return n;
}

template <class F> std::string petsc_quietly(F&& f) {
  std::string detail;
  PetscPushErrorHandler(petsc_capture_error, &detail);
  const PetscErrorCode ierr = f();
  PetscPopErrorHandler();
  if (!ierr) return {};
  const char* text = nullptr;
  PetscErrorMessage(ierr, &text, nullptr);
  std::string msg = text ? text : "error";
  if (!detail.empty() && detail != msg) msg += ": " + detail;
  return msg;
}
} // namespace morphogen

// PetscCall for functions that do not return PetscErrorCode: PETSc prints its trace, then we
// throw so main() can finalise cleanly and exit non-zero.
#define MG_PETSC(...)                                                                              \
  do {                                                                                             \
    PetscErrorCode mg_ierr_ = (__VA_ARGS__);                                                       \
    if (PetscUnlikely(mg_ierr_)) {                                                                 \
      (void)PetscError(PETSC_COMM_SELF, __LINE__, PETSC_FUNCTION_NAME, __FILE__, mg_ierr_,         \
                       PETSC_ERROR_REPEAT, " ");                                                   \
      throw ::morphogen::PetscFailure(mg_ierr_);                                                   \
    }                                                                                              \
  } while (0)
