#include "buckle/mechanics/classification.h"

#include <cmath>

#include "buckle/mechanics/shape_name.h"

namespace buckle::mechanics {

using continuation::SpecialPoint;
using continuation::SpecialPointType;

const char* toString(Phenomenon p) {
  switch (p) {
    case Phenomenon::Buckling: return "buckling";
    case Phenomenon::QuasiBuckling: return "quasi-buckling";
    case Phenomenon::Jumping: return "jumping";
    case Phenomenon::None: return "none";
  }
  return "none";
}

bool isLoadControlled(const EquilibriumProblem& problem) {
  for (int c : problem.endCondition().heldIndices())
    if (problem.direction()[c] != 0.0) return false;
  return true;
}

namespace {

// The bifurcating mode of a branch point: the kernel vector orthogonal to the traced branch
// (nullVectors column 1). At a multiple point (nullVectors with m + 1 ≥ 3 columns) the
// bifurcating directions form an m-dimensional space whose basis is arbitrary (a rounding change
// or the approach direction rotates it), so one fixed member is named instead: the projection
// onto that space of the unit rotation of the first joint it reaches the most (ties within a
// relative 1e-9 go to the lower joint). Three identical joints at the fold of their common
// torque-angle curve (the hysteresis scene): span{(1,1,1)}⊥, joint 1's projection (2,−1,−1)/3.
// Returned whole (joints, reactions, λ).
Eigen::VectorXd bifurcatingDirection(const SpecialPoint& point, int joints) {
  const Eigen::MatrixXd& V = point.nullVectors;
  if (V.cols() < 3) return V.col(1);
  const Eigen::MatrixXd directions = V.rightCols(V.cols() - 1);  // orthonormal (locator.cpp)
  int best = 0;
  double bestNorm = -1.0;
  for (int i = 0; i < joints; ++i) {
    const double norm = directions.row(i).norm();  // ‖P e_i‖ for the projector P = D Dᵀ
    if (norm > bestNorm * (1.0 + 1e-9)) {
      best = i;
      bestNorm = norm;
    }
  }
  return directions * directions.row(best).transpose();
}

/// The shape of the family crossing the traced branch at a branch point: its mode's name, or
/// "straight" where that direction moves no joint beyond rounding (the traced branch meets the
/// straight chain at its tip: the other family moves λ and the reactions alone, and the sign
/// pattern of its joints' rounding would name a shape at random).
std::string bifurcatingShape(const EquilibriumProblem& problem, const SpecialPoint& point, int joints) {
  const Eigen::VectorXd direction = bifurcatingDirection(point, joints);
  const Eigen::VectorXd mode = direction.head(joints);
  // compared in the problem's own scales (joints, reactions and λ in their typical sizes): any units
  const continuation::ProblemScales scales = problem.scales();
  Eigen::VectorXd scaled = direction;
  if (scales.unknowns.size() + 1 == direction.size()) {
    scaled.head(scales.unknowns.size()) = direction.head(scales.unknowns.size()).cwiseQuotient(scales.unknowns);
    scaled[scaled.size() - 1] /= scales.parameter;
  }
  if (!(scaled.head(joints).norm() > 1e-6 * scaled.norm())) return "straight";
  return modeShapeName(mode, 1e-6);
}

}  // namespace

bool startIsUnstable(const continuation::Branch& branch) {
  return !branch.points.empty() && branch.points.front().stability.valid() &&
         branch.points.front().stability.negative > 0;
}

Classification classify(const EquilibriumProblem& problem, const SpecialPoint& point) {
  Classification c;
  const int n = problem.segments();
  c.load = problem.wrench(point.u, point.lambda);
  c.pose = endPose(problem.chain(), point.u.head(n));
  c.stableBefore = point.inertiaBefore == 0;
  c.stableAfter = point.inertiaAfter == 0;
  c.shape = shapeName(point.u.head(n), 1e-7);
  const bool loadControl = isLoadControlled(problem);
  switch (point.type) {
    case SpecialPointType::BranchPoint: {
      // The bifurcating direction is the kernel vector orthogonal to the traced branch.
      if (point.nullVectors.cols() >= 2) c.shape = bifurcatingShape(problem, point, n);
      c.phenomenon = Phenomenon::Buckling;
      c.explanation = "branch point: the " + shapeName(point.u.head(n), 1e-7) +
                      " configuration loses stability to the " + c.shape + " family";
      if (point.multiplicity > 1)
        c.explanation += " (multiplicity " + std::to_string(point.multiplicity) + ": degenerate)";
      break;
    }
    case SpecialPointType::Fold:
      // A fold of the traced parameter ends the equilibrium the chain was in, whatever the
      // parameter moves (a load, or a held coordinate directly): past it no nearby equilibrium
      // exists, so the chain jumps — unless both sides are unstable. (A fold of a *reaction*
      // under displacement control is no fold of the controlled parameter: branch_report.h.)
      if (!c.stableBefore && !c.stableAfter) {
        c.phenomenon = Phenomenon::None;
        c.explanation = "fold between two unstable parts of the branch";
      } else {
        c.phenomenon = Phenomenon::Jumping;
        c.explanation = loadControl ? "fold under load control: the stable branch ends, no nearby equilibrium beyond it"
                                    : "fold of the controlled displacement: the stable branch ends, the chain jumps";
      }
      break;
    case SpecialPointType::Boundary:
      // a joint reaching its limit: the stiffness changes sharply there, under any control
      c.phenomenon = Phenomenon::QuasiBuckling;
      c.explanation = point.boundaryName.empty() ? "boundary reached" : point.boundaryName + " reached";
      c.explanation += ": sharp change of stiffness";
      break;
    case SpecialPointType::EigenvalueTouch:
      // The stiffness in one mode reaches zero and recovers: the count does not change, the
      // state stays on the same side of stability (neutral there, to the touch's accuracy).
      c.phenomenon = Phenomenon::None;
      c.explanation = "an eigenvalue of the stability operator touches zero without changing sign";
      break;
    case SpecialPointType::Endpoint:
      c.phenomenon = Phenomenon::None;
      c.explanation = point.boundaryName.empty() ? "end of the branch" : point.boundaryName;
      break;
  }
  return c;
}

}  // namespace buckle::mechanics
