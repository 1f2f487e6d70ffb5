// Points of contact problems for the cross-checks of the O(n) routes (solver, counts, products,
// stiffness) against the dense ones: an end condition, a wall vertex or none, self contacts.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "buckle/mechanics/contact.h"

namespace buckle::mechanics::testing {

struct ContactCase {
  std::string name;
  EndCondition end;
  bool wall = false;
  std::vector<SelfContact> self;
  double lastForceSign = 1.0;  ///< −1: the last contact force pulls
};

/// The locked joints, the wall vertex when the case has the wall, and the case's self contacts.
inline ContactSet caseContacts(const ContactCase& k, const std::vector<std::pair<int, LimitSide>>& locked,
                               const WallVertex& wall) {
  ContactSet set;
  for (const auto& [joint, side] : locked) set.lock(joint, side);
  if (k.wall) set.touch(wall);
  for (const SelfContact& c : k.self) set.hold(c);
  return set;
}

}  // namespace buckle::mechanics::testing
