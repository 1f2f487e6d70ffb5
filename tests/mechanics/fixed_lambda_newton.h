// Newton at fixed λ on a problem's own F_u (dense LU), written in the tests apart from the
// library's correctors: an equilibrium polished to rounding from a nearby guess.
#pragma once

#include <catch2/catch.hpp>

#include <Eigen/LU>

#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::test {

inline Eigen::VectorXd polishAtFixedLambda(mechanics::EquilibriumProblem& p, Eigen::VectorXd u, double lambda,
                                           int iterations = 8) {
  const int N = p.dimension();
  Eigen::VectorXd F(N), Fl(N);
  Eigen::MatrixXd Fu(N, N);
  for (int it = 0; it < iterations; ++it) {
    REQUIRE(buckle::continuation::BoundProblem(p).residual(u, lambda, F));
    REQUIRE(buckle::continuation::BoundProblem(p).jacobian(u, lambda, Fu, Fl));
    u -= Fu.partialPivLu().solve(F);
  }
  return u;
}

}  // namespace buckle::test
