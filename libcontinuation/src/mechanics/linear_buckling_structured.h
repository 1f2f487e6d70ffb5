// The O(n) route of linearBuckling (linear_buckling.cpp) for long chains and a few modes:
// internal, not installed.
#pragma once

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/linear_buckling.h"

namespace buckle::mechanics {

/// The first options.count modes of a long chain, O(n) each through the chain structure (the
/// count of critical loads below a trial load on T(λ), finished by Rayleigh-quotient iteration),
/// sorted by |λ|; false where that route does not apply (K_q not definite on ker J_h: the dense
/// pencil then). kq: the diagonal of K_q at the unloaded shape, Ch: the held rows of J as columns,
/// force: the chain's force unit k̄ b̄ (K_q ≈ 0 is judged against the load matrix times it).
bool structuredBuckling(const ChainData& data, const Vector& kq, const Matrix& Ch, const LinearBucklingOptions& options,
                        double force, LinearBucklingResult& fast);

}  // namespace buckle::mechanics
