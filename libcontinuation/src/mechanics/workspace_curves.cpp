#include "workspace_curves.h"

#include <Eigen/QR>
#include <cmath>
#include <map>

#include "buckle/continuation/corrector.h"
#include "buckle/continuation/tracer.h"

namespace buckle::mechanics::detail {

namespace cont = buckle::continuation;

namespace {

BoundaryCause causeOf(InputPlaneCurveProblem::Condition c) {
  switch (c) {
    case InputPlaneCurveProblem::Condition::Fold: return BoundaryCause::Fold;
    case InputPlaneCurveProblem::Condition::Singular: return BoundaryCause::Singular;
    case InputPlaneCurveProblem::Condition::Limit: return BoundaryCause::JointLimit;
  }
  return BoundaryCause::Fold;
}

// Distance in the box scaled to the unit square: one grid cell is (1/(count₁−1), 1/(count₂−1)).
struct BoxMetric {
  double w1, w2;
  double operator()(double a1, double a2, double b1, double b2) const {
    return std::hypot((a1 - b1) / w1, (a2 - b2) / w2);
  }
};

bool onTracedCurve(const WorkspaceMap& map, const std::string& name, double u1, double u2, const BoxMetric& d,
                   double within) {
  for (const WorkspaceCurve& c : map.curves) {
    if (c.name != name) continue;
    for (size_t k = 0; k < c.points.size(); ++k) {
      if (d(c.points[k].u1, c.points[k].u2, u1, u2) < within) return true;
      if (k == 0) continue;  // the segment between two points: a step can be longer than a cell
      const WorkspaceCurvePoint &a = c.points[k - 1], &b = c.points[k];
      const double ex = (b.u1 - a.u1) / d.w1, ey = (b.u2 - a.u2) / d.w2, len2 = ex * ex + ey * ey;
      if (len2 <= 0.0) continue;
      const double t = std::clamp(((u1 - a.u1) / d.w1 * ex + (u2 - a.u2) / d.w2 * ey) / len2, 0.0, 1.0);
      if (d(a.u1 + t * (b.u1 - a.u1), a.u2 + t * (b.u2 - a.u2), u1, u2) < within) return true;
    }
  }
  return false;
}

// The unit tangent of the curve at x = (q, u₂, u₁): the null vector of [G_U, G_λ] (scaled).
bool curveTangent(const cont::BoundProblem& bound, ConstVectorRef x, Vector& t) {
  const int N = bound.dimension();
  Matrix J(N, N + 1);
  Vector Gl(N);
  if (!bound.jacobian(x.head(N), x[N], J.leftCols(N), Gl)) return false;
  J.col(N) = Gl;
  const Eigen::FullPivHouseholderQR<Matrix> qr(J.transpose());
  const Matrix Q = qr.matrixQ();
  t = Q.col(N);
  return t.allFinite();
}

WorkspaceCurvePoint curvePoint(const InputPlaneCurveProblem& problem, cont::ProblemWorkspace& ws,
                               const cont::ContinuationPoint& pt, int n) {
  WorkspaceCurvePoint w;
  w.u1 = pt.lambda;
  w.u2 = pt.u[n];
  w.q = pt.u.head(n);
  w.residual = pt.residualNorm;
  cont::ProblemWorkspace* eqWs = nullptr;
  const EquilibriumProblem& p = problem.alongFirst(ws, w.u2, eqWs);
  w.pose = endPose(p.chain(), pt.u.head(n));
  cont::StabilityInfo info;
  if (p.stability(*eqWs, pt.u.head(n), w.u1, 0, info)) w.negative = info.negative;
  return w;
}

}  // namespace

void traceBoundaryCurves(const InputPlane& plane, const WorkspaceMapOptions& o, const std::vector<CurveStart>& starts,
                         WorkspaceMap& map) {
  const int n = plane.segments();
  const BoxMetric metric{(o.first.to - o.first.from) / (o.first.count - 1),
                         (o.second.to - o.second.from) / (o.second.count - 1)};
  std::map<std::string, int> traced;
  for (const CurveStart& s : starts) {
    if (o.tracer.interrupt.requested()) return;
    const double u1 = s.x[n + 1], u2 = s.x[n];
    if (traced[s.name] >= o.maxCurves || onTracedCurve(map, s.name, u1, u2, metric, 0.75)) continue;
    InputPlaneCurveProblem problem(plane, s.condition, s.boundary);
    problem.watch(&o.tracer.interrupt);
    auto ws = problem.createWorkspace();
    cont::BoundProblem bound(problem, *ws);
    Vector x(n + 2);
    {
      ScaledCorrector corrector(bound);
      if (!corrector.withFixedCoordinate(s.x, s.fixed, x)) {
        map.problems.push_back("a " + s.name + " curve near (" + std::to_string(u1) + ", " + std::to_string(u2) +
                               ") could not be started: the augmented system did not converge there");
        continue;
      }
    }
    if (x[n + 1] < o.first.from || x[n + 1] > o.first.to || x[n] < o.second.from || x[n] > o.second.to) continue;
    if (onTracedCurve(map, s.name, x[n + 1], x[n], metric, 0.75)) continue;
    Vector t;
    if (!curveTangent(bound, x, t)) continue;
    cont::TracerOptions to = o.tracer;
    to.maxPoints = o.maxCurvePoints;
    to.lambdaMin = o.first.from;
    to.lambdaMax = o.first.to;
    to.boxLower = Vector::Constant(n + 2, -std::numeric_limits<double>::infinity());
    to.boxUpper = Vector::Constant(n + 2, std::numeric_limits<double>::infinity());
    to.boxLower[n] = o.second.from;
    to.boxUpper[n] = o.second.to;
    to.detection = cont::DetectionOptions();
    to.detection.folds = to.detection.branchPoints = to.detection.stability = false;
    to.detection.lowestEigenvalues = 0;
    to.linearAlgebra = cont::TracerOptions::LinearAlgebra::Dense;
    // a closed curve comes back to its start: it ends there (once it has gone a few cells away)
    bool closed = false;
    double farthest = 0.0;
    to.onStep = [&](const cont::StepInfo& step) {
      const double d = metric(step.point.lambda, step.point.u[n], x[n + 1], x[n]);
      farthest = std::max(farthest, d);
      if (farthest > 2.0 && d < 0.5) {
        closed = true;
        return cont::StepAction::Join;
      }
      return cont::StepAction::Continue;
    };
    WorkspaceCurve curve;
    curve.cause = causeOf(s.condition);
    curve.name = s.name;
    const cont::Branch forward = cont::trace(bound, x.head(n + 1), x[n + 1], cont::InitialDirection::along(t), to);
    cont::Branch backward;
    if (!closed) {
      farthest = 0.0;
      backward = cont::trace(bound, x.head(n + 1), x[n + 1], cont::InitialDirection::along(-t), to);
    }
    for (size_t k = backward.points.size(); k-- > 1;) curve.points.push_back(curvePoint(problem, *ws, backward.points[k], n));
    for (const cont::ContinuationPoint& pt : forward.points) curve.points.push_back(curvePoint(problem, *ws, pt, n));
    curve.stop = closed ? std::string("closed") : forward.stopMessage + "; " + backward.stopMessage;
    if (curve.points.size() < 2) continue;
    ++traced[s.name];
    map.curves.push_back(std::move(curve));
  }
}

}  // namespace buckle::mechanics::detail
