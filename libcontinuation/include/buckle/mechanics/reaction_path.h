// Displacement control from a start that cannot move the end along the held coordinate c to
// first order (the straight chain along x). There the problem with c held is singular, so the
// branches are traced through c's reaction F_c (branch_report.h): c is released, F_c is the
// continuation parameter, bounded by a load limit, and each branch ends where c leaves the path's
// range (EquilibriumOptions::heldRange). The end moves only on the buckled branches, which leave
// the straight one at the critical reactions (linear_buckling.h, eq 14–17 for three segments): a
// load limit below the first of them traces a chain that never moves.
#pragma once

#include <limits>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/end_condition.h"

namespace buckle::mechanics {

/// The bound of |F_c| that covers the first `modes` critical reactions with this margin: a
/// buckled branch's reaction grows or falls away from its critical value as the end moves, and
/// the bound must leave room for that growth over the path's range (Fig 6: the U branch of three
/// segments reaches 1.4 F_U at x = 4.5 b).
constexpr double kReactionLimitMargin = 2.0;

struct ReactionLimit {
  double limit = 0.0;  ///< kReactionLimitMargin · |governing|
  /// The critical reaction of smallest magnitude (signed: negative for compression along +c).
  double firstCritical = std::numeric_limits<double>::quiet_NaN();
  /// The `modes`-th critical reaction by magnitude (or the last one that exists), signed.
  double governing = std::numeric_limits<double>::quiet_NaN();
  int modesFound = 0;  ///< finite critical reactions found (≤ modes)
};

/// The critical reactions of held end coordinate `coordinate` (0 x, 1 y, 2 φ) at the unloaded
/// shape q0, with the other coordinates as `end` prescribes them (the path's end condition with c
/// held), and the load limit derived from them. Throws std::invalid_argument when c is not held
/// in `end`, when q0 is not an unloaded equilibrium, or when no finite nonzero critical reaction
/// exists (K_q ≈ 0 on the constraints, or the load never destabilises the chain): then a load
/// limit cannot be derived and must be given.
ReactionLimit reactionLimit(const Chain& chain, ConstVectorRef q0, const EndCondition& end, int coordinate,
                            int modes = 1);

}  // namespace buckle::mechanics
