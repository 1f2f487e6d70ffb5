// An independent equilibrium of a heavy chain for the tests: Newton on E + V with V the links'
// weight by GravityPotential (absolute positions, gravity.h) and dense Hessians, no end load.
#pragma once

#include <Eigen/Dense>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/gravity.h"

namespace buckle::mechanics::testing {

/// At most `iterations` Newton steps from q (fewer once a step is below 1e-15 rad).
inline Vector heavyNewton(const Chain& chain, const InertiaData& inertia, const Eigen::Vector2d& g, Vector q,
                          int iterations = 60) {
  const int n = chain.size();
  GravityPotential V(chain, inertia, g);
  Vector grad(n), gv(n);
  Matrix H(n, n), G(n, n);
  for (int it = 0; it < iterations; ++it) {
    energyGradient(chain, q, grad);
    V.gradient(q, gv);
    totalPotentialHessian(chain, q, Wrench::Zero(), H);
    V.hessian(q, G);
    const Vector step = (H + G).ldlt().solve(grad + gv);
    q -= step;
    if (step.lpNorm<Eigen::Infinity>() <= 1e-15) break;
  }
  return q;
}

}  // namespace buckle::mechanics::testing
