#include "scene/runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/jump.h"
#include "buckle/mechanics/landing.h"
#include "buckle/mechanics/load_history.h"
#include "buckle/mechanics/unloaded_shape.h"

namespace buckle::scene {

namespace cont = buckle::continuation;
namespace mech = buckle::mechanics;

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
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
  void record(const cont::Branch& b, const mech::BranchReport& report, mech::EquilibriumProblem& problem,
              const std::string& origin);
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
  /// How the mechanics layer reports this case's branches (branch_report.h).
  mech::ReportOptions reportOptions() const {
    mech::ReportOptions o;
    o.stiffness = scene_.analyses.stiffness;
    if (throughLoad()) {
      o.heldCoordinate = spec_.path.coordinate;
      o.rangeLow = std::min(spec_.path.from, spec_.path.to);
      o.rangeHigh = std::max(spec_.path.from, spec_.path.to);
    }
    return o;
  }

  const Scene& scene_;
  const CaseSpec& spec_;
  CaseResult& out_;
  RunResult& run_;
  const RunControl& control_;
  int branchesSoFar_ = 0;  // for progress reports
};

void copyLanding(const mech::Landing& l, SpecialRecord& s) {
  s.jumpTried = l.tried;
  s.jumpSuccess = l.success;
  s.jumpLanding = l.kind;
  s.jumpMessage = l.message;
  s.jumpQ = l.q;
  s.jumpF = l.F;
  s.jumpPose = l.pose;
  s.jumpShape = l.shape;
  s.energyReleased = l.energyReleased;
  s.jumpDistance = l.distance;
}

SpecialRecord toRecord(const mech::SpecialPointReport& sp, int branch) {
  SpecialRecord s;
  s.type = mech::eventLabel(sp.type);
  s.field = mech::phenomenonName(sp.phenomenon);
  s.branch = branch;
  s.parameter = sp.parameter;
  s.F = sp.F;
  s.pose = sp.pose;
  s.q = sp.q;
  s.shape = sp.shape;
  s.stabilityBefore = sp.stabilityBefore;
  s.stabilityAfter = sp.stabilityAfter;
  s.accuracy = sp.accuracy;
  s.residual = sp.residual;
  s.K = sp.K;
  s.refined = sp.refined;
  s.note = sp.note;
  copyLanding(sp.landing, s);
  return s;
}

void CaseRunner::record(const cont::Branch& b, const mech::BranchReport& report, mech::EquilibriumProblem& problem,
                        const std::string& origin) {
  BranchRecord br;
  br.id = b.id;
  br.parent = b.parentId;
  br.origin = origin;
  br.stopReason = report.stopReason;
  br.stopMessage = report.stopMessage;
  br.points = static_cast<int>(b.points.size());
  br.finished = report.finished;
  if (b.stopReason == cont::StopReason::Interrupted) {
    interrupted();  // reported once for the run, not per branch
  } else if (!br.finished) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\", branch " + std::to_string(b.id) + " (" + origin +
                            ") stopped early: " + br.stopReason + (b.stopMessage.empty() ? "" : " — " + b.stopMessage));
  }
  out_.branches.push_back(br);

  for (const mech::PointReport& p : report.points) {
    PointRecord r;
    r.branch = b.id;
    r.index = p.index;
    r.parameter = p.parameter;
    r.q = p.q;
    r.F = p.F;
    r.pose = p.pose;
    r.negative = p.negative;
    r.stable = p.stable;
    r.minEigenvalue = p.minEigenvalue;
    r.haveStiffness = p.haveStiffness;
    r.K = p.K;
    out_.points.push_back(r);
  }
  run_.worstResidual = std::max(run_.worstResidual, report.worstResidual);

  for (const mech::SpecialPointReport& sp : report.specialPoints) {
    SpecialRecord s = toRecord(sp, b.id);
    if (sp.source >= 0) run_.worstLocation = std::max(run_.worstLocation, sp.accuracy);
    if (scene_.analyses.jump.enabled && sp.jumps && sp.source >= 0 && !throughLoad()) {
      const cont::SpecialPoint& fold = b.specialPoints[size_t(sp.source)];
      if (interrupted()) {
        s.jumpMessage = "not simulated: " + run_.interruption;
      } else {
        if (control_.progress) control_.progress->note("jump from the fold at " + std::to_string(fold.lambda));
        mech::JumpOptions opt;
        opt.perturbation = scene_.analyses.jump.perturbation;
        opt.integration = integrationOptions(mech::jumpIntegrationDefaults(out_.chain.size()));
        opt.integration.recordTrajectory = false;
        const mech::Landing landing = mech::jumpFromFold(problem, fold, opt);
        copyLanding(landing, s);
        if (landing.interrupted) {
          interrupted();
        } else if (!landing.success) {
          run_.complete = false;
          run_.problems.push_back("case \"" + spec_.label + "\": jump from the fold at " + spec_.path.parameter +
                                  " = " + std::to_string(fold.lambda) +
                                  " did not land on a stable equilibrium: " + landing.message);
        }
      }
    }
    out_.specials.push_back(s);
  }
}

// The load history of the scene: stable quasi-static pieces joined by jumps. Each piece is a
// branch of the output; each jump a special point "JUMP" (field "jumping") with its landing,
// drawn as an arrow in the bifurcation plots.
void CaseRunner::loadHistory() {
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
    record(b, mech::reportBranch(problem, b, reportOptions()), problem, origin.str());
  }
  for (const mech::JumpRecord& j : h.jumps)
    out_.specials.push_back(
        toRecord(mech::reportJump(problem, j, spec_.path.parameter), j.fromSegment >= 0 ? base + j.fromSegment : base));
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

  mech::EquilibriumBranchOptions opt;
  opt.tracer = solverOptions();
  opt.tracer.lambdaMin = lambdaLo;
  opt.tracer.lambdaMax = lambdaHi;
  opt.tracer.computeStability = true;
  opt.switchingDepth = scene_.analyses.continuation.branchSwitching;
  opt.report = reportOptions();
  opt.onBranch = [this](const cont::BranchTree& t, const cont::Branch&) {
    branchesSoFar_ = static_cast<int>(t.branches.size());
  };

  // The start branches (one per requested direction), then branch switching breadth first, by
  // the core's tree driver (its guards: never back at the BP a branch started from, never twice
  // at the same point). The start point is the unloaded shape at the start value, polished by the
  // tracer's fixed-parameter corrector.
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
  const mech::EquilibriumBranches result = mech::traceEquilibria(problem, out_.q0, s0, starts, opt);
  const auto& branches = result.tree.branches;
  if (!branches.empty() && branches.front().stopReason == cont::StopReason::StartFailed) {
    run_.complete = false;
    std::ostringstream os;
    os << "case \"" << spec_.label << "\": no equilibrium found at the start " << spec_.path.parameter << " = " << s0
       << " from the unloaded shape (" << branches.front().stopMessage << ")";
    run_.problems.push_back(os.str());
    return;
  }
  for (size_t i = 0; i < branches.size(); ++i) {
    const cont::Branch& b = branches[i];
    std::string origin = b.parentId < 0 ? origins[size_t(b.id)]
                                        : "BP " + std::to_string(b.parentSpecialPoint) + " of branch " +
                                              std::to_string(b.parentId) + (b.direction > 0 ? ", + side" : ", - side");
    record(b, result.reports[i], problem, origin);
  }
  if (result.tree.interrupted) interrupted();
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
  out_.torque = mech::torqueCurve(out_.chain.segment(0), t.qFrom, t.qTo, t.points);
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
