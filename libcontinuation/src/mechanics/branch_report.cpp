#include "buckle/mechanics/branch_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "buckle/continuation/branch_point_coefficients.h"
#include "branch_report_contacts.h"
#include "contact_geometry_report.h"
#include "buckle/mechanics/shape_name.h"
#include "buckle/mechanics/stiffness.h"
#include "buckle/mechanics/stiffness_extremum.h"

namespace buckle::mechanics {

namespace cont = buckle::continuation;

const char* label(EventType type) {
  switch (type) {
    case EventType::BranchPoint: return cont::label(cont::SpecialPointType::BranchPoint);
    case EventType::Fold: return cont::label(cont::SpecialPointType::Fold);
    case EventType::ReactionFold: return "LPF";
    case EventType::Boundary:
    case EventType::JointLimit: return cont::label(cont::SpecialPointType::Boundary);
    case EventType::StiffnessMinimum: return "KMIN";
    case EventType::Jump: return "JUMP";
    case EventType::Contact: return "CT";
    case EventType::Release: return "RL";
    case EventType::BaseContact: return "BC";
    case EventType::SelfContact: return "SC";
    case EventType::WallContact: return "WC";
    case EventType::WallRelease: return "WR";
    case EventType::SelfHold: return "SH";
    case EventType::SelfRelease: return "SR";
    case EventType::EigenvalueTouch: return cont::label(cont::SpecialPointType::EigenvalueTouch);
    case EventType::StabilityLoss: return "LS";
    case EventType::InputBound: return "IB";
  }
  return "?";
}

std::string stabilityLabel(int negative) {
  if (negative < 0) return "unknown";
  if (negative == 0) return "stable";
  return "unstable (" + std::to_string(negative) + " negative)";
}

namespace {

std::string formatShort(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

// A branch point of free joints: Koiter's coefficients and the imperfection sensitivities (a
// simple point's only: a multiple one has its reduced equation).
void addPostBuckling(EquilibriumProblem& problem, const cont::SpecialPoint& sp, const cont::Interrupt& interrupt,
                     SpecialPointReport& s, BranchReport& r) {
  if (sp.multiplicity != 1) return;
  if (interrupt.requested()) {
    r.skip("post-buckling coefficients");
    s.note += (s.note.empty() ? "" : "; ") + std::string("post-buckling coefficients not computed: ") +
              interrupt.describe();
    return;
  }
  s.koiter = koiterCoefficients(problem, sp);
  if (!s.koiter.valid) {
    s.note = s.koiter.message;
    return;
  }
  for (int c = 0; c < 3; ++c) s.imperfections.push_back(imperfectionSensitivity(problem, sp, s.koiter, c));
  // preload asymmetries: of every segment at once, and of the most sensitive single one
  s.imperfections.push_back(preloadImperfectionSensitivity(problem, sp, s.koiter, -1));
  if (problem.segments() > 1)
    s.imperfections.push_back(
        preloadImperfectionSensitivity(problem, sp, s.koiter, mostSensitivePreloadSegment(problem, sp, s.koiter)));
  if (!s.koiter.message.empty()) s.note += (s.note.empty() ? "" : "; ") + s.koiter.message;
}

// A fold whose λ'' is zero to its accuracy: two folds merged, a cusp of the fold curve.
void noteCusp(EquilibriumProblem& problem, const cont::SpecialPoint& sp, SpecialPointReport& s) {
  cont::FoldCoefficient fc;
  if (sp.refined && cont::foldCoefficient(problem, sp, fc) && fc.cusp)
    s.note += (s.note.empty() ? "" : "; ") + std::string("cusp: the fold's quadratic coefficient lambda'' = ") +
              formatShort(fc.curvature) + " is zero to its accuracy " + formatShort(fc.accuracy);
}

bool regularStop(cont::StopReason r) {
  return r == cont::StopReason::LambdaRange || r == cont::StopReason::Boundary || r == cont::StopReason::Box ||
         r == cont::StopReason::MaxArclength || r == cont::StopReason::Joined || r == cont::StopReason::ClosedLoop;
}

/// The chain under the path's own end condition, for a branch traced through the reaction of
/// held coordinate c: the same loads on the loaded coordinates, c held again. Its stability
/// operator is K_q − K_g(F) on ker J_h with row c in J_h (displacement control of c).
class HeldStability {
 public:
  HeldStability(const EquilibriumProblem& traced, int c)
      : problem_(traced.chain(), heldEnd(traced.endCondition(), c), Eigen::Vector3d::Zero()),
        bound_(problem_),
        held_(problem_.endCondition().heldIndices()),
        u_(traced.segments() + int(held_.size())) {}

  int negative(const Eigen::VectorXd& q, const Wrench& F, double* smallest = nullptr,
               const ContactSet& locked = ContactSet()) {
    const int n = int(q.size());
    u_.head(n) = q;
    for (size_t k = 0; k < held_.size(); ++k) u_[n + int(k)] = F[held_[k]];
    cont::StabilityInfo info;
    if (!locked.empty())
      info = constrainedStability(problem_, locked, u_, 0.0, smallest ? 1 : 0);
    else if (!bound_.stability(u_, 0.0, smallest ? 1 : 0, info))
      return -1;
    if (!info.valid()) return -1;
    if (smallest) *smallest = info.smallest;
    return info.negative;
  }

 private:
  static EndCondition heldEnd(EndCondition end, int c) {
    end.control[size_t(c)] = Control::Held;
    return end;
  }
  EquilibriumProblem problem_;
  cont::BoundProblem bound_;  // its workspace, for every point of the branch
  std::vector<int> held_;
  Eigen::VectorXd u_;
};

bool inRange(double v, const ReportOptions& o) {
  if (!std::isfinite(o.rangeLow) || !std::isfinite(o.rangeHigh)) return true;
  const double slack = 1e-9 * std::max({o.rangeHigh - o.rangeLow, std::abs(o.rangeLow), std::abs(o.rangeHigh)});
  return v >= o.rangeLow - slack && v <= o.rangeHigh + slack;
}

SpecialPointReport atPoint(const PointReport& p, EventType type, Phenomenon phenomenon) {
  SpecialPointReport s;
  s.type = type;
  s.phenomenon = phenomenon;
  s.index = p.index;
  s.parameter = p.parameter;
  s.F = p.F;
  s.pose = p.pose;
  s.q = p.q;
  s.shape = shapeName(p.q, kStraightTolerance);
  s.residual = p.residual;
  return s;
}

/// A joint within 0.2 % of its range of a geometric limit at the last point of a branch whose
/// steps collapsed: there the closing spring's length goes to zero and the model's derivatives
/// blow up (L' ~ 1/L), so the steps collapse just before it, where the smooth model ends. Not a
/// user's stop (q_min, q_max) inside the geometric range: the tracer locates that as a boundary,
/// or the contact model holds the joint on it, and steps collapsing next to it are a failure.
/// −1: none.
int jointAtLimit(const Chain& chain, const Eigen::VectorXd& q) {
  int joint = -1;
  for (int i = 0; i < chain.size(); ++i) {
    const Segment& s = chain.segment(i);
    const double lo = s.geometricLowerLimit(), hi = s.geometricUpperLimit();
    if (std::min(hi - q[i], q[i] - lo) < 2e-3 * (hi - lo)) joint = i;
  }
  return joint;
}

// Through the reaction the traced λ is the reaction: its range is the load limit, and the
// path's own range end is the held coordinate's boundary (EquilibriumOptions::heldRange).
void describeReactionPathStop(const EquilibriumProblem& problem, const cont::Branch& b, BranchReport& r) {
  if (b.stopReason == cont::StopReason::LambdaRange) {
    r.stopReason = "load limit";
    r.stopMessage = "the reaction reached the load limit " + formatShort(b.points.empty() ? 0.0 : b.points.back().lambda) +
                    " before the held coordinate left the path's range";
  } else if (b.stopReason == cont::StopReason::Boundary && !b.specialPoints.empty() &&
             problem.isRangeBoundary(b.specialPoints.back().boundaryName)) {
    r.stopReason = cont::toString(cont::StopReason::LambdaRange);
    r.stopMessage = b.specialPoints.back().boundaryName;
  }
}

// ---- reportBranch, part by part ---------------------------------------------------------------

// Every point of the branch (also those out of range: the stability of neighbours); those in
// range, with their stiffness, into r.points. Returned only where the two differ (traced through
// a reaction, options.heldCoordinate): else every point is in range and r.points is the list.
std::vector<PointReport> reportPoints(EquilibriumProblem& problem, const cont::Branch& b, const ReportOptions& options,
                                      const std::vector<ContactStretch>& stretches, HeldStability* held,
                                      BranchReport& r) {
  const Chain& chain = problem.chain();
  const int n = chain.size();
  const int c = options.heldCoordinate;
  const bool throughReaction = c >= 0;
  std::vector<PointReport> all;  // every point, also out of range (stability of neighbours)
  all.reserve(b.points.size());
  Eigen::VectorXd torques(problem.dimension());
  std::optional<cont::BoundProblem> free;  // one workspace for the locked points' residuals
  for (size_t i = 0; i < b.points.size(); ++i) {
    const cont::ContinuationPoint& p = b.points[i];
    PointReport pr;
    pr.index = int(i);
    pr.parameter = p.lambda;
    pr.q = p.u.head(n);
    pr.F = problem.wrench(p.u, p.lambda);
    pr.pose = endPose(chain, pr.q);
    pr.negative = p.stability.negative;
    pr.stable = p.stability.valid() && p.stability.stable();
    pr.minEigenvalue = p.stability.smallest;
    pr.residual = p.residualNorm;
    pr.locked = lockedAt(stretches, int(i));
    if (pr.locked.gapCount() > 0) {
      // the wall's and the self contacts' forces close the free rows (ContactProblem::contactForces);
      // the joints' contact torques include their terms
      ContactProblem held(problem, pr.locked);
      const Vector mu = held.contactForces(*held.createWorkspace(), p.u, p.lambda);
      pr.wallForces = mu.head(pr.locked.wallCount());
      pr.selfForces = mu.tail(pr.locked.selfCount());
      for (const LockedJoint& l : pr.locked.joints())
        pr.contactTorque =
            std::max(pr.contactTorque, held.compression(*held.createWorkspace(), p.u, p.lambda, l.joint));
    } else if (!pr.locked.empty() && (free ? *free : free.emplace(problem)).residual(p.u, p.lambda, torques)) {
      // The compression −side·τ_c of each locked joint (ContactProblem::compression), its contact
      // torque τ_c the free equilibrium's row: one residual for all of them.
      for (const LockedJoint& l : pr.locked.joints())
        pr.contactTorque = std::max(pr.contactTorque, -double(int(l.side)) * torques[l.joint]);
    }
    if (throughReaction) {
      pr.parameter = pr.pose[c];
      pr.negative = held->negative(pr.q, pr.F, &pr.minEigenvalue, pr.locked);
      pr.stable = pr.negative == 0;
    }
    all.push_back(std::move(pr));
  }
  // every point in range: r.points takes them over (no copy of each shape)
  if (!throughReaction)
    r.points.swap(all);
  else
    for (const PointReport& p : all)
      if (inRange(p.parameter, options)) r.points.push_back(p);
  size_t withoutStiffness = 0;  // from the point where the interrupt was requested on
  for (PointReport& pr : r.points) {
    r.worstResidual = std::max(r.worstResidual, pr.residual);
    if (options.stiffness && (withoutStiffness > 0 || options.interrupt.requested())) {
      ++withoutStiffness;
      continue;
    }
    CartesianStiffness structured;
    if (options.stiffness && chain.size() >= kStructuredStiffnessFrom &&
        structuredContactStiffness(ContactProblem(problem, pr.locked), b.points[size_t(pr.index)].u,
                                   b.points[size_t(pr.index)].lambda, structured)) {
      pr.K = structured.stiffness;  // O(n); where it does not apply (contact.h), the dense routes below
      pr.C = structured.compliance;
      pr.rotationalStiffness = structured.rotationalStiffness;
      pr.haveStiffness = true;
    } else if (options.stiffness && pr.locked.selfCount() > 0) {
      // a self contact's rank-2 Hessian term is outside lockedLoadedStiffness's solve: the dense one
      const cont::ContinuationPoint& p = b.points[size_t(pr.index)];
      const CartesianStiffness s = denseContactStiffness(ContactProblem(problem, pr.locked), p.u, p.lambda);
      pr.K = s.stiffness;
      pr.C = s.compliance;
      pr.rotationalStiffness = s.rotationalStiffness;
      pr.haveStiffness = true;
    } else if (options.stiffness) {
      // along a control path K_q is that of the free lengths at the point's λ
      // and with body loads the Hessian's generator h − γ (eq B3)
      const double lambda = b.points[size_t(pr.index)].lambda;
      StiffnessOptions so;
      so.bodyGenerator = problem.bodyLoadGenerator(pr.q, lambda);
      const CartesianStiffness s = lockedLoadedStiffness(problem.controlled() ? problem.chainAt(lambda) : chain, pr.q,
                                                         pr.F, problem.endCondition(), pr.locked, so, pr.wallForces);
      pr.K = s.stiffness;
      pr.C = s.compliance;
      pr.rotationalStiffness = s.rotationalStiffness;
      pr.haveStiffness = true;
    }
  }
  if (withoutStiffness > 0)
    r.skip("the loaded stiffness at " + std::to_string(withoutStiffness) + " of " + std::to_string(r.points.size()) +
           " points");
  return all;
}

// The special points located by the tracer, named and with their physical quantities.
void reportLocatedPoints(EquilibriumProblem& problem, const cont::Branch& b, const ReportOptions& options,
                         const std::vector<ContactStretch>& stretches, const std::vector<PointReport>& all,
                         BranchReport& r) {
  const Chain& chain = problem.chain();
  const int n = chain.size();
  const int c = options.heldCoordinate;
  const bool throughReaction = c >= 0;
  for (size_t k = 0; k < b.specialPoints.size(); ++k) {
    const cont::SpecialPoint& sp = b.specialPoints[k];
    if (sp.type == cont::SpecialPointType::Endpoint) continue;
    // the path's range end, traced through the reaction: the branch's end, no limit of the model
    if (sp.type == cont::SpecialPointType::Boundary && problem.isRangeBoundary(sp.boundaryName)) continue;
    PointReport at;  // the located point, as a point of the branch
    at.index = sp.index;
    at.parameter = sp.lambda;
    at.q = sp.u.head(n);
    at.F = problem.wrench(sp.u, sp.lambda);
    at.pose = endPose(chain, at.q);
    at.residual = sp.residualNorm;
    SpecialPointReport s = atPoint(at, EventType::BranchPoint, Phenomenon::None);
    s.source = int(k);
    s.lambda = sp.lambda;
    s.negativeBefore = sp.inertiaBefore;
    s.negativeAfter = sp.inertiaAfter;
    s.accuracy = sp.lambdaAccuracy;
    s.refined = sp.refined;
    s.multiplicity = sp.multiplicity;
    s.branchesPredicted = sp.branchesPredicted;
    s.branchesFound = sp.branchesFound;
    if (const ContactSet& set = lockedAt(stretches, sp.index); set.gapCount() > 0) {
      ContactProblem held(problem, set);  // the forces of the stretch's wall vertices and self contacts at the point
      const Vector mu = held.contactForces(*held.createWorkspace(), sp.u, sp.lambda);
      s.wallVertices = set.wall();
      s.wallForces = mu.head(set.wallCount());
      s.selfForces = mu.tail(set.selfCount());
    }
    const Classification cl = classify(problem, sp);
    s.phenomenon = cl.phenomenon;
    s.shape = cl.shape;
    switch (sp.type) {
      case cont::SpecialPointType::BranchPoint:
        s.type = EventType::BranchPoint;
        if (lockedAt(stretches, sp.index).empty()) addPostBuckling(problem, sp, options.interrupt, s, r);
        break;
      case cont::SpecialPointType::Fold:
        s.type = EventType::Fold;
        noteCusp(problem, sp, s);
        break;
      case cont::SpecialPointType::EigenvalueTouch: s.type = EventType::EigenvalueTouch; break;
      default:
        s.type = EventType::Boundary;
        s.note = sp.boundaryName;
        reportContactEvent(problem, b, sp, stretches, all, s);
        break;
    }
    if (throughReaction) {
      // Reported against the held coordinate, with the displacement-controlled stability of the
      // neighbouring points (the traced problem's inertia is the load-controlled one).
      s.parameter = s.pose[c];
      if (!b.points.empty()) {
        const size_t i0 = std::min(size_t(std::max(sp.index, 0)), b.points.size() - 1);
        const size_t i1 = std::min(i0 + 1, b.points.size() - 1);
        s.negativeBefore = all[i0].negative;
        s.negativeAfter = all[i1].negative;
      }
      s.note = "stability under displacement control of the held coordinate (neighbouring points)";
      if (sp.type == cont::SpecialPointType::Fold) {
        // The reaction peaks while the held coordinate moves on: the stiffness in that direction
        // passes through zero, nothing jumps.
        s.type = EventType::ReactionFold;
        s.phenomenon = Phenomenon::QuasiBuckling;
        s.note = "fold of the reaction force: no jump under displacement control";
      }
    }
    s.jumps = s.type == EventType::Fold && s.phenomenon == Phenomenon::Jumping;
    if (!sp.note.empty()) s.note += (s.note.empty() ? "" : "; ") + sp.note;
    if (sp.multiplicity > 1)
      s.note += (s.note.empty() ? "" : "; ") + std::string("multiplicity ") + std::to_string(sp.multiplicity);
    r.specialPoints.push_back(std::move(s));
  }
}

// A joint limit where the steps collapsed (not located: the last converged point).
void reportCollapsedLimit(const Chain& chain, const cont::Branch& b, int limitJoint, const std::vector<PointReport>& all,
                          BranchReport& r) {
  if (limitJoint >= 0) {
    const PointReport& p = all.back();
    SpecialPointReport s = atPoint(p, EventType::JointLimit, Phenomenon::QuasiBuckling);
    s.lambda = b.points.back().lambda;
    s.negativeBefore = s.negativeAfter = p.negative;
    s.accuracy = all.size() >= 2 ? std::abs(p.parameter - all[all.size() - 2].parameter) : 0.0;
    const Segment& segment = chain.segment(limitJoint);
    const double lo = segment.geometricLowerLimit(), hi = segment.geometricUpperLimit();
    const bool upper = s.q[limitJoint] > 0.5 * (lo + hi);
    std::ostringstream os;
    os << "joint " << limitJoint + 1 << " " << (upper ? "upper" : "lower") << " geometric limit: last converged point "
       << std::abs((upper ? hi : lo) - s.q[limitJoint]) << " rad from it (the closing spring nearly reaches zero length)";
    s.note = os.str();
    r.specialPoints.push_back(std::move(s));
  }
}

// Displacement control: turning points of the held coordinate.
void reportHeldCoordinateFolds(const cont::Branch& b, const ReportOptions& options, const std::vector<PointReport>& all,
                               BranchReport& r) {
  const int c = options.heldCoordinate;
  const bool throughReaction = c >= 0;
  // Where the displacement-controlled stability changes between two points away from a branch
  // point, the held coordinate c(s) turns back (dc/ds = 0): the chain jumps there.
  if (throughReaction) {
    for (size_t i = 1; i < all.size(); ++i) {
      const PointReport &a = all[i - 1], &m = all[i];
      if (a.negative == m.negative || a.negative < 0 || m.negative < 0) continue;
      if (!inRange(a.parameter, options) || !inRange(m.parameter, options)) continue;
      const double gap = std::abs(a.F[c] - m.F[c]);
      bool nearBP = false;
      for (const SpecialPointReport& sr : r.specialPoints)
        if (sr.type == EventType::BranchPoint &&
            std::abs(sr.F[c] - m.F[c]) <= gap * (1.0 + 1e-12) + 1e-15 * std::abs(m.F[c]))
          nearBP = true;
      if (nearBP) continue;
      const PointReport& at = a.stable ? a : m;
      SpecialPointReport s = atPoint(at, EventType::Fold, Phenomenon::Jumping);
      s.index = a.index;
      s.lambda = b.points[size_t(at.index)].lambda;
      s.negativeBefore = a.negative;
      s.negativeAfter = m.negative;
      s.accuracy = std::abs(m.parameter - a.parameter);
      s.note = "fold of the held coordinate under displacement control, located to the point spacing";
      r.specialPoints.push_back(std::move(s));
    }
    r.specialPoints.erase(std::remove_if(r.specialPoints.begin(), r.specialPoints.end(),
                                         [&](const SpecialPointReport& s) { return !inRange(s.parameter, options); }),
                          r.specialPoints.end());
  }
}

// Quasi-buckling: a deep local minimum of the stiffness measure along a stable stretch.
void reportStiffnessMinima(EquilibriumProblem& problem, const cont::Branch& b, const ReportOptions& options,
                           BranchReport& r) {
  const Chain& chain = problem.chain();
  const int n = chain.size();
  const int c = options.heldCoordinate;
  const bool throughReaction = c >= 0;
  // Bracketed where the exact rate dm/ds along the traced tangents changes from negative to
  // positive between two consecutive stable points, then located on the branch itself
  // (stiffness_extremum.h): neither the step size nor the units move it.
  // every point's K is needed (the measure at the start, the depth of each minimum)
  if (options.stiffness && !r.skipped.empty()) r.skip("the stiffness minima");
  if (options.stiffness && r.skipped.empty() && r.points.size() >= 2 && !b.points.empty()) {
    const StiffnessMeasure measure = options.stiffnessMeasure;
    const char* name = toString(measure);
    const int N = problem.dimension();
    const double m0 = stiffnessMeasure(r.points.front().K, measure);
    std::vector<double> rate(r.points.size(), std::numeric_limits<double>::quiet_NaN());
    for (size_t i = 0; i < r.points.size(); ++i) {
      const cont::ContinuationPoint& p = b.points[size_t(r.points[i].index)];
      if (p.tangent.size() != N + 1 || !r.points[i].stable || !r.points[i].locked.empty()) continue;  // free stretches only
      if (options.interrupt.requested()) return r.skip("the stiffness minima");
      const StiffnessRate sr = stiffnessRate(problem, p.u, p.lambda, p.tangent.head(N), p.tangent[N], measure);
      if (sr.valid) rate[i] = sr.rate;
    }
    for (size_t i = 0; i + 1 < r.points.size(); ++i) {
      const PointReport &p0 = r.points[i], &p1 = r.points[i + 1];
      if (p1.index != p0.index + 1 || !(rate[i] < 0.0 && rate[i + 1] > 0.0) || !std::isfinite(m0)) continue;
      if (options.interrupt.requested()) return r.skip("the stiffness minima");
      const StiffnessExtremum x =
          locateStiffnessMinimum(problem, b.points[size_t(p0.index)], b.points[size_t(p1.index)], measure);
      const double ma = stiffnessMeasure(p0.K, measure), mc = stiffnessMeasure(p1.K, measure);
      const double value = x.located ? x.value : std::min(ma, mc);
      if (!(value > 0.0 && value < options.deepStiffnessRatio * m0)) continue;
      SpecialPointReport s = atPoint(ma <= mc ? p0 : p1, EventType::StiffnessMinimum, Phenomenon::QuasiBuckling);
      s.index = p0.index;
      s.lambda = b.points[size_t(ma <= mc ? p0.index : p1.index)].lambda;
      s.negativeBefore = s.negativeAfter = 0;
      std::ostringstream os;
      os.precision(12);
      os << "local minimum of " << name << " = " << value << " (branch start: " << m0 << "), ";
      if (x.located) {
        s.refined = true;
        s.lambda = x.lambda;
        s.q = x.u.head(n);
        s.F = problem.wrench(x.u, x.lambda);
        s.pose = endPose(chain, s.q);
        s.parameter = throughReaction ? s.pose[c] : x.lambda;
        s.shape = shapeName(s.q, kStraightTolerance);
        s.accuracy = x.accuracy;
        s.residual = x.residual;
        s.K = x.K;
        os << "located on the branch where d" << name << "/ds = 0 (|dλ| of the last iterates " << x.accuracy << ")";
      } else {
        s.accuracy = std::abs(p1.parameter - p0.parameter);
        os << "not located (" << x.message << "): to the point spacing";
      }
      s.note = os.str();
      r.specialPoints.push_back(std::move(s));
    }
  }
}

}  // namespace

void BranchReport::skip(const std::string& what) {
  if (skipped.find(what) != std::string::npos) return;
  skipped += (skipped.empty() ? "" : ", ") + what;
}

std::string ReportOptions::validate(const std::string& prefix) const {
  return cont::firstProblem(
      {cont::require(heldCoordinate >= -1 && heldCoordinate <= 2, prefix, "heldCoordinate",
                     "must be -1 (none), 0 (x), 1 (y) or 2 (phi)"),
       cont::require(!std::isnan(rangeLow) && !std::isnan(rangeHigh) && rangeLow <= rangeHigh, prefix, "rangeLow",
                     "must not exceed rangeHigh (neither NaN)"),
       cont::require(deepStiffnessRatio > 0.0 && deepStiffnessRatio <= 1.0, prefix, "deepStiffnessRatio",
                     "must lie in (0, 1]")});
}

BranchReport reportBranch(EquilibriumProblem& problem, const cont::Branch& b, const ReportOptions& options) {
  return reportBranch(problem, b, options, {});
}

BranchReport reportBranch(EquilibriumProblem& problem, const cont::Branch& b, const ReportOptions& options,
                          const std::vector<ContactStretch>& stretches, GeometricContacts* geometric) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("ReportOptions: " + why);
  const Chain& chain = problem.chain();
  const int n = chain.size();
  const int c = options.heldCoordinate;
  const bool throughReaction = c >= 0;
  std::unique_ptr<HeldStability> held;
  if (throughReaction) held = std::make_unique<HeldStability>(problem, c);

  BranchReport r;
  r.stopReason = cont::toString(b.stopReason);
  r.stopMessage = b.stopMessage;
  r.finished = regularStop(b.stopReason);
  if (throughReaction) describeReactionPathStop(problem, b, r);
  int limitJoint = -1;
  if (!r.finished && b.stopReason == cont::StopReason::StepSizeTooSmall && !b.points.empty()) {
    limitJoint = jointAtLimit(chain, b.points.back().u.head(n));
    if (limitJoint >= 0) {
      r.finished = true;
      r.stopReason = "joint limit";
      r.stopMessage = "joint " + std::to_string(limitJoint + 1) + " reached its geometric limit (" + b.stopMessage + ")";
    }
  }

  const std::vector<PointReport> inAndOutOfRange = reportPoints(problem, b, options, stretches, held.get(), r);
  const std::vector<PointReport>& all = throughReaction ? inAndOutOfRange : r.points;
  reportLocatedPoints(problem, b, options, stretches, all, r);
  reportCollapsedLimit(chain, b, limitJoint, all, r);
  reportHeldCoordinateFolds(b, options, all, r);
  reportStiffnessMinima(problem, b, options, r);
  reportGeometricContacts(problem, b, all, options, r, geometric);  // base / self contact (contact_geometry.h)
  if (!r.skipped.empty()) r.skipped = "not computed: " + r.skipped + " (" + options.interrupt.describe() + ")";
  for (PointReport& p : r.points) p.branch = b.id;
  for (SpecialPointReport& s : r.specialPoints) {
    s.branch = b.id;
    s.stabilityBefore = stabilityLabel(s.negativeBefore);
    s.stabilityAfter = stabilityLabel(s.negativeAfter);
  }
  return r;
}

}  // namespace buckle::mechanics
