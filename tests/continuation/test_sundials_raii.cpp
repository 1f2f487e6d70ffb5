#include "buckle/continuation/sundials_raii.h"

#include <catch2/catch.hpp>
#include <sunmatrix/sunmatrix_dense.h>

#include <cstdlib>
#include <string>

using namespace buckle::continuation;

TEST_CASE("SUNDIALS objects are created and released many times", "[sundials_raii]") {
  for (int repeat = 0; repeat < 200; ++repeat) {
    SunContextPtr context = makeSunContext();
    REQUIRE(context);
    NVectorPtr vector = makeSerialVector(7, context.get());
    REQUIRE(vector);
    REQUIRE(N_VGetLength(vector.get()) == 7);
    CHECK(N_VMaxNorm(vector.get()) == 0.0);
    SunMatrixPtr matrix = makeDenseMatrix(7, 7, context.get());
    REQUIRE(matrix);
    CHECK(SUNDenseMatrix_Rows(matrix.get()) == 7);
    SunLinearSolverPtr solver = makeDenseLinearSolver(vector.get(), matrix.get(), context.get());
    REQUIRE(solver);
    KinsolMemoryPtr kinsol = makeKinsolMemory(context.get());
    REQUIRE(kinsol);
    // Release order is the reverse of declaration: KINSOL, solver, matrix, vector, context.
  }
}

TEST_CASE("Moved SUNDIALS handles keep single ownership", "[sundials_raii]") {
  SunContextPtr context = makeSunContext();
  NVectorPtr a = makeSerialVector(3, context.get());
  N_Vector raw = a.get();
  NVectorPtr b = std::move(a);
  CHECK(a.get() == nullptr);
  CHECK(b.get() == raw);
  b.reset();
  CHECK(b.get() == nullptr);
}

TEST_CASE("kinsolFlagName matches KINSOL's own names", "[sundials_raii]") {
  for (int flag : {KIN_SUCCESS, KIN_INITIAL_GUESS_OK, KIN_STEP_LT_STPTOL, KIN_WARNING, KIN_MEM_NULL, KIN_ILL_INPUT,
                   KIN_NO_MALLOC, KIN_MEM_FAIL, KIN_LINESEARCH_NONCONV, KIN_MAXITER_REACHED, KIN_MXNEWT_5X_EXCEEDED,
                   KIN_LINESEARCH_BCFAIL, KIN_LINSOLV_NO_RECOVERY, KIN_LINIT_FAIL, KIN_LSETUP_FAIL, KIN_LSOLVE_FAIL,
                   KIN_SYSFUNC_FAIL, KIN_FIRST_SYSFUNC_ERR, KIN_REPTD_SYSFUNC_ERR, KIN_VECTOROP_ERR}) {
    char *reference = KINGetReturnFlagName(flag);  // malloc'd by KINSOL
    REQUIRE(reference != nullptr);
    // KINSOL 6.4 answers "NONE" for the system-function and vector-op flags; ours names them.
    if (std::string(reference) != "NONE") CHECK(std::string(kinsolFlagName(flag)) == std::string(reference));
    else CHECK(std::string(kinsolFlagName(flag)).rfind("KIN_", 0) == 0);
    std::free(reference);
  }
  CHECK(std::string(kinsolFlagName(KIN_LINESEARCH_NONCONV)) == "KIN_LINESEARCH_NONCONV");
  CHECK(std::string(kinsolFlagName(KIN_MAXITER_REACHED)) == "KIN_MAXITER_REACHED");
  CHECK(std::string(kinsolFlagName(KIN_FIRST_SYSFUNC_ERR)) == "KIN_FIRST_SYSFUNC_ERR");
  CHECK(std::string(kinsolFlagName(KIN_REPTD_SYSFUNC_ERR)) == "KIN_REPTD_SYSFUNC_ERR");
  CHECK(std::string(kinsolFlagName(12345)) == "KIN_UNKNOWN_FLAG");
}
