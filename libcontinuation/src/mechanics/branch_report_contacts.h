// Internal to reportBranch (branch_report.cpp): the special points where a branch's contacts
// change (continueUnderContact) named as such: CT / RL at the joints, WC / WR at the base wall,
// SH / SR between the chain's own links.
#pragma once

#include <vector>

#include "buckle/continuation/branch.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

/// Makes `s`, reported for the boundary special point `sp` of branch `b` (its points `all`), the
/// contact event it ends a stretch with; s is left a plain boundary when no stretch starts after it.
void reportContactEvent(EquilibriumProblem& problem, const continuation::Branch& b, const continuation::SpecialPoint& sp,
                        const std::vector<ContactStretch>& stretches, const std::vector<PointReport>& all,
                        SpecialPointReport& s);

}  // namespace buckle::mechanics
