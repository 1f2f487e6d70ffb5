#include "scene/runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/equilibrium_solve.h"
#include "buckle/mechanics/jump.h"
#include "buckle/mechanics/load_history.h"
#include "buckle/mechanics/shape_name.h"
#include "buckle/mechanics/stiffness.h"
#include "buckle/mechanics/unloaded_shape.h"

namespace buckle::scene {

namespace cont = buckle::continuation;
namespace mech = buckle::mechanics;

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string stabilityLabel(int negative) {
  if (negative < 0) return "unknown";
  if (negative == 0) return "stable";
  return "unstable (" + std::to_string(negative) + " negative)";
}

bool regularStop(cont::StopReason r) {
  return r == cont::StopReason::LambdaRange || r == cont::StopReason::Boundary || r == cont::StopReason::Box ||
         r == cont::StopReason::MaxArclength;
}

/// Everything needed to trace and post-process the branches of one case.
class CaseRunner {
 public:
  CaseRunner(const Scene& scene, const CaseSpec& spec, CaseResult& out, RunResult& run, const RunControl& control)
      : scene_(scene), spec_(spec), out_(out), run_(run), control_(control) {}

  void continuation();
  void loadHistory();
  void suddenLoad();
  void criticalForces();
  void energyCurves();
  void torqueAngle();

  /// True once the time limit passed or a signal came: the run is then marked incomplete,
  /// once, with the reason.
  bool interrupted() {
    if (run_.interrupted) return true;
    if (!control_.interrupt.requested()) return false;
    run_.interrupted = true;
    run_.complete = false;
    run_.interruption = control_.interrupt.describe();
    run_.problems.push_back("stopped early in case \"" + spec_.label + "\": " + run_.interruption +
                            "; everything computed until then is written");
    return true;
  }

 private:
  void record(const cont::Branch& b, mech::EquilibriumProblem& problem, const std::string& origin);
  bool throughLoad() const { return spec_.path.loadLimit > 0.0; }
  /// The scene's /solver settings as tracer options (the λ range is set by each analysis).
  cont::TracerOptions solverOptions() const {
    cont::TracerOptions opt;
    opt.initialStep = scene_.solver.initialStep;
    opt.minStep = scene_.solver.minStep;
    opt.maxStep = scene_.solver.maxStep;
    opt.maxPoints = scene_.solver.maxPoints;
    opt.newtonTolerance = scene_.solver.tolerance;
    opt.interrupt = control_.interrupt;
    if (control_.progress) {
      Progress* progress = control_.progress;
      const CaseResult* out = &out_;
      const int* branches = &branchesSoFar_;
      opt.onStep = [progress, out, branches](const cont::Branch& b) {
        progress->step(*branches + 1, static_cast<int>(b.points.size()), b.points.back().lambda,
                       static_cast<int>(out->specials.size() + b.specialPoints.size()));
        return cont::StepAction::Continue;
      };
    }
    return opt;
  }
  /// Integration settings of the dynamics with the run's interrupt.
  mech::IntegrationOptions integrationOptions(mech::IntegrationOptions opt = mech::IntegrationOptions()) const {
    opt.interrupt = control_.interrupt;
    return opt;
  }
  /// The path as an EquilibriumProblem: prescribed(λ) = start values + (λ − s0)·direction.
  mech::EquilibriumProblem pathProblem() const {
    mech::EndCondition end = spec_.end.condition;
    end.value -= out_.startValue * spec_.path.direction;
    return mech::EquilibriumProblem(out_.chain, end, spec_.path.direction);
  }
  /// Releases the chain at a fold with the loads frozen there: where does it land?
  void simulateJumpAt(mech::EquilibriumProblem& problem, const cont::SpecialPoint& sp, SpecialRecord& s) {
    const int n = out_.chain.size();
    mech::JumpOptions opt;
    opt.perturbation = scene_.analyses.jump.perturbation;
    opt.integration = integrationOptions(mech::jumpIntegrationDefaults(out_.chain.size()));
    opt.integration.recordTrajectory = false;
    s.jumpTried = true;
    try {
      const mech::JumpResult j = mech::simulateJump(problem, sp.u, sp.lambda, opt);
      s.jumpSuccess = j.success;
      s.jumpMessage = j.message;
      // the chain snaps onto a geometric joint limit, where the smooth model ends (a spring
      // reaches zero length): a known outcome, reported with the state reached there
      const bool toLimit = !j.success && j.stopReason == mech::IntegrationStop::JointLimit && j.restPoint.size() >= n;
      if (toLimit) {
        s.jumpSuccess = true;
        s.jumpLanding = "joint limit";
        s.jumpQ = j.restPoint.head(n);
        s.jumpF = problem.wrench(sp.u, sp.lambda);
        s.jumpPose = mech::endPose(out_.chain, s.jumpQ);
        s.jumpShape = mech::shapeName(s.jumpQ, 1e-6);
        s.energyReleased = j.energyReleased;
        s.jumpDistance = (s.jumpQ - sp.u.head(n)).cwiseAbs().maxCoeff();
        return;
      }
      s.jumpLanding = "stable equilibrium";
      if (j.to.size() >= n) {
        s.jumpQ = j.to.head(n);
        s.jumpF = problem.wrench(j.to, sp.lambda);
        s.jumpPose = mech::endPose(out_.chain, s.jumpQ);
        s.jumpShape = mech::shapeName(s.jumpQ, 1e-6);
      }
      s.energyReleased = j.energyReleased;
      s.jumpDistance = j.distance;
      if (!j.success && j.stopReason == mech::IntegrationStop::Interrupted) {
        interrupted();
      } else if (!j.success) {
        run_.complete = false;
        run_.problems.push_back("case \"" + spec_.label + "\": jump from the fold at " + spec_.path.parameter + " = " +
                                std::to_string(sp.lambda) + " did not land on a stable equilibrium: " + j.message);
      }
    } catch (const std::invalid_argument& e) {
      s.jumpSuccess = false;
      s.jumpMessage = e.what();
      run_.complete = false;
      run_.problems.push_back("case \"" + spec_.label + "\": jump: " + e.what());
    }
  }
  /// Stability under the scene's own end condition (displacement control of the parameter).
  cont::StabilityInfo heldStability(const Eigen::VectorXd& q, const mech::Wrench& F) const {
    const int n = out_.chain.size();
    mech::Matrix H(n, n);
    mech::totalPotentialHessian(out_.chain, q, F, H);
    mech::ChainData data(out_.chain);
    mech::forwardKinematics(out_.chain, q, data);
    mech::Matrix J(3, n);
    mech::endJacobian(data, J);
    const std::vector<int> held = spec_.end.condition.heldIndices();
    mech::Matrix C(held.size(), n);
    for (size_t k = 0; k < held.size(); ++k) C.row(Eigen::Index(k)) = J.row(held[k]);
    return cont::projectedInertia(H, C, 1e-10);
  }

  const Scene& scene_;
  const CaseSpec& spec_;
  CaseResult& out_;
  RunResult& run_;
  const RunControl& control_;
  int branchesSoFar_ = 0;  // for progress reports
};

void CaseRunner::record(const cont::Branch& b, mech::EquilibriumProblem& problem, const std::string& origin) {
  const int n = out_.chain.size();
  BranchRecord br;
  br.id = b.id;
  br.parent = b.parentId;
  br.origin = origin;
  br.stopReason = cont::stopReasonName(b.stopReason);
  br.stopMessage = b.stopMessage;
  br.points = static_cast<int>(b.points.size());
  br.finished = regularStop(b.stopReason);
  // Near a geometric joint limit the closing spring's length goes to zero and the model's
  // derivatives blow up (L' ~ 1/L): the tracer's steps collapse just before the limit. That is
  // the joint reaching its limit, not a failure; it is reported as such.
  int limitJoint = -1;
  if (!br.finished && b.stopReason == cont::StopReason::StepSizeTooSmall && !b.points.empty()) {
    const Eigen::VectorXd q = b.points.back().u.head(n);
    for (int i = 0; i < n; ++i) {
      const double lo = out_.chain.lowerLimits()[i], hi = out_.chain.upperLimits()[i];
      if (std::min(hi - q[i], q[i] - lo) < 2e-3 * (hi - lo)) limitJoint = i;
    }
    if (limitJoint >= 0) {
      br.finished = true;
      br.stopReason = "joint limit";
      br.stopMessage = "joint " + std::to_string(limitJoint + 1) + " reached its limit (" + br.stopMessage + ")";
    }
  }
  if (b.stopReason == cont::StopReason::Interrupted) {
    interrupted();  // reported once for the run, not per branch
  } else if (!br.finished) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\", branch " + std::to_string(b.id) + " (" + origin +
                            ") stopped early: " + br.stopReason + (b.stopMessage.empty() ? "" : " — " + b.stopMessage));
  }
  out_.branches.push_back(br);

  const size_t first = out_.points.size();
  for (size_t i = 0; i < b.points.size(); ++i) {
    const cont::ContinuationPoint& p = b.points[i];
    PointRecord r;
    r.branch = b.id;
    r.index = static_cast<int>(i);
    r.parameter = p.lambda;
    r.q = p.u.head(n);
    r.F = problem.wrench(p.u, p.lambda);
    r.pose = mech::endPose(out_.chain, r.q);
    r.negative = p.stability.negative;
    r.stable = p.stability.valid() && p.stability.stable();
    r.minEigenvalue = p.stability.smallest;
    if (throughLoad()) {
      const int c = spec_.path.coordinate;
      r.parameter = r.pose[c];
      const double lo = std::min(spec_.path.from, spec_.path.to), hi = std::max(spec_.path.from, spec_.path.to);
      if (r.parameter < lo - 1e-9 || r.parameter > hi + 1e-9) continue;
      const cont::StabilityInfo st = heldStability(r.q, r.F);
      r.negative = st.negative;
      r.stable = st.valid() && st.negative == 0;
      r.minEigenvalue = st.smallest;
    }
    if (scene_.analyses.stiffness) {
      const mech::CartesianStiffness K = mech::loadedStiffness(out_.chain, r.q, r.F, problem.endCondition());
      r.K = K.stiffness;
      r.haveStiffness = true;
    }
    run_.worstResidual = std::max(run_.worstResidual, p.residualNorm);
    out_.points.push_back(r);
  }

  for (const cont::SpecialPoint& sp : b.specialPoints) {
    SpecialRecord s;
    switch (sp.type) {
      case cont::SpecialPointType::BranchPoint:
        s.type = "BP";
        s.field = "buckling";
        break;
      case cont::SpecialPointType::Fold:
        s.type = "LP";
        s.field = "jumping";
        break;
      case cont::SpecialPointType::Boundary:
        s.type = "BD";
        s.field = "quasi-buckling";
        s.note = sp.boundaryName;
        break;
      case cont::SpecialPointType::Endpoint: continue;
    }
    s.branch = b.id;
    s.parameter = sp.lambda;
    s.q = sp.u.head(n);
    s.F = problem.wrench(sp.u, sp.lambda);
    s.pose = mech::endPose(out_.chain, s.q);
    s.stabilityBefore = stabilityLabel(sp.inertiaBefore);
    s.stabilityAfter = stabilityLabel(sp.inertiaAfter);
    if (throughLoad()) {
      // reported against the held coordinate, with displacement-control stability
      s.parameter = s.pose[spec_.path.coordinate];
      const size_t i0 = std::min(size_t(sp.index), b.points.size() - 1), i1 = std::min(i0 + 1, b.points.size() - 1);
      const auto before = heldStability(b.points[i0].u.head(n), problem.wrench(b.points[i0].u, b.points[i0].lambda));
      const auto after = heldStability(b.points[i1].u.head(n), problem.wrench(b.points[i1].u, b.points[i1].lambda));
      s.stabilityBefore = stabilityLabel(before.negative);
      s.stabilityAfter = stabilityLabel(after.negative);
      s.note = "stability under displacement control of " + spec_.path.parameter + " (neighbouring points)";
      if (sp.type == cont::SpecialPointType::Fold) {
        s.type = "LPF";
        s.field = "none";
        s.note = "fold of the reaction force: no jump under displacement control";
      }
    }
    s.accuracy = sp.lambdaAccuracy;
    s.residual = sp.residualNorm;
    s.refined = sp.refined;
    if (!sp.note.empty()) s.note += (s.note.empty() ? "" : "; ") + sp.note;
    if (sp.type == cont::SpecialPointType::BranchPoint && sp.nullVectors.cols() >= 2)
      s.shape = mech::modeShapeName(sp.nullVectors.col(1).head(n));
    else
      s.shape = mech::shapeName(s.q, 1e-6);
    if (sp.multiplicity > 1) s.note += (s.note.empty() ? "" : "; ") + std::string("multiplicity ") + std::to_string(sp.multiplicity);
    run_.worstLocation = std::max(run_.worstLocation, sp.lambdaAccuracy);
    if (scene_.analyses.jump.enabled && sp.type == cont::SpecialPointType::Fold && !throughLoad()) {
      if (interrupted()) {
        s.jumpMessage = "not simulated: " + run_.interruption;
      } else {
        if (control_.progress) control_.progress->note("jump from the fold at " + std::to_string(sp.lambda));
        simulateJumpAt(problem, sp, s);
      }
    }
    out_.specials.push_back(s);
  }

  if (limitJoint >= 0) {
    const cont::ContinuationPoint& p = b.points.back();
    SpecialRecord s;
    s.type = "BD";
    s.field = "quasi-buckling";
    s.branch = b.id;
    s.parameter = p.lambda;
    s.q = p.u.head(n);
    s.F = problem.wrench(p.u, p.lambda);
    s.pose = mech::endPose(out_.chain, s.q);
    s.shape = mech::shapeName(s.q, 1e-6);
    s.stabilityBefore = s.stabilityAfter = stabilityLabel(p.stability.negative);
    if (throughLoad()) {
      s.parameter = s.pose[spec_.path.coordinate];
      s.stabilityBefore = s.stabilityAfter = stabilityLabel(heldStability(s.q, s.F).negative);
    }
    s.accuracy = b.points.size() >= 2 ? std::abs(p.lambda - b.points[b.points.size() - 2].lambda) : 0.0;
    s.residual = p.residualNorm;
    const bool upper = s.q[limitJoint] > 0.5 * (out_.chain.lowerLimits()[limitJoint] + out_.chain.upperLimits()[limitJoint]);
    std::ostringstream os;
    os << "joint " << limitJoint + 1 << " " << (upper ? "upper" : "lower") << " limit: last converged point "
       << std::abs((upper ? out_.chain.upperLimits()[limitJoint] : out_.chain.lowerLimits()[limitJoint]) - s.q[limitJoint])
       << " rad from it (the closing spring nearly reaches zero length)";
    s.note = os.str();
    out_.specials.push_back(s);
  }

  // Under displacement control through the reaction, a fold of the coordinate (dx/ds = 0) is
  // where the displacement-controlled stability changes away from branch points: a jump.
  if (throughLoad()) {
    for (size_t i = first + 1; i < out_.points.size(); ++i) {
      const PointRecord &a = out_.points[i - 1], &m = out_.points[i];
      if (a.branch != m.branch || a.negative == m.negative || a.negative < 0 || m.negative < 0) continue;
      bool nearBP = false;
      for (const SpecialRecord& sr : out_.specials)
        if (sr.branch == b.id && sr.type == "BP" &&
            std::abs(sr.F[spec_.path.coordinate] - m.F[spec_.path.coordinate]) <=
                std::abs(a.F[spec_.path.coordinate] - m.F[spec_.path.coordinate]) + 1e-12)
          nearBP = true;
      if (nearBP) continue;
      SpecialRecord s;
      s.type = "LP";
      s.field = "jumping";
      s.branch = b.id;
      const PointRecord& at = a.stable ? a : m;
      s.parameter = at.parameter;
      s.F = at.F;
      s.pose = at.pose;
      s.q = at.q;
      s.shape = mech::shapeName(at.q, 1e-6);
      s.stabilityBefore = stabilityLabel(a.negative);
      s.stabilityAfter = stabilityLabel(m.negative);
      s.accuracy = std::abs(m.parameter - a.parameter);
      s.note = "fold of " + spec_.path.parameter + " under displacement control, located to the point spacing";
      out_.specials.push_back(s);
    }
  }

  if (throughLoad()) {
    const double lo = std::min(spec_.path.from, spec_.path.to), hi = std::max(spec_.path.from, spec_.path.to);
    out_.specials.erase(std::remove_if(out_.specials.begin(), out_.specials.end(),
                                       [&](const SpecialRecord& r) {
                                         return r.branch == b.id && (r.parameter < lo - 1e-9 || r.parameter > hi + 1e-9);
                                       }),
                        out_.specials.end());
  }

  // Quasi-buckling (docs/mechanics.md, "What the physics does"): a deep, smooth minimum of Kxx along a
  // stable stretch of the branch — below half of its value at the branch start.
  if (scene_.analyses.stiffness && out_.points.size() - first >= 3) {
    const double k0 = out_.points[first].K(0, 0);
    for (size_t i = first + 1; i + 1 < out_.points.size(); ++i) {
      const PointRecord &a = out_.points[i - 1], &m = out_.points[i], &c = out_.points[i + 1];
      const double ka = a.K(0, 0), km = m.K(0, 0), kc = c.K(0, 0);
      if (!std::isfinite(ka) || !std::isfinite(km) || !std::isfinite(kc) || !std::isfinite(k0)) continue;
      if (!(m.stable && a.stable && c.stable)) continue;
      if (km < ka && km <= kc && km > 0.0 && km < 0.5 * k0) {
        SpecialRecord s;
        s.type = "KMIN";
        s.field = "quasi-buckling";
        s.branch = b.id;
        s.parameter = m.parameter;
        s.F = m.F;
        s.pose = m.pose;
        s.q = m.q;
        s.shape = mech::shapeName(m.q, 1e-6);
        s.stabilityBefore = s.stabilityAfter = "stable";
        s.accuracy = 0.5 * std::max(std::abs(c.parameter - m.parameter), std::abs(m.parameter - a.parameter));
        std::ostringstream os;
        os << "local minimum of Kxx = " << km << " (branch start: " << k0 << "), located to the point spacing";
        s.note = os.str();
        out_.specials.push_back(s);
      }
    }
  }
}

// The load history of the scene: stable quasi-static pieces joined by jumps. Each piece is a
// branch of the output; each jump a special point "JUMP" (field "jumping") with its landing,
// drawn as an arrow in the bifurcation plots.
void CaseRunner::loadHistory() {
  const int n = out_.chain.size();
  mech::EquilibriumProblem problem = pathProblem();
  mech::LoadHistoryOptions opt;
  opt.tracer = solverOptions();
  opt.jump.perturbation = scene_.analyses.loadHistory.perturbation;
  opt.jump.integration = integrationOptions(mech::jumpIntegrationDefaults(out_.chain.size()));
  mech::LoadHistoryResult h;
  try {
    h = mech::followLoadHistory(problem, out_.q0, scene_.analyses.loadHistory.waypoints, opt);
  } catch (const std::exception& e) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": load history: " + e.what());
    return;
  }
  const int base = out_.branches.empty() ? 0 : out_.branches.back().id + 1;
  for (size_t k = 0; k < h.segments.size(); ++k) {
    cont::Branch b = h.segments[k];
    b.id = base + int(k);
    b.parentId = k == 0 ? -1 : base + int(k) - 1;
    const bool endsInJump = std::any_of(h.jumps.begin(), h.jumps.end(),
                                        [&](const mech::JumpRecord& j) { return j.fromSegment == int(k); });
    if (endsInJump) {
      b.stopReason = cont::StopReason::Boundary;
      b.stopMessage = "the stable state ends here: the chain jumps";
    }
    std::ostringstream origin;
    origin << "load history, leg " << h.segmentLeg[k] << " (" << spec_.path.parameter << " -> "
           << scene_.analyses.loadHistory.waypoints[size_t(h.segmentLeg[k])] << ")"
           << (h.segmentBifurcated[k] ? ", on the stable branch born at the branch point" : "");
    record(b, problem, origin.str());
  }
  for (const mech::JumpRecord& j : h.jumps) {
    SpecialRecord s;
    s.type = "JUMP";
    s.field = "jumping";
    s.branch = j.fromSegment >= 0 ? base + j.fromSegment : base;
    s.parameter = j.lambda;
    s.q = j.from.head(n);
    s.F = problem.wrench(j.from, j.lambda);
    s.pose = mech::endPose(out_.chain, s.q);
    s.shape = mech::shapeName(s.q, 1e-6);
    s.stabilityBefore = j.trigger == mech::JumpTrigger::UnstableStart ? "unstable" : "critical";
    s.stabilityAfter = j.success ? "stable" : "unknown";
    std::ostringstream note;
    note << "trigger: " << mech::toString(j.trigger) << " at " << spec_.path.parameter << " = " << j.criticalLambda
         << "; released at " << j.lambda;
    s.note = note.str();
    s.jumpTried = true;
    s.jumpSuccess = j.success;
    s.jumpLanding = j.success ? "stable equilibrium" : "none";
    s.jumpMessage = j.message;
    if (j.to.size() > 0) {
      s.jumpQ = j.to.head(n);
      s.jumpF = j.load;
      s.jumpPose = mech::endPose(out_.chain, s.jumpQ);
      s.jumpShape = mech::shapeName(s.jumpQ, 1e-6);
    }
    s.energyReleased = j.energyReleased;
    s.jumpDistance = j.distance;
    out_.specials.push_back(s);
  }
  if (!h.completed && !interrupted()) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": load history stopped: " + h.message);
  }
}

// The sporadic load: the path parameter is set to its value at once on the chain at rest in its
// unloaded shape; the dynamic rest state is compared with the quasi-static answer, which is the
// load history from the start to the same value (jumps included where the stable state ends).
void CaseRunner::suddenLoad() {
  const int n = out_.chain.size();
  const SuddenLoadSpec& spec = scene_.analyses.suddenLoad;
  const double s0 = out_.startValue;
  mech::EquilibriumProblem problem = pathProblem();
  SuddenLoadRecord& rec = out_.sudden;
  out_.haveSudden = true;
  rec.value = spec.value;
  Eigen::VectorXd qStatic;
  if (spec.value != s0) {
    mech::LoadHistoryOptions opt;
    opt.tracer = solverOptions();
    opt.jump.integration = integrationOptions(mech::jumpIntegrationDefaults(out_.chain.size()));
    try {
      const mech::LoadHistoryResult h = mech::followLoadHistory(problem, out_.q0, {s0, spec.value}, opt);
      if (h.completed && !h.segments.empty()) qStatic = h.segments.back().points.back().u.head(n);
    } catch (const std::exception&) {
      // no quasi-static answer: the comparison is skipped and said so below
    }
  } else {
    qStatic = out_.q0;
  }
  mech::EndCondition loaded = problem.endCondition();
  loaded.value += spec.value * problem.direction();
  mech::SuddenLoadOptions opt;
  opt.integration = integrationOptions();
  if (spec.massPerLength > 0) {
    opt.scene.inertia = mech::InertiaData::uniformRods(out_.chain, spec.massPerLength);
    if (spec.damping > 0) opt.scene.jointDamping.assign(size_t(n), spec.damping);
  }
  try {
    const mech::SuddenLoadResult r = mech::simulateSuddenLoad(out_.chain, loaded, out_.q0, qStatic, opt);
    rec.success = r.success;
    rec.message = r.message;
    rec.inertial = r.inertial;
    rec.rest = r.rest;
    if (r.rest.size() == n) rec.restPose = mech::endPose(out_.chain, r.rest);
    rec.stable = r.stable;
    rec.haveStatic = r.compared;
    if (r.compared) {
      rec.staticShape = r.staticShape;
      rec.staticPose = mech::endPose(out_.chain, r.staticShape);
      rec.differs = r.differs;
      rec.maxDifference = r.maxDifference;
      rec.potentialDynamic = r.potentialDynamic;
      rec.potentialStatic = r.potentialStatic;
      rec.lower = mech::toString(r.lower);
    }
    rec.peakKinetic = r.peakKinetic;
    rec.maxExcursion = r.maxExcursion;
    rec.duration = r.dynamics.time;
    rec.residual = r.residual;
    rec.energyBalanceError = r.dynamics.maxEnergyBalanceError;
    rec.trajectory = r.dynamics.trajectory;
    if (!r.success && !interrupted()) {
      run_.complete = false;
      run_.problems.push_back("case \"" + spec_.label + "\": sudden load: " + r.message);
    }
  } catch (const std::exception& e) {
    rec.message = e.what();
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": sudden load: " + e.what());
  }
}

void CaseRunner::continuation() {
  double s0 = out_.startValue;
  mech::EndCondition end = spec_.end.condition;
  Eigen::Vector3d direction = spec_.path.direction;
  double lambdaLo = std::min(spec_.path.from, spec_.path.to), lambdaHi = std::max(spec_.path.from, spec_.path.to);
  std::vector<double> targets{spec_.path.to, spec_.path.from};
  const int c = spec_.path.coordinate;
  if (throughLoad()) {
    // trace with the held coordinate's reaction as parameter (see PathSpec::loadLimit)
    end.control[size_t(c)] = mech::Control::Load;
    end.value[c] = 0.0;
    direction = Eigen::Vector3d::Zero();
    direction[c] = 1.0;
    s0 = 0.0;
    // both signs of the reaction: with an unstable start (κ < 0) the branch points lie on the
    // tension side, and their branches still move the end into the requested range
    targets = {-spec_.path.loadLimit, spec_.path.loadLimit};
    lambdaLo = -spec_.path.loadLimit;
    lambdaHi = spec_.path.loadLimit;
  }
  end.value -= s0 * direction;  // prescribed(λ) = start values + (λ − s0)·direction
  mech::EquilibriumProblem problem(out_.chain, end, direction);

  // The unloaded shape at the start value, polished.
  const cont::Vector guess = problem.initialGuess(out_.q0, s0);
  const mech::NewtonResult nr = mech::solveEquilibrium(problem, guess, s0);
  if (!nr.converged) {
    run_.complete = false;
    std::ostringstream os;
    os << "case \"" << spec_.label << "\": no equilibrium found at the start " << spec_.path.parameter << " = " << s0
       << " from the unloaded shape (Newton residual " << nr.residualNorm << ")";
    run_.problems.push_back(os.str());
    return;
  }

  cont::TracerOptions opt = solverOptions();
  opt.lambdaMin = lambdaLo;
  opt.lambdaMax = lambdaHi;
  opt.computeStability = true;

  // The start branches (one per requested direction), then branch switching breadth first, by
  // the core's tree driver (its guards: never back at the BP a branch started from, never twice
  // at the same point).
  std::vector<cont::InitialDirection> starts;
  std::vector<std::string> origins;
  for (double target : targets) {
    if (target == s0) continue;
    const bool up = target > s0;
    starts.push_back(up ? cont::InitialDirection::increasingLambda() : cont::InitialDirection::decreasingLambda());
    origins.push_back(std::string("start, ") + (up ? "increasing " : "decreasing ") +
                      (throughLoad() ? std::string(c == 0 ? "Fx" : c == 1 ? "Fy" : "Me") + " (through the reaction)"
                                     : spec_.path.parameter));
  }
  cont::TreeOptions tree;
  tree.maxDepth = scene_.analyses.continuation.branchSwitching;
  tree.onBranch = [this](const cont::BranchTree& t, const cont::Branch&) {
    branchesSoFar_ = static_cast<int>(t.branches.size());
  };
  const cont::BranchTree result = cont::traceTree(problem, nr.u, s0, starts, opt, tree);
  for (const cont::Branch& b : result.branches) {
    std::string origin = b.parentId < 0 ? origins[size_t(b.id)]
                                        : "BP " + std::to_string(b.parentSpecialPoint) + " of branch " +
                                              std::to_string(b.parentId) + (b.direction > 0 ? ", + side" : ", - side");
    record(b, problem, origin);
  }
  if (result.interrupted) interrupted();
}

void CaseRunner::criticalForces() {
  mech::EndCondition end = spec_.end.condition;
  mech::LinearBucklingOptions opt;
  opt.count = scene_.analyses.criticalForces.modes;
  const int c = spec_.path.coordinate;
  if (end.isHeld(static_cast<mech::EndCoordinate>(c))) {
    // displacement control: the critical loads of the force that drives that coordinate
    end.control[size_t(c)] = mech::Control::Load;
    opt.direction = Eigen::Vector3d::Zero();
    opt.direction[c] = 1.0;
  } else {
    opt.direction = spec_.path.direction;
    for (int j = 0; j < 3; ++j)
      if (end.isHeld(static_cast<mech::EndCoordinate>(j))) opt.direction[j] = 0.0;
  }
  try {
    out_.critical = mech::linearBuckling(out_.chain, out_.q0, end, opt);
    out_.haveCritical = true;
  } catch (const std::invalid_argument& e) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": critical forces: " + e.what());
    return;
  }
  // the closed forms (eq 17) apply to three identical symmetric segments, straight, clamped–pinned
  const auto& segs = spec_.chain.segments;
  bool symmetric = segs.size() == 3 && out_.q0.cwiseAbs().maxCoeff() == 0.0;
  for (const auto& s : segs)
    symmetric = symmetric && s.a1 == segs[0].a1 && s.a2 == s.a1 && s.b1 == segs[0].b1 && s.b2 == s.b1 &&
                s.k1 == segs[0].k1 && s.k2 == s.k1 && s.L1_0 == segs[0].L1_0 && s.L2_0 == s.L1_0;
  const bool clampedPinned = end.isHeld(mech::EndCoordinate::Y) && !end.isHeld(mech::EndCoordinate::X) &&
                             !end.isHeld(mech::EndCoordinate::Phi) && opt.direction[0] != 0.0 &&
                             opt.direction[1] == 0.0;
  if (symmetric && clampedPinned) {
    out_.analytic = mech::analyticClampedPinned3(segs[0].a1, segs[0].b1, segs[0].k1, segs[0].L1_0);
    out_.haveAnalytic = true;
  }
}

void CaseRunner::energyCurves() {
  const EnergyCurvesSpec& e = scene_.analyses.energyCurves;
  mech::LandscapeOptions opt;
  opt.samples = e.points;
  opt.q1Min = std::max(e.q1From, out_.chain.lowerLimits()[0]);
  opt.q1Max = std::min(e.q1To, out_.chain.upperLimits()[0]);
  try {
    out_.landscape = mech::energyLandscape(out_.chain, e.x, e.y, opt);
    out_.haveLandscape = true;
  } catch (const std::invalid_argument& ex) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": energy curves: " + ex.what());
  }
}

void CaseRunner::torqueAngle() {
  const TorqueAngleSpec& t = scene_.analyses.torqueAngle;
  const mech::Segment& seg = out_.chain.segment(0);
  const double margin = 1e-6;
  const double lo = std::max(t.qFrom, seg.lowerLimit() + margin);
  const double hi = std::min(t.qTo, seg.upperLimit() - margin);
  TorqueCurve& c = out_.torque;
  for (int i = 0; i < t.points; ++i) {
    const double q = lo + (hi - lo) * i / (t.points - 1);
    c.q.push_back(q);
    c.M.push_back(seg.torque(q));
    c.Kq.push_back(seg.stiffness(q));
  }
  const mech::SegmentUnloadedAngle roots = mech::unloadedAngle(seg);
  auto add = [&](const mech::TorqueRoot& r) {
    if (r.q >= lo && r.q <= hi) c.equilibria.emplace_back(r.q, r.stable);
  };
  if (roots.found) add(roots.root);
  for (const auto& r : roots.others) add(r);
  std::sort(c.equilibria.begin(), c.equilibria.end());
  // a root found from both sides of a sign change is one root
  c.equilibria.erase(std::unique(c.equilibria.begin(), c.equilibria.end(),
                                 [](const auto& x, const auto& y) { return std::abs(x.first - y.first) < 1e-9; }),
                     c.equilibria.end());
  out_.haveTorque = true;
}

}  // namespace

RunResult runScene(const Scene& scene, const RunControl& given) {
  RunResult run;
  const Clock::time_point start = Clock::now();
  RunControl control = given;
  if (!control.interrupt.hasDeadline()) {
    // The limit bounds the whole run, writing the results included: the computation stops a
    // fifth of the limit (at most 1 s) before it, room for writing a long chain's points and
    // plots (a 50-segment tree stopped at 4.5 s writes its 19 000 points in 0.45 s on an idle
    // machine, twice that on a loaded one).
    const double limit = std::min(scene.solver.timeLimit, 1e9);
    const double compute = limit - std::min(0.2 * limit, 1.0);
    control.interrupt.setDeadline(
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(compute)), limit);
  }
  const AnalysesSpec& a = scene.analyses;
  if (a.continuation.enabled)
    run.computed.push_back(a.continuation.branchSwitching > 0
                               ? "continuation with branch switching (depth " +
                                     std::to_string(a.continuation.branchSwitching) + ")"
                               : "continuation of the primary branch");
  if (a.stiffness) run.computed.push_back("loaded stiffness K_F along the branches (eq 29)");
  if (a.jump.enabled) run.computed.push_back("jumps from the folds (gradient-flow dynamics, landing polished)");
  if (a.loadHistory.enabled)
    run.computed.push_back("quasi-static load history with jumps (hysteresis), " +
                           std::to_string(a.loadHistory.waypoints.size()) + " waypoints");
  if (a.suddenLoad.enabled)
    run.computed.push_back(std::string("sudden load: ") +
                           (a.suddenLoad.massPerLength > 0 ? "inertial dynamics (uniform rods)" : "gradient flow") +
                           ", compared with the quasi-static load history");
  if (a.criticalForces.enabled) run.computed.push_back("critical forces of the start configuration (linear buckling)");
  if (a.energyCurves.enabled) run.computed.push_back("energy curves E(q1) with the end held (eq 6-8)");
  if (a.torqueAngle.enabled) run.computed.push_back("torque-angle curves M(q) of the first segment (eq 1)");

  std::vector<std::pair<std::string, std::function<void(CaseRunner&)>>> stages;
  if (a.torqueAngle.enabled) stages.emplace_back("torque_angle", [](CaseRunner& r) { r.torqueAngle(); });
  if (a.criticalForces.enabled) stages.emplace_back("critical_forces", [](CaseRunner& r) { r.criticalForces(); });
  if (a.energyCurves.enabled) stages.emplace_back("energy_curves", [](CaseRunner& r) { r.energyCurves(); });
  if (a.continuation.enabled) stages.emplace_back("continuation", [](CaseRunner& r) { r.continuation(); });
  if (a.loadHistory.enabled) stages.emplace_back("load_history", [](CaseRunner& r) { r.loadHistory(); });
  if (a.suddenLoad.enabled) stages.emplace_back("sudden_load", [](CaseRunner& r) { r.suddenLoad(); });
  std::vector<double> stageSeconds(stages.size(), 0.0);

  std::vector<std::string> skipped;
  run.cases.reserve(scene.cases.size());
  for (const CaseSpec& spec : scene.cases) {
    mech::Chain chain(spec.chain.segments);
    CaseResult& out = run.cases.emplace_back(chain);
    out.label = spec.label;
    out.q0 = spec.chain.q0;
    out.pose0 = mech::endPose(chain, out.q0);
    out.startValue = spec.end.condition.value[spec.path.coordinate];
    CaseRunner runner(scene, spec, out, run, control);
    for (size_t s = 0; s < stages.size(); ++s) {
      if (runner.interrupted()) {
        skipped.push_back(stages[s].first + (scene.cases.size() > 1 ? " (case \"" + spec.label + "\")" : ""));
        continue;
      }
      if (control.progress)
        control.progress->stage(stages[s].first, spec.label, int(&spec - scene.cases.data()), int(scene.cases.size()));
      const Clock::time_point t0 = Clock::now();
      stages[s].second(runner);
      stageSeconds[s] += secondsSince(t0);
    }
  }
  if (!skipped.empty()) {
    std::string list;
    for (const std::string& k : skipped) list += (list.empty() ? "" : ", ") + k;
    run.problems.push_back("not run after the stop: " + list);
  }
  for (size_t s = 0; s < stages.size(); ++s) run.timings.emplace_back(stages[s].first, stageSeconds[s]);
  run.totalSeconds = secondsSince(start);
  return run;
}

}  // namespace buckle::scene
