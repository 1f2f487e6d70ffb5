// The boundaries of the equilibrium problem (Problem::boundary): the joint limits, where the
// tracer stops or contact begins (contact.h), and the held coordinate's path range of a
// displacement path traced through its reaction (EquilibriumOptions::heldRange), and the base
// wall (EquilibriumOptions::wallAsBoundary), where a wall contact begins, and the chain's clearance
// from itself (EquilibriumOptions::selfContactAsBoundary), where a self contact begins.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/self_contact.h"
#include "buckle/mechanics/wall_contact.h"

namespace buckle::mechanics {

using continuation::ConstVectorRef;
using continuation::ProblemWorkspace;
using continuation::VectorRef;
using continuation::workspaceAs;

int EquilibriumProblem::boundaryCount() const {
  return selfContactBoundaryIndex() + (options_.selfContactAsBoundary ? 1 : 0);
}

// A joint limit is the joint angle at the limit itself, geometric (the closing spring's length
// is zero, or |c1 − c2|) or the user's: the spring model is regular there (inDomain,
// equilibrium_problem.cpp).
double EquilibriumProblem::boundary(ProblemWorkspace& ws, int k, ConstVectorRef u, double lambda) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int n = chain_.size();
  if (options_.wallAsBoundary && k == wallBoundaryIndex()) return nearestWallVertex(chain_, u.head(n)).distance;
  if (options_.selfContactAsBoundary && k == selfContactBoundaryIndex()) return selfClearanceApart(chain_, u.head(n), {});
  const int r = k - rangeBoundaryBegin();
  if (r >= 0) {
    // the pose from the evaluation cache (no allocation per point); outside the domain, directly.
    // A slack of 1e-12 of the range's scale keeps a start on the range end inside: the path's
    // start value is the same pose summed by another route (endPose), equal to a few ulp.
    const EquilibriumOptions::CoordinateRange& range = options_.heldRange;
    const double v =
        prepare(d, u, lambda) ? d.data.pose[range.coordinate] : endPose(chain_, u.head(n))[range.coordinate];
    const double slack = 1e-12 * std::max({range.high - range.low, std::abs(range.low), std::abs(range.high)});
    return r == 0 ? v - range.low + slack : range.high - v + slack;
  }
  if (k < n) return chain_.upperLimits()[k] - u[k];
  return u[k - n] - chain_.lowerLimits()[k - n];
}

void EquilibriumProblem::boundaries(ProblemWorkspace& ws, ConstVectorRef u, double lambda, VectorRef g) const {
  const int n = chain_.size();
  const Eigen::Index count = g.size();
  const int limits = rangeBoundaryBegin();
  const double* const upper = chain_.upperLimits().data();
  const double* const lower = chain_.lowerLimits().data();
  for (int k = 0; k < n && k < limits && k < count; ++k) g[k] = upper[k] - u[k];
  for (int k = n; k < 2 * n && k < limits && k < count; ++k) g[k] = u[k - n] - lower[k - n];
  for (int k = limits; k < count; ++k) g[k] = boundary(ws, k, u, lambda);
}

std::string EquilibriumProblem::boundaryName(int k) const {
  const int n = chain_.size();
  if (options_.wallAsBoundary && k == wallBoundaryIndex()) return wallBoundaryName();
  if (options_.selfContactAsBoundary && k == selfContactBoundaryIndex()) return selfContactBoundaryName();
  if (const int r = k - rangeBoundaryBegin(); r >= 0) {
    static const char* names[3] = {"x", "y", "phi"};
    const EquilibriumOptions::CoordinateRange& range = options_.heldRange;
    std::ostringstream os;
    os.precision(12);
    os << "end " << names[range.coordinate] << " reached the path's range end " << (r == 0 ? range.low : range.high);
    return os.str();
  }
  const int j = k < n ? k : k - n;
  const Segment& s = chain_.segment(j);
  const bool geometric = k < n ? s.parameters().qMaxUser >= s.geometricUpperLimit()
                               : s.parameters().qMinUser <= s.geometricLowerLimit();
  return "joint " + std::to_string(j + 1) + (k < n ? " upper" : " lower") +
         (geometric ? " geometric limit (closing spring length -> 0)" : " limit");
}

bool EquilibriumProblem::isRangeBoundary(const std::string& name) const {
  for (int r = 0; r < rangeBoundaryCount(); ++r)
    if (name == boundaryName(rangeBoundaryBegin() + r)) return true;
  return false;
}

}  // namespace buckle::mechanics
