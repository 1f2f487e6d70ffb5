#include "buckle/continuation/internal/sundials_raii.h"
#include "buckle/continuation/internal/serial_vector_ops.h"

#include <catch2/catch.hpp>
#include <sunmatrix/sunmatrix_dense.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <utility>
#include <random>
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

TEST_CASE("the lean serial operations give bitwise the library's results, also in clones", "[sundials_raii]") {
  // serial_vector_ops.h promises the operations of N_V*_Serial in the same order: compare them
  // bit for bit on random vectors of the corrector's sizes and on edge values.
  SunContextPtr context = makeSunContext();
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> W(-3.0, 3.0);
  std::uniform_int_distribution<int> E(-40, 40);
  auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  auto sameVector = [&](N_Vector a, N_Vector b) {
    for (sunindextype i = 0; i < N_VGetLength(a); ++i)
      if (!same(NV_Ith_S(a, i), NV_Ith_S(b, i))) return false;
    return true;
  };
  for (int n : {1, 2, 4, 5, 8, 13}) {
    NVectorPtr lean = makeSerialVector(n, context.get());
    useLeanSerialOperations(lean.get());
    NVectorPtr x(N_VClone(lean.get()));  // a clone inherits the lean operations
    NVectorPtr w(N_VClone(lean.get())), y(N_VClone(lean.get())), z(N_VClone(lean.get()));
    NVectorPtr plain = makeSerialVector(n, context.get());
    CHECK(x->ops->nvwl2norm != plain->ops->nvwl2norm);
    NVectorPtr zp(N_VClone(plain.get()));
    for (int trial = 0; trial < 200; ++trial) {
      for (int i = 0; i < n; ++i) {
        NV_Ith_S(x.get(), i) = std::ldexp(W(rng), E(rng));
        NV_Ith_S(w.get(), i) = trial % 3 == 0 ? 1.0 : std::abs(W(rng));
        NV_Ith_S(y.get(), i) = trial % 7 == 0 && i % 2 ? 0.0 : W(rng);
      }
      if (trial % 11 == 0) NV_Ith_S(x.get(), 0) = -0.0;
      CHECK(same(N_VWL2Norm(x.get(), w.get()), N_VWL2Norm_Serial(x.get(), w.get())));
      CHECK(same(N_VMaxNorm(x.get()), N_VMaxNorm_Serial(x.get())));
      CHECK(same(N_VMin(x.get()), N_VMin_Serial(x.get())));
      N_VProd(x.get(), y.get(), z.get());
      N_VProd_Serial(x.get(), y.get(), zp.get());
      CHECK(sameVector(z.get(), zp.get()));
      for (double c : {1.0, -1.0, 0.5, W(rng)}) {
        N_VScale(c, x.get(), z.get());
        N_VScale_Serial(c, x.get(), zp.get());
        CHECK(sameVector(z.get(), zp.get()));
        N_VScale(c, z.get(), z.get());  // in place (the library's scale-by branch)
        N_VScale_Serial(c, zp.get(), zp.get());
        CHECK(sameVector(z.get(), zp.get()));
      }
      // z = a x + b y: the lean a = b = 1 case and the library's others, out of place and in place
      for (const auto& ab : {std::pair<double, double>{1.0, 1.0}, {1.0, -1.0}, {-1.0, 1.0}, {0.5, 1.0}, {W(rng), W(rng)}}) {
        N_VLinearSum(ab.first, x.get(), ab.second, y.get(), z.get());
        N_VLinearSum_Serial(ab.first, x.get(), ab.second, y.get(), zp.get());
        CHECK(sameVector(z.get(), zp.get()));
        NVectorPtr y2(N_VClone(lean.get())), yp(N_VClone(plain.get()));
        N_VScale_Serial(1.0, y.get(), y2.get());
        N_VScale_Serial(1.0, y.get(), yp.get());
        N_VLinearSum(ab.first, x.get(), ab.second, y2.get(), y2.get());  // into y (axpy)
        N_VLinearSum_Serial(ab.first, x.get(), ab.second, yp.get(), yp.get());
        CHECK(sameVector(y2.get(), yp.get()));
        NVectorPtr x2(N_VClone(lean.get())), xp(N_VClone(plain.get()));
        N_VScale_Serial(1.0, x.get(), x2.get());
        N_VScale_Serial(1.0, x.get(), xp.get());
        N_VLinearSum(ab.first, x2.get(), ab.second, y.get(), x2.get());  // into x
        N_VLinearSum_Serial(ab.first, xp.get(), ab.second, y.get(), xp.get());
        CHECK(sameVector(x2.get(), xp.get()));
      }
      const double c = W(rng);
      N_VConst(c, z.get());
      N_VConst_Serial(c, zp.get());
      CHECK(sameVector(z.get(), zp.get()));
    }
  }
  NVectorPtr zeros = makeSerialVector(3, context.get());
  useLeanSerialOperations(zeros.get());
  CHECK(N_VWL2Norm(zeros.get(), zeros.get()) == 0.0);
  CHECK(N_VMaxNorm(zeros.get()) == 0.0);
}
