// Ownership of SUNDIALS objects.
//
// SUNDIALS hands out raw C handles that must be released in a fixed order (solver memory
// before the objects it references, everything before its SUNContext). Wrapping each handle in
// a unique_ptr with its own deleter makes that order the reverse of member declaration order and
// keeps every error path leak-free. The make* functions throw std::runtime_error when SUNDIALS
// cannot allocate: that is exceptional, unlike a Newton failure, which is a result.
#pragma once

#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>

#include <memory>
#include <type_traits>

namespace buckle::continuation {

struct SunContextDeleter {
  void operator()(std::remove_pointer_t<SUNContext> *context) const noexcept;
};
struct NVectorDeleter {
  void operator()(std::remove_pointer_t<N_Vector> *vector) const noexcept;
};
struct SunMatrixDeleter {
  void operator()(std::remove_pointer_t<SUNMatrix> *matrix) const noexcept;
};
struct SunLinearSolverDeleter {
  void operator()(std::remove_pointer_t<SUNLinearSolver> *solver) const noexcept;
};
struct KinsolMemoryDeleter {
  void operator()(void *memory) const noexcept;
};

using SunContextPtr = std::unique_ptr<std::remove_pointer_t<SUNContext>, SunContextDeleter>;
using NVectorPtr = std::unique_ptr<std::remove_pointer_t<N_Vector>, NVectorDeleter>;
using SunMatrixPtr = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, SunMatrixDeleter>;
using SunLinearSolverPtr = std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, SunLinearSolverDeleter>;
using KinsolMemoryPtr = std::unique_ptr<void, KinsolMemoryDeleter>;

SunContextPtr makeSunContext();
/// Serial vector of length n, zero-initialised.
NVectorPtr makeSerialVector(sunindextype n, SUNContext context);
/// Dense column-major rows×cols matrix, zero-initialised.
SunMatrixPtr makeDenseMatrix(sunindextype rows, sunindextype cols, SUNContext context);
/// Dense LU solver for `matrix`, templated on `vector`.
SunLinearSolverPtr makeDenseLinearSolver(N_Vector vector, SUNMatrix matrix, SUNContext context);
/// An empty SUNMatrix of ID SUNMATRIX_CUSTOM: a placeholder for KINSOL's matrix-based
/// interface when a custom linear solver holds the factorization itself.
SunMatrixPtr makeEmptyCustomMatrix(SUNContext context);
/// A SUNLinearSolver of type DIRECT whose solve() is `solve` and whose setup() is `setup`
/// (null: setup does nothing, the factorization happens in the Jacobian callback). `data` is
/// returned by customLinearSolverData() and is not owned. Return values follow SUNDIALS: 0
/// success, > 0 recoverable (e.g. SUNLS_LUFACT_FAIL), < 0 unrecoverable.
using CustomSolveFn = int (*)(SUNLinearSolver, SUNMatrix, N_Vector x, N_Vector b, realtype tol);
using CustomSetupFn = int (*)(SUNLinearSolver, SUNMatrix);
SunLinearSolverPtr makeCustomDirectLinearSolver(CustomSolveFn solve, void *data, SUNContext context,
                                                CustomSetupFn setup = nullptr);
void *customLinearSolverData(SUNLinearSolver solver);
/// KINSOL memory that never prints: errors go to a handler the caller installs (or nowhere).
KinsolMemoryPtr makeKinsolMemory(SUNContext context);

/// Symbolic name of a KINSOL return flag ("KIN_SUCCESS", "KIN_LINESEARCH_NONCONV", ...);
/// "KIN_UNKNOWN_FLAG" for anything else. Static storage: never free the result.
const char *kinsolFlagName(int flag);

}  // namespace buckle::continuation
