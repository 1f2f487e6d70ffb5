// Special points of an equilibrium branch in the field's words (paper §III; docs/mechanics.md,
// "What the physics does"); the one classifier, used by branch_report.h:
//   buckling        a branch point on the loaded path: the configuration loses stability to a
//                   new family of shapes (U / Z for three segments);
//   jumping         a fold of the traced parameter (a load, or a held coordinate) with a stable
//                   side: past the fold no nearby equilibrium exists, so the chain must jump
//                   (dynamics) — or an unloaded start that is itself unstable (Fig 6b);
//   quasi-buckling  a joint running into its limit (sharp change of stiffness, Fig 10),
//                   a deep minimum of the stiffness, or — under displacement control traced
//                   through the reaction — a fold of the reaction force (the controlled force
//                   peaks, the stiffness in the controlled direction passes through zero, but
//                   nothing jumps): branch_report.h;
//   none            a fold between two unstable parts, or a plain end point: no physical event.
#pragma once

#include <string>

#include "buckle/continuation/branch.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

enum class Phenomenon { Buckling, QuasiBuckling, Jumping, None };

/// "buckling", "quasi-buckling", "jumping", "none".
const char* toString(Phenomenon p);

struct Classification {
  Phenomenon phenomenon = Phenomenon::None;
  std::string shape;        ///< shape at the point, or of the bifurcating mode at a branch point
  bool stableBefore = false;
  bool stableAfter = false;
  Wrench load = Wrench::Zero();   ///< total end wrench at the point (loads and reactions)
  Pose pose = Pose::Zero();
  std::string explanation;  ///< one sentence: why this name
};

/// True when the path parameter moves only loads (no held coordinate changes with λ).
bool isLoadControlled(const EquilibriumProblem& problem);

/// Classifies one special point of a branch traced on `problem`.
Classification classify(const EquilibriumProblem& problem, const continuation::SpecialPoint& point);

/// Start of a branch whose unloaded / initial state is unstable: "jumping" (Fig 6b).
bool startIsUnstable(const continuation::Branch& branch);

}  // namespace buckle::mechanics
