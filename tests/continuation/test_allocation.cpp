// The corrector's hot loop (KINSOL iterations, residual and Jacobian callbacks on mapped
// SUNDIALS storage) must not touch the heap once the Corrector exists (malloc_counter.h).
#include "buckle/continuation/corrector.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include "../malloc_counter.h"

using namespace buckle::continuation;
using buckle::testing::mallocCalls;

TEST_CASE("Corrector solves allocate nothing after construction", "[allocation]") {
#if BUCKLE_COUNT_MALLOC
  const int n = 30;
  toys::Bratu bratu(n);
  Corrector corrector(bratu);
  Vector predictor = Vector::Zero(n + 1), tangent = Vector::Zero(n + 1), x = Vector::Zero(n + 1);
  Vector u0 = Vector::Zero(n), u = Vector::Zero(n);
  tangent[n] = 1.0;
  predictor[n] = 0.5;
  REQUIRE(corrector.correct(predictor, tangent, x).converged);  // warm-up

  const long before = mallocCalls.load();
  int iterations = 0;
  bool converged = true;
  for (int k = 0; k < 20; ++k) {
    predictor[n] = 0.1 + 0.1 * k;
    tangent.setConstant(0.1);
    tangent[n] = 1.0;
    tangent.normalize();
    const CorrectorSummary keller = corrector.correct(predictor, tangent, x);
    const CorrectorSummary fixed = corrector.solveAtFixedParameter(u0, 0.05 * k, u);
    converged = converged && keller.converged && fixed.converged;
    iterations += keller.iterations + fixed.iterations;
  }
  const long after = mallocCalls.load();
  CHECK(converged);
  CHECK(iterations > 20);
  CHECK(after - before == 0);

  // The counter itself works: a fresh Eigen vector is one malloc.
  const long probe = mallocCalls.load();
  Vector fresh(100);
  fresh.setZero();
  CHECK(mallocCalls.load() - probe >= 1);
#else
  SUCCEED("malloc interposition is disabled under AddressSanitizer");
#endif
}
