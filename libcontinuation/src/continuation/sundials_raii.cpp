#include "buckle/continuation/internal/sundials_raii.h"

#include "buckle/continuation/internal/serial_vector_ops.h"

#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <cmath>
#include <stdexcept>

namespace buckle::continuation {

namespace {
// KINSOL's default handler prints to stderr; a library must stay silent unless asked.
void silentErrorHandler(int, const char *, const char *, char *, void *) {}

SUNMatrix_ID customMatrixId(SUNMatrix) { return SUNMATRIX_CUSTOM; }
int customMatrixZero(SUNMatrix) { return 0; }  // nothing stored: the solver holds the factors

// The custom solver's content is the caller's `data`, which it does not own.
struct CustomSolverContent {
  CustomSolveFn solve;
  CustomSetupFn setup;
  void *data;
};
SUNLinearSolver_Type customSolverType(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
SUNLinearSolver_ID customSolverId(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int customSolverSetup(SUNLinearSolver solver, SUNMatrix A) {
  const auto *content = static_cast<CustomSolverContent *>(solver->content);
  return content->setup ? content->setup(solver, A) : SUNLS_SUCCESS;
}
int customSolverSolve(SUNLinearSolver solver, SUNMatrix A, N_Vector x, N_Vector b, realtype tol) {
  return static_cast<CustomSolverContent *>(solver->content)->solve(solver, A, x, b, tol);
}
int customSolverFree(SUNLinearSolver solver) {
  if (solver == nullptr) return SUNLS_SUCCESS;
  delete static_cast<CustomSolverContent *>(solver->content);
  solver->content = nullptr;
  SUNLinSolFreeEmpty(solver);
  return SUNLS_SUCCESS;
}
// serial_vector_ops.h: the operations of N_V*_Serial (SUNDIALS 6.4), same order of operations.
realtype leanWL2Norm(N_Vector x, N_Vector w) {
  const sunindextype n = NV_LENGTH_S(x);
  const realtype *xd = NV_DATA_S(x), *wd = NV_DATA_S(w);
  realtype sum = 0.0;
  for (sunindextype i = 0; i < n; ++i) {
    const realtype p = xd[i] * wd[i];
    sum += p * p;
  }
  return std::sqrt(sum);
}
void leanProd(N_Vector x, N_Vector y, N_Vector z) {
  const sunindextype n = NV_LENGTH_S(x);
  const realtype *xd = NV_DATA_S(x), *yd = NV_DATA_S(y);
  realtype *zd = NV_DATA_S(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] * yd[i];
}
realtype leanMaxNorm(N_Vector x) {
  const sunindextype n = NV_LENGTH_S(x);
  const realtype *xd = NV_DATA_S(x);
  realtype max = 0.0;
  for (sunindextype i = 0; i < n; ++i)
    if (std::abs(xd[i]) > max) max = std::abs(xd[i]);
  return max;
}
realtype leanMin(N_Vector x) {
  const sunindextype n = NV_LENGTH_S(x);
  const realtype *xd = NV_DATA_S(x);
  realtype min = xd[0];
  for (sunindextype i = 1; i < n; ++i)
    if (xd[i] < min) min = xd[i];
  return min;
}
// c·x_i: for c = 1 and c = −1 exactly the library's copy and negation.
void leanScale(realtype c, N_Vector x, N_Vector z) {
  const sunindextype n = NV_LENGTH_S(x);
  const realtype *xd = NV_DATA_S(x);
  realtype *zd = NV_DATA_S(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c * xd[i];
}
// z = x + y for a = b = 1 (KINSOL's full Newton step u + p): every branch of the library's
// N_VLinearSum_Serial for a = b = 1 (its two in-place axpy cases and VSum) adds x_i and y_i, and
// IEEE addition is commutative, so this is the library's result bit for bit; any other a, b goes to
// the library's own function, special cases and all.
void leanLinearSum(realtype a, N_Vector x, realtype b, N_Vector y, N_Vector z) {
  if (a != 1.0 || b != 1.0) {
    N_VLinearSum_Serial(a, x, b, y, z);
    return;
  }
  const sunindextype n = NV_LENGTH_S(x);
  const realtype *xd = NV_DATA_S(x), *yd = NV_DATA_S(y);
  realtype *zd = NV_DATA_S(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] + yd[i];
}
void leanConst(realtype c, N_Vector z) {
  const sunindextype n = NV_LENGTH_S(z);
  realtype *zd = NV_DATA_S(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c;
}
}  // namespace

void useLeanSerialOperations(N_Vector v) {
  if (N_VGetVectorID(v) != SUNDIALS_NVEC_SERIAL)
    throw std::invalid_argument("useLeanSerialOperations: not a serial N_Vector");
  v->ops->nvwl2norm = leanWL2Norm;
  v->ops->nvprod = leanProd;
  v->ops->nvmaxnorm = leanMaxNorm;
  v->ops->nvmin = leanMin;
  v->ops->nvscale = leanScale;
  v->ops->nvconst = leanConst;
  v->ops->nvlinearsum = leanLinearSum;
}

void SunContextDeleter::operator()(std::remove_pointer_t<SUNContext> *context) const noexcept {
  SUNContext handle = context;
  SUNContext_Free(&handle);
}
void NVectorDeleter::operator()(std::remove_pointer_t<N_Vector> *vector) const noexcept { N_VDestroy(vector); }
void SunMatrixDeleter::operator()(std::remove_pointer_t<SUNMatrix> *matrix) const noexcept {
  SUNMatDestroy(matrix);
}
void SunLinearSolverDeleter::operator()(std::remove_pointer_t<SUNLinearSolver> *solver) const noexcept {
  SUNLinSolFree(solver);
}
void KinsolMemoryDeleter::operator()(void *memory) const noexcept { KINFree(&memory); }

SunContextPtr makeSunContext() {
  SUNContext context = nullptr;
  if (SUNContext_Create(nullptr, &context) != 0 || context == nullptr)
    throw std::runtime_error("SUNContext_Create failed");
  return SunContextPtr(context);
}

NVectorPtr makeSerialVector(sunindextype n, SUNContext context) {
  NVectorPtr vector(N_VNew_Serial(n, context));
  if (!vector) throw std::runtime_error("N_VNew_Serial failed");
  N_VConst(0.0, vector.get());
  return vector;
}

SunMatrixPtr makeDenseMatrix(sunindextype rows, sunindextype cols, SUNContext context) {
  SunMatrixPtr matrix(SUNDenseMatrix(rows, cols, context));
  if (!matrix) throw std::runtime_error("SUNDenseMatrix failed");
  SUNMatZero(matrix.get());
  return matrix;
}

SunLinearSolverPtr makeDenseLinearSolver(N_Vector vector, SUNMatrix matrix, SUNContext context) {
  SunLinearSolverPtr solver(SUNLinSol_Dense(vector, matrix, context));
  if (!solver) throw std::runtime_error("SUNLinSol_Dense failed");
  return solver;
}

SunMatrixPtr makeEmptyCustomMatrix(SUNContext context) {
  SunMatrixPtr matrix(SUNMatNewEmpty(context));
  if (!matrix) throw std::runtime_error("SUNMatNewEmpty failed");
  matrix->ops->getid = customMatrixId;
  matrix->ops->zero = customMatrixZero;
  return matrix;
}

SunLinearSolverPtr makeCustomDirectLinearSolver(CustomSolveFn solve, void *data, SUNContext context,
                                                CustomSetupFn setup) {
  SunLinearSolverPtr solver(SUNLinSolNewEmpty(context));
  if (!solver) throw std::runtime_error("SUNLinSolNewEmpty failed");
  solver->ops->gettype = customSolverType;
  solver->ops->getid = customSolverId;
  solver->ops->setup = customSolverSetup;
  solver->ops->solve = customSolverSolve;
  solver->ops->free = customSolverFree;
  solver->content = new CustomSolverContent{solve, setup, data};
  return solver;
}

void *customLinearSolverData(SUNLinearSolver solver) {
  return static_cast<CustomSolverContent *>(solver->content)->data;
}

KinsolMemoryPtr makeKinsolMemory(SUNContext context) {
  KinsolMemoryPtr memory(KINCreate(context));
  if (!memory) throw std::runtime_error("KINCreate failed");
  KINSetErrHandlerFn(memory.get(), silentErrorHandler, nullptr);
  KINSetPrintLevel(memory.get(), 0);
  return memory;
}

const char *kinsolFlagName(int flag) {
  // A static table rather than KINGetReturnFlagName, whose result is malloc'd and would have to
  // be freed by every caller.
  switch (flag) {
    case KIN_SUCCESS: return "KIN_SUCCESS";
    case KIN_INITIAL_GUESS_OK: return "KIN_INITIAL_GUESS_OK";
    case KIN_STEP_LT_STPTOL: return "KIN_STEP_LT_STPTOL";
    case KIN_WARNING: return "KIN_WARNING";
    case KIN_MEM_NULL: return "KIN_MEM_NULL";
    case KIN_ILL_INPUT: return "KIN_ILL_INPUT";
    case KIN_NO_MALLOC: return "KIN_NO_MALLOC";
    case KIN_MEM_FAIL: return "KIN_MEM_FAIL";
    case KIN_LINESEARCH_NONCONV: return "KIN_LINESEARCH_NONCONV";
    case KIN_MAXITER_REACHED: return "KIN_MAXITER_REACHED";
    case KIN_MXNEWT_5X_EXCEEDED: return "KIN_MXNEWT_5X_EXCEEDED";
    case KIN_LINESEARCH_BCFAIL: return "KIN_LINESEARCH_BCFAIL";
    case KIN_LINSOLV_NO_RECOVERY: return "KIN_LINSOLV_NO_RECOVERY";
    case KIN_LINIT_FAIL: return "KIN_LINIT_FAIL";
    case KIN_LSETUP_FAIL: return "KIN_LSETUP_FAIL";
    case KIN_LSOLVE_FAIL: return "KIN_LSOLVE_FAIL";
    case KIN_SYSFUNC_FAIL: return "KIN_SYSFUNC_FAIL";
    case KIN_FIRST_SYSFUNC_ERR: return "KIN_FIRST_SYSFUNC_ERR";
    case KIN_REPTD_SYSFUNC_ERR: return "KIN_REPTD_SYSFUNC_ERR";
    case KIN_VECTOROP_ERR: return "KIN_VECTOROP_ERR";
    case KIN_CONTEXT_ERR: return "KIN_CONTEXT_ERR";
    default: return "KIN_UNKNOWN_FLAG";
  }
}

}  // namespace buckle::continuation
