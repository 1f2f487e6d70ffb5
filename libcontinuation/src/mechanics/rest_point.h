// Where a jump's or a sudden load's dynamics came to rest (jump.cpp): the rest point polished
// as an equilibrium with its contacts (joints at their limits, vertices on the base wall, self
// contacts), its stability, and whether the dynamics reached the wall. Internal to jump.cpp.
#pragma once

#include <vector>

#include "buckle/continuation/corrector.h"
#include "buckle/continuation/problem.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/jump.h"

namespace buckle::mechanics {

/// Whether any joint is locked (per joint 0 free, ±1 at a limit).
bool anyContact(const std::vector<int>& sides);

/// The rest point of `dyn` as an equilibrium at λ: polished (with its contacts fixed), its
/// stability (of the constrained system in contact) and contact torques.
struct RestPoint {
  PolishResult polished;
  continuation::StabilityInfo stability;
  std::vector<int> sides;
  Vector torques;
  bool stable = false;
  std::vector<WallVertex> wall;  ///< vertices on the wall (a barrier stop's landing)
  Vector wallForces;
  std::vector<SelfContact> self;  ///< self contacts held at the landing
  Vector selfForces;
};

/// The landing of dynamics that ended on the base wall or on the chain itself: at rest with
/// vertices on the wall (IntegrationOptions::wall) or self contacts held (IntegrationOptions::self),
/// or stopped at the wall (IntegrationStop::Barrier: the vertex of `chain`, the model's, nearest to
/// the wall). Those contacts and the joints locked then start the active set of landOnWall
/// (wall_landing.h).
RestPoint wallRestPoint(EquilibriumProblem& problem, const Chain& chain, const DynamicsResult& dyn, double lambda,
                        const continuation::CorrectorOptions& options, bool self);

/// Whether the dynamics reached the base wall, and where first: the first wall contact event
/// (its vertex's x at that instant), or the vertex nearest to the wall where the caller's
/// barrier stopped them (IntegrationStop::Barrier).
void noteWallReached(const DynamicsModel& model, const DynamicsResult& dyn, bool& reached, WallVertex& vertex,
                     double& gap);

/// Whether the integration ended where a landing can be read off: at rest, handed over, or at
/// the wall with a converged constrained equilibrium.
bool arrivedAt(const DynamicsResult& dyn, const RestPoint& rest);

/// The rest point of `dyn` polished at λ with its contacts (file comment). `settled`: the
/// equilibrium the basin test certified when the integration ended Settled
/// (no joint in contact then: the test runs only without locked joints). `self`: the chain's
/// contact with itself is traced, so every rest point lands by landOnWall's active set.
RestPoint polishRestPoint(EquilibriumProblem& problem, const Chain& chain, const DynamicsResult& dyn, double lambda,
                          const continuation::CorrectorOptions& options, bool self,
                          const PolishResult* settled = nullptr);

}  // namespace buckle::mechanics
