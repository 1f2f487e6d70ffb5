// Internal to continueUnderContact (equilibrium_branches.cpp): what a located boundary at the end
// of a stretch means for the contacts (a joint's limit, the base wall, the chain's own links), how
// the set of contacts changes there, and the rate of the changed contact's boundary.
#pragma once

#include <string>

#include "buckle/continuation/branch.h"
#include "buckle/continuation/problem.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

// What a branch's last special point stopped on: a joint limit or a joint's release (joint ≥ 0),
// the wall reached by a vertex or a vertex's release from it (vertex.segment ≥ 0), two links
// touching, a self contact's release or its vertex at an end of its edge (onSelf), or nothing.
struct BoundaryEvent {
  LockedJoint joint;
  WallVertex vertex;
  bool wallRelease = false;
  SelfContact self;
  bool onSelf = false, selfRelease = false, selfEdgeEnd = false;
  bool any() const { return joint.joint >= 0 || vertex.segment >= 0 || onSelf; }
};

// The event found by the boundary's name among the problem's boundaries (the joints' limits and
// contacts, the wall's clearance and releases, the self contacts'); `contacts` those before it.
BoundaryEvent endEvent(const EquilibriumProblem& base, const continuation::Problem& problem,
                      const continuation::Branch& branch, const ContactSet& contacts);

// What an event changes (continueUnderContact): the contacts after it, whether it releases one, its
// words for notes, and the index of the changed wall vertex or self contact among `after`'s (−1:
// a joint). A vertex at the base-corner end of its edge is held there on the corner's other edge
// too (self_contact.h cornerNeighbour; the index is that contact's); elsewhere (an apex, unequal
// half-heights) `followed` is false.
struct ContactChange {
  ContactSet after;
  bool release = false, followed = true;
  std::string what;
  int index = -1;
  /// The release of one of a vertex's two contacts at a corner: the index among `after`'s self
  /// contacts of the one that stays, along whose edge the vertex slides away from the corner
  /// (−1 otherwise). The outline is convex there: the released edge's gap decreases on the way.
  int slidesOn = -1;
};
ContactChange changeOf(const EquilibriumProblem& problem, const continuation::SpecialPoint& at, const BoundaryEvent& hit,
                       const ContactSet& before);

// dg/ds at the start p0 of a stretch (on its problem's unknowns (q, r, μ), λ) for the changed
// contact's boundary g: a released joint's g = side·(q̄ − q) moves with −side·t_q; a joint contact's
// compression −side·τ_c with −side·(F_u,i t_u + F_λ,i t_λ) (row i of the stretch before, exact); a
// vertex's wall force μ_v with its own component of the tangent; a released vertex's x_v with
// ∇x_v·t_q; a self contact's force and gap the same way, but a vertex leaving a corner
// (ContactChange::slidesOn) with −∇g·t_q of the released edge: the outline is convex there, so the
// vertex moving along the other edge, away from the corner, goes inside the released edge's line.
double contactRate(EquilibriumProblem& problem, const ContactSet& before, const BoundaryEvent& hit,
                   const ContactChange& change, const continuation::ContinuationPoint& p0);

}  // namespace buckle::mechanics
