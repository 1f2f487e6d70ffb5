// Points of contact problems for the cross-checks of the O(n) routes (solver, counts, products,
// stiffness) against the dense ones: an end condition, a wall vertex or none, self contacts.
#pragma once

#include <random>
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

/// Two self contacts across a chain of n segments (n ≥ 40): a distal corner three quarters along
/// on a distal triangle's edge a quarter along (the vertex's body the distal one), and a proximal
/// corner an eighth along on a proximal triangle's edge at five eighths (the edge's the distal one).
inline std::pair<SelfContact, SelfContact> crossingSelfContacts(int n) {
  return {SelfContact{{3 * n / 4, 3}, {n / 4, true, 1}}, SelfContact{{n / 8, 1}, {5 * n / 8, false, 2}}};
}

/// The locked joints, the wall vertex when the case has the wall, and the case's self contacts.
inline ContactSet caseContacts(const ContactCase& k, const std::vector<std::pair<int, LimitSide>>& locked,
                               const WallVertex& wall) {
  ContactSet set;
  for (const auto& [joint, side] : locked) set.lock(joint, side);
  if (k.wall) set.touch(wall);
  for (const SelfContact& c : k.self) set.hold(c);
  return set;
}

/// For each case: its problem on `chain` under a random load direction drawn from `rng`, and the
/// contact problem with the `locked` joints, the wall vertex (2, 3) when the case has the wall and
/// the case's self contacts — body(case, contact problem).
template <class Body>
void forEachContactCase(std::mt19937& rng, const Chain& chain, const std::vector<ContactCase>& cases,
                        const std::vector<std::pair<int, LimitSide>>& locked, Body body) {
  std::uniform_real_distribution<double> W(-1.0, 1.0);
  for (const ContactCase& k : cases) {
    EquilibriumProblem problem(chain, k.end, Eigen::Vector3d(W(rng), W(rng), W(rng)));
    const ContactProblem contact(problem, caseContacts(k, locked, WallVertex{2, 3}));
    body(k, contact);
  }
}

}  // namespace buckle::mechanics::testing
