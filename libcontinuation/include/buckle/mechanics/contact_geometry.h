// Contact of the chain with its base and with itself (detection; the joints' own contact with
// their limits is contact.h). Conventions: conventions.h.
//
//  * Base contact. The chain is clamped to a wall, the plane x = 0 (the material fills x < 0;
//    the shape plots draw it hatched). The moving bodies are the segments' triangles except the
//    first segment's proximal one (clamped, its base edge on the wall); the springs run between
//    triangle vertices. A convex body's smallest x is at a vertex, so the signed distance
//        d_base(q) = min over the moving triangles' vertices of x          (> 0: clear)
//    is exact for this geometry and costs O(n).
//  * Self contact. Link m's rigid body is made of two triangles, their real outlines from a and b
//    (the base link ℓ_0: the first segment's clamped proximal triangle; link m: segment m's distal
//    and segment m + 1's proximal triangle, base to base; the last link: the last segment's
//    distal one), each with its apex at its segment's joint. Links that share a joint always
//    touch there (the joint's own limit is contact.h); links two or more apart are in contact
//    when their triangles meet. The signed distance of two triangles is their distance while
//    they are disjoint and, while they overlap, the largest gap of their projections on their
//    edges' normals — minus the depth of the overlap (separating axes; continuous at the first
//    touch, negative after it); a pair of links takes the smallest over their triangles, and
//        d_self(q) = min over non-adjacent pairs                            (> 0: clear).
//    Pairs are rejected by their bounding circles (the link's mid-point, its farthest vertex: a
//    pair is evaluated exactly only if its circles' gap, or −r_a − r_b where they overlap, could
//    beat the best so far), and only the links whose mid-points lie within that reach in x and y
//    of a link's (a sweep over the links sorted by x) are looked at: nothing is missed, the pair
//    found is the all-pairs scan's, and a chain that does not fold onto itself costs O(n log n)
//    per point — O(n) along a branch, whose scan keeps the links' x order from the last shape.
//    Detection: the chain does not yet stop at a self contact (the base wall can be a
//    constraint, wall_contact.h).
//
// Along a traced branch (branch_report.h) a sign change of d_base or d_self between two
// consecutive points is a special point "BC" / "SC", located by root finding on the signed
// distance with an equilibrium solve at each trial load (the stretch's locked joints fixed).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "buckle/continuation/branch.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

/// The nearest approach of the chain to its base wall x = 0.
struct BaseClearance {
  double distance = 0.0;  ///< d_base: smallest x over the moving triangles' vertices
  int segment = -1;       ///< 0-based segment whose triangle holds that vertex
  bool distal = true;     ///< that triangle is the segment's distal (true) or proximal one
  Eigen::Vector2d point = Eigen::Vector2d::Zero();  ///< the vertex
};
/// O(n). Throws std::invalid_argument when q does not have one angle per segment.
BaseClearance baseClearance(const Chain& chain, ConstVectorRef q);

/// The nearest approach of two non-adjacent links' bodies (file comment).
struct SelfClearance {
  double distance = 0.0;  ///< d_self (+inf with fewer than three links)
  int linkA = -1, linkB = -1;  ///< links m (0: the base link ℓ_0), linkA < linkB − 1
  Eigen::Vector2d point = Eigen::Vector2d::Zero();  ///< the point of link A's body nearest to link B's (overlapping: near the overlap)
};
/// Bounding-circle cut-off and an x sweep (file comment): O(n log n) unless the chain folds onto itself.
SelfClearance selfClearance(const Chain& chain, ConstVectorRef q);

/// A scan's question to selfClearance: is the clearance below `stopBelow`? The pair (linkA, linkB),
/// typically the previous point's nearest, is measured first: its distance starts the search's
/// cut-off (tight from the first pair), and a pair found below `stopBelow` ends the search — the
/// result is then that pair's distance, an upper bound of d_self that has its sign.
struct SelfClearanceHint {
  int linkA = -1, linkB = -1;
  double stopBelow = -std::numeric_limits<double>::infinity();
  /// Pairs of links (lower first) left out of the search: those holding a self contact.
  std::vector<std::pair<int, int>> exclude;
};
/// As selfClearance(chain, q), exact unless a pair below hint.stopBelow ended the search
/// (`exact` false: then distance < stopBelow and d_self ≤ distance).
SelfClearance selfClearance(const Chain& chain, ConstVectorRef q, const SelfClearanceHint& hint, bool* exact);

/// Clearances within this fraction of the chain's length of zero are "touching": bodies resting on
/// each other within rounding (locateGeometricContacts counts sign changes between points outside it).
inline constexpr double kTouchingBand = 1e-9;

/// Base (true) or self (false) contact located on a branch.
struct GeometricContact {
  bool base = true;
  bool located = false;      ///< the root finding converged (else: to the point spacing)
  bool entering = true;      ///< the distance goes from > 0 to < 0 along the branch
  int index = 0;             ///< between points[index] and [index + 1]
  double lambda = 0.0;
  continuation::Vector u;    ///< (q, r) at the contact
  double accuracy = 0.0;     ///< |Δλ| of the last bracket
  int segment = -1;          ///< base: the touching segment (0-based)
  int linkA = -1, linkB = -1;  ///< self: the links
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
};

/// The base and self contacts of a branch handed to or from reportBranch: `given` true, `list`
/// holds them (a mirror image's: its source's mirrored, mirror_symmetry.h) and they are not
/// located again; false, reportBranch locates them and leaves them in `list`.
struct GeometricContacts {
  bool given = false;
  std::vector<GeometricContact> list;
};

/// The base and self contacts along `branch` traced on `problem`; `locked[i]` the joints locked
/// at point i (empty: none anywhere). Each sign change of d_base / d_self between points clear of
/// zero by more than kTouchingBand × the chain's length (in the interval where it flips) is located by Illinois iteration on λ, each trial an equilibrium solved at fixed λ with
/// the interval's locked joints fixed (solveConstrainedEquilibrium), to |Δλ| <= tolerance·max(λ
/// scale, |λ|). Not located (to the point spacing) across a fold inside the interval, where λ
/// does not parametrize the branch, nor once `interrupt` is requested.
std::vector<GeometricContact> locateGeometricContacts(EquilibriumProblem& problem, const continuation::Branch& branch,
                                                      const std::vector<ContactSet>& locked, double tolerance = 1e-12,
                                                      const continuation::Interrupt& interrupt = {});

}  // namespace buckle::mechanics
