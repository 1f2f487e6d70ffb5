// Landing on the base wall: a jump or sudden load whose dynamics came to rest with vertices on
// the wall x = 0 (IntegrationOptions::wall, jump.h JumpOptions::wall), or stopped where a moving
// vertex reached it (a caller's barrier, IntegrationStop::Barrier), lands on the equilibrium with
// those vertices held on the wall (contact.h, wall_contact.h: each row −x_v = 0, its force μ_v an
// unknown, friction-free), not on a state through it; with self contact traced (`self`), on the
// equilibrium with the self contacts held then (self_contact.h), not on links passing through
// each other.
//
// The contact set is found by an active-set iteration from the dynamics' last state: solve the
// constrained equilibrium (solveConstrainedEquilibrium); a vertex whose force came out pulling
// (μ_v < 0) or a locked joint whose compression did is released, one at a time (the most
// negative first); a vertex not on the wall that the solution puts behind it (x_v < 0), two links
// it puts into each other (the pair by which they touch, `touchingPair`), a held vertex it puts
// past its edge's base corner (the corner's other edge; past an end it cannot pass, released),
// or a free joint it puts past a limit, is added; repeat until the set is consistent. The landing is
// then stable when K_q − K_g with the wall rows' −Σ μ_v ∂²x_v, projected on the tangent of every
// active row (held coordinates, locked joints, wall vertices), is positive definite
// (constrainedStability) and every contact pushes. Each solve is O(n) (the chain structure).
#pragma once

#include <functional>
#include <string>

#include "buckle/continuation/problem.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

struct WallLanding {
  bool converged = false;   ///< a consistent contact set with a converged constrained equilibrium
  bool stable = false;      ///< and stable on the constrained tangent, every contact pushing
  std::string message;      ///< what was found or why it failed, in words
  ContactSet contacts;      ///< locked joints, vertices on the wall and self contacts at the landing
  Vector u;                 ///< (q, r) at the landing (the last iterate when not converged)
  Vector wallForces;        ///< μ_v, one per vertex of contacts.wall() (along +x on the chain)
  Vector selfForces;        ///< one per contacts.self()
  Vector torques;           ///< contact torques τ_c,i (0 at free joints)
  continuation::StabilityInfo stability;
  double residual = 0.0;    ///< scaled residual of the last solve
  int solves = 0;           ///< constrained solves of the active-set iteration
};

/// From the joint angles q (the barrier state) at λ with the contacts `start` (the vertex that
/// reached the wall, the self contacts held and the joints locked then), the constrained
/// equilibrium (file comment). `self`: the chain's contact with itself is traced. `tolerance`
/// bounds each solve's scaled residual. Never throws for a failed landing: `message` says why.
WallLanding landOnWall(const EquilibriumProblem& problem, const ContactSet& start, continuation::ConstVectorRef q,
                       double lambda, double tolerance = 1e-12, int maxIterations = 50, bool self = false);

/// The base wall as the dynamics' barrier (IntegrationOptions::admissible): true while no moving
/// vertex of `chain` (which must outlive the function) is behind x = 0. O(n) per call.
std::function<bool(continuation::ConstVectorRef)> wallBarrier(const Chain& chain);

/// "" when no moving vertex of `chain` at q is behind the wall by more than 1e-9 of `length` (the
/// chain's length unit: rounding of a vertex on it), else "; the landing is behind the base wall
/// (vertex …, x = …; …)": the dynamics without the wall passed through it (detected, as the
/// continuation's BC without the wall).
std::string behindWall(const Chain& chain, continuation::ConstVectorRef q, double length);

}  // namespace buckle::mechanics
