#include "buckle/mechanics/task_path_trace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "buckle/mechanics/shape_name.h"

namespace buckle::mechanics {

namespace cont = buckle::continuation;

const char* toString(TaskPathEvent event) {
  switch (event) {
    case TaskPathEvent::Completed: return "completed";
    case TaskPathEvent::Fold: return "fold";
    case TaskPathEvent::BranchPoint: return "branch point";
    case TaskPathEvent::StabilityLoss: return "loss of stability";
    case TaskPathEvent::JointLimit: return "joint limit";
    case TaskPathEvent::InputBound: return "input bound";
    case TaskPathEvent::EigenvalueCoalescence: return "eigenvalue coalescence";
    case TaskPathEvent::MaxPoints: return "max points";
    case TaskPathEvent::Failed: return "failed";
    case TaskPathEvent::Interrupted: return "interrupted";
  }
  return "";
}

double taskLegLength(const TaskSetup& setup, const Vector& from, const Vector& to, double angleLength) {
  double sum = 0.0;
  for (size_t k = 0; k < setup.coordinates.size(); ++k) {
    const double d = (to[Eigen::Index(k)] - from[Eigen::Index(k)]) * (setup.coordinates[k] == 2 ? angleLength : 1.0);
    sum += d * d;
  }
  return std::sqrt(sum);
}

bool taskPathPoint(const TaskPathProblem& problem, cont::ProblemWorkspace& workspace, const Vector& u, double s,
                   bool stiffness, TaskPathPoint& out) {
  const int n = problem.segments();
  out.s = s;
  out.q = u.head(n);
  out.inputs = u.segment(n, problem.inputCount());
  out.pose = endPose(problem.chain(), out.q);
  out.target = problem.target(s);
  if (!problem.fixedInputStability(workspace, u, out.inertia, out.minEigenvalue)) return false;
  out.stable = out.inertia.negative == 0 && out.inertia.zero == 0;
  out.K.setConstant(std::numeric_limits<double>::quiet_NaN());
  out.C.setConstant(std::numeric_limits<double>::quiet_NaN());
  if (!stiffness || out.inertia.zero > 0) return true;
  // C_F = J_p H⁻¹ J_pᵀ (eq 29, rotation free) by two O(n) solves through T (chain_structure.h)
  ChainStructure ws(n);
  Matrix B, Jc;
  if (!problem.assembleStructure(workspace, u, ws, B, Jc)) return false;
  ChainData data(problem.chain());
  forwardKinematics(problem.chain(), out.q, data);
  Matrix J(3, n);
  endJacobian(data, J);
  Matrix X(n, 2);
  for (int c = 0; c < 2; ++c) {
    Vector x(n);
    if (!solve(ws, J.row(c).transpose(), x)) return true;
    X.col(c) = x;
  }
  out.C = J.topRows(2) * X;
  out.C = 0.5 * (out.C + out.C.transpose()).eval();
  if (out.C.determinant() != 0.0) out.K = out.C.inverse();
  return true;
}

namespace {

TaskPathEvent boundaryEvent(TaskPathProblem& problem, const std::string& name) {
  for (int k = 0; k < problem.boundaryCount(); ++k)
    if (problem.boundaryName(k) == name) {
      switch (problem.boundaryKind(k)) {
        case TaskPathProblem::BoundaryKind::JointLimit: return TaskPathEvent::JointLimit;
        case TaskPathProblem::BoundaryKind::InputBound: return TaskPathEvent::InputBound;
        case TaskPathProblem::BoundaryKind::Stability: return TaskPathEvent::StabilityLoss;
        case TaskPathProblem::BoundaryKind::Coalescence: return TaskPathEvent::EigenvalueCoalescence;
      }
    }
  return TaskPathEvent::Failed;
}

// The special point that ends a leg, from the tracer's located point.
TaskPathSpecial special(const TaskPathProblem& problem, cont::ProblemWorkspace& workspace, const cont::SpecialPoint& sp,
                        TaskPathEvent event, int leg, bool stiffness) {
  TaskPathSpecial out;
  out.event = event;
  out.accuracy = sp.lambdaAccuracy;
  taskPathPoint(problem, workspace, sp.u, sp.lambda, stiffness, out.point);
  out.point.leg = leg;
  switch (event) {
    case TaskPathEvent::Fold:
      out.note = "fold of the task map: the inputs cannot move the end further along the path (s turns back)";
      break;
    case TaskPathEvent::BranchPoint: out.note = "branch point of the task continuation: the path is not followed uniquely"; break;
    default: out.note = sp.boundaryName; break;
  }
  return out;
}

}  // namespace

TaskPathResult traceTaskPath(TaskPathProblem& problem, const Vector& q0, const std::vector<Vector>& waypoints,
                             double angleLength, const TaskPathOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("TaskPathOptions: " + why);
  TaskPathResult result;
  const TaskSetup& setup = problem.setup();
  const int m = problem.taskCount();
  const Pose pose0 = endPose(problem.chain(), q0);
  std::vector<Vector> corners{Vector(m)};
  for (int k = 0; k < m; ++k) corners[0][k] = pose0[setup.coordinates[size_t(k)]];
  for (const Vector& w : waypoints) corners.push_back(w);
  const cont::BoundProblem bound(problem);  // one workspace for every leg (warm starts carry over)
  problem.setLeg({corners[0], Vector::Zero(m), 0.0});
  Vector u;
  try {
    u = problem.startPoint(bound.workspace(), q0, options.tracer);
  } catch (const std::runtime_error& e) {
    result.end = TaskPathEvent::Failed;
    result.message = e.what();
    return result;
  }
  double s = 0.0;
  result.legEnds.push_back(0.0);
  const double tiny = 1e-12 * std::max(problem.lengthUnit(), problem.chain().length());
  for (size_t k = 0; k + 1 < corners.size(); ++k) {
    const double length = taskLegLength(setup, corners[k], corners[k + 1], angleLength);
    if (!(length > tiny)) continue;
    const int leg = int(result.legEnds.size()) - 1;
    problem.setLeg({corners[k], (corners[k + 1] - corners[k]) / length, s});
    cont::TracerOptions opt = options.tracer;
    opt.lambdaMin = s - length;
    opt.lambdaMax = s + length;
    opt.detection.stability = false;
    opt.detection.certifiedCounting = false;
    opt.detection.boundaries = true;
    const cont::StepCallback user = opt.onStep;
    // a fold or branch point ends the path: nothing past it follows the task stably and uniquely
    opt.onStep = [user](const cont::StepInfo& step) {
      for (const cont::SpecialPoint& sp : step.specialPoints)
        if (sp.type == cont::SpecialPointType::Fold || sp.type == cont::SpecialPointType::BranchPoint)
          return cont::StepAction::Stop;
      return user ? user(step) : cont::StepAction::Continue;
    };
    const cont::Branch b = cont::trace(bound, u, s, cont::InitialDirection::increasingLambda(), opt);
    if (b.points.empty()) {
      result.end = TaskPathEvent::Failed;
      result.message = "leg " + std::to_string(leg + 1) + ": " + b.stopMessage;
      return result;
    }
    const cont::SpecialPoint* stop = nullptr;
    for (const cont::SpecialPoint& sp : b.specialPoints)
      if (sp.type == cont::SpecialPointType::Fold || sp.type == cont::SpecialPointType::BranchPoint) {
        stop = &sp;
        break;
      }
    const size_t last = stop ? size_t(stop->index) : b.points.size() - 1;
    for (size_t i = (k == 0 ? 0 : 1); i <= last; ++i) {
      TaskPathPoint p;
      p.leg = leg;
      if (!taskPathPoint(problem, bound.workspace(), b.points[i].u, b.points[i].lambda, options.stiffness, p)) continue;
      result.points.push_back(p);
      result.worstResidual = std::max(result.worstResidual, b.points[i].residualNorm);
    }
    if (stop) {
      const TaskPathEvent e = stop->type == cont::SpecialPointType::Fold ? TaskPathEvent::Fold : TaskPathEvent::BranchPoint;
      result.specials.push_back(special(problem, bound.workspace(), *stop, e, leg, options.stiffness));
      result.points.push_back(result.specials.back().point);
      result.end = e;
      result.message = result.specials.back().note;
      return result;
    }
    switch (b.stopReason) {
      case cont::StopReason::LambdaRange:
        if (std::abs(b.points.back().lambda - (s + length)) <= 1e-9 * length) break;
        result.end = TaskPathEvent::Failed;
        result.message = "leg " + std::to_string(leg + 1) + ": the continuation turned back to the leg's start";
        return result;
      case cont::StopReason::Boundary: {
        const cont::SpecialPoint& sp = b.specialPoints.back();
        result.specials.push_back(
            special(problem, bound.workspace(), sp, boundaryEvent(problem, sp.boundaryName), leg, options.stiffness));
        result.end = result.specials.back().event;
        result.message = sp.boundaryName;
        return result;
      }
      case cont::StopReason::MaxPoints:
        result.end = TaskPathEvent::MaxPoints;
        result.message = "leg " + std::to_string(leg + 1) + ": the solver's point limit (" +
                         std::to_string(opt.maxPoints) + ") reached";
        return result;
      case cont::StopReason::Interrupted:
        result.end = TaskPathEvent::Interrupted;
        result.message = b.stopMessage;
        return result;
      default:
        result.end = TaskPathEvent::Failed;
        result.message = "leg " + std::to_string(leg + 1) + ": " + std::string(cont::toString(b.stopReason)) + ": " + b.stopMessage;
        return result;
    }
    u = b.points.back().u;
    s += length;
    result.legEnds.push_back(s);
  }
  result.end = TaskPathEvent::Completed;
  return result;
}

namespace {

EventType eventType(TaskPathEvent e) {
  switch (e) {
    case TaskPathEvent::Fold: return EventType::Fold;
    case TaskPathEvent::BranchPoint: return EventType::BranchPoint;
    case TaskPathEvent::StabilityLoss: return EventType::StabilityLoss;
    case TaskPathEvent::InputBound: return EventType::InputBound;
    default: return EventType::Boundary;  // a joint limit (the path's specials are these five)
  }
}

const char* stabilityOf(const TaskPathPoint& p) {
  return p.stable ? "stable" : (p.inertia.negative > 0 ? "unstable" : "critical");
}

}  // namespace

BranchReport reportTaskPath(const TaskPathResult& path, const Wrench& payload, bool stiffness, int id) {
  BranchReport r;
  for (size_t i = 0; i < path.points.size(); ++i) {
    const TaskPathPoint& p = path.points[i];
    PointReport& o = r.points.emplace_back();
    o.branch = id;
    o.index = int(i);
    o.parameter = p.s;
    o.F = payload;
    o.pose = p.pose;
    o.q = p.q;
    o.stable = p.stable;
    o.negative = p.inertia.negative;
    o.minEigenvalue = p.minEigenvalue;
    o.haveStiffness = stiffness;
    o.K = p.K;
    o.C = p.C;
    o.inputs = p.inputs;
  }
  for (const TaskPathSpecial& sp : path.specials) {
    SpecialPointReport& s = r.specialPoints.emplace_back();
    s.branch = id;
    s.type = eventType(sp.event);
    s.index = std::max(0, int(path.points.size()) - 2);
    s.parameter = s.lambda = sp.point.s;
    s.F = payload;
    s.pose = sp.point.pose;
    s.q = sp.point.q;
    s.shape = shapeName(sp.point.q);
    // stability at fixed inputs on the path before the point, and at the point itself
    s.stabilityBefore = path.points.size() > 1 ? stabilityOf(path.points[path.points.size() - 2]) : stabilityOf(sp.point);
    s.stabilityAfter = sp.event == TaskPathEvent::StabilityLoss ? "unstable" : stabilityOf(sp.point);
    s.accuracy = sp.accuracy;
    s.K = sp.point.K;
    s.refined = true;
    s.note = sp.note;
    s.inputs = sp.point.inputs;
  }
  r.finished = path.end != TaskPathEvent::Failed && path.end != TaskPathEvent::Interrupted &&
               path.end != TaskPathEvent::MaxPoints;
  r.stopReason = toString(path.end);
  r.stopMessage = path.message;
  r.worstResidual = path.worstResidual;
  return r;
}

}  // namespace buckle::mechanics
