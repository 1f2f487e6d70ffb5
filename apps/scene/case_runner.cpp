#include "scene/case_runner.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/critical_loading.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/jump.h"
#include "buckle/mechanics/landing.h"
#include "buckle/mechanics/load_history.h"
#include "buckle/mechanics/mirror_symmetry.h"
#include "buckle/mechanics/unloaded_shape.h"

namespace buckle::scene {

namespace cont = buckle::continuation;
namespace mech = buckle::mechanics;

namespace {

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
  s.jumpContacts = l.contacts;
}

SpecialRecord toRecord(const mech::SpecialPointReport& sp, int branch) {
  SpecialRecord s;
  s.type = mech::label(sp.type);
  s.field = mech::toString(sp.phenomenon);
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
  s.multiplicity = sp.multiplicity;
  s.branchesPredicted = sp.branchesPredicted;
  s.branchesFound = sp.branchesFound;
  s.note = sp.note;
  s.joint = sp.joint;
  s.contactTorque = sp.contactTorque;
  s.lockedAfter = sp.lockedAfter.label();
  if (sp.vertex.segment >= 0) {
    s.vertex = sp.vertex.label();
    s.contactForce = sp.contactForce;
    s.wallAfter = sp.lockedAfter.wallLabel();
  }
  s.contactPoint = sp.contactPoint;
  s.koiter = sp.koiter;
  s.imperfections = sp.imperfections;
  copyLanding(sp.landing, s);
  return s;
}

}  // namespace

std::string solverFailureInWords(const std::string& solverMessage) {
  if (solverMessage.find("KIN_") == std::string::npos) return solverMessage;
  const auto has = [&solverMessage](const char* flag) { return solverMessage.find(flag) != std::string::npos; };
  std::string what, change;
  if (has("SYSFUNC")) {
    what = "the spring model could not be evaluated at the solver's trial shapes (a spring length reaching zero "
           "at a joint limit, or values outside the double range)";
    change = "check the joint limits, the held coordinates and the loads, or lower solver.max_step";
  } else if (has("LSETUP") || has("LSOLVE") || has("LINSOLV")) {
    what = "the linearised equilibrium equations (eq 8 with the held end coordinates) are singular there";
    change = "the chain may be at a fold or branch point of its constraints; lower solver.initial_step or "
             "solver.max_step, or move /path/from";
  } else {
    what = "Newton's method made no progress on the equilibrium equations (the joint torques dE/dq balancing "
           "J^T F, eq 8, with the held end coordinates)";
    change = "lower solver.max_step (or initial_step), or keep the held coordinates and loads nearer the "
             "unloaded shape";
  }
  return what + "; " + change + " (solver detail: " + solverMessage + ")";
}

void CaseRunner::record(const cont::Branch& b, const mech::BranchReport& report, mech::EquilibriumProblem& problem,
                        const std::string& origin) {
  BranchRecord br;
  br.id = b.id;
  br.parent = b.parentId;
  br.origin = origin;
  br.stopReason = report.stopReason;
  br.stopMessage = report.stopMessage;
  br.points = static_cast<int>(report.points.size());  // those reported (in the path's range)
  br.finished = report.finished;
  // a switched branch that used up its requested "child_points" ended where it was asked to
  const bool childBudget = b.parentId >= 0 && scene_.analyses.continuation.childPoints > 0 &&
                           b.stopReason == cont::StopReason::MaxPoints;
  if (childBudget) br.finished = true;
  if (b.stopReason == cont::StopReason::Interrupted) {
    interrupted();  // reported once for the run, not per branch
  } else if (!br.finished) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\", branch " + std::to_string(b.id) + " (" + origin +
                            ") stopped early: " + br.stopReason +
                            (b.stopMessage.empty() ? "" : " — " + solverFailureInWords(b.stopMessage)));
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
    r.C = p.C;
    r.Kphi = p.rotationalStiffness;
    r.locked = p.locked.label();
    r.contactTorque = p.contactTorque;
    r.wall = p.locked.wallLabel();
    r.wallForce = p.wallForces.sum();
    if (scene_.analyses.frequencies.enabled) r.omega = naturalFrequencies(p.q, p.F, p.locked, p.parameter);
    out_.points.push_back(std::move(r));
  }
  run_.worstResidual = std::max(run_.worstResidual, report.worstResidual);

  for (const mech::SpecialPointReport& sp : report.specialPoints) {
    SpecialRecord s = toRecord(sp, b.id);
    // at the located point itself (plots mark it there), the joints locked as at the traced point before it
    if (scene_.analyses.frequencies.enabled && sp.q.size() == out_.chain.size() && !report.points.empty()) {
      const mech::PointReport* before = &report.points.front();
      for (const mech::PointReport& p : report.points)
        if (p.index <= sp.index) before = &p;
      s.omega = naturalFrequencies(sp.q, sp.F, before->locked, sp.parameter);
    }
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
        // The fold of a mirror image branch jumps as the mirror image of its source's fold.
        const auto source = landings_.find({b.mirrorOf, sp.source});
        const mech::Landing landing = b.mirrorOf >= 0 && source != landings_.end()
                                          ? mech::mirrored(source->second)
                                          : mech::jumpFromFold(problem, fold, opt);
        landings_[{b.id, sp.source}] = landing;
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
    h = mech::followLoadHistory(problem, out_.qStart, scene_.analyses.loadHistory.waypoints, opt);
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
  // the chain at rest before the load changes: the path's start shape, with weight or point loads
  // the equilibrium under them at the start value (the quasi-static history's polished first point)
  Eigen::VectorXd qRest = out_.qStart;
  if (spec.value != s0) {
    mech::LoadHistoryOptions opt;
    opt.tracer = solverOptions();
    opt.jump.integration = integrationOptions(mech::jumpIntegrationDefaults(out_.chain.size()));
    try {
      const mech::LoadHistoryResult h = mech::followLoadHistory(problem, out_.qStart, {s0, spec.value}, opt);
      if (h.completed && !h.segments.empty()) qStatic = h.segments.back().points.back().u.head(n);
      if (problem.bodyLoads().active() && !h.segments.empty() && !h.segments.front().points.empty())
        qRest = h.segments.front().points.front().u.head(n);
    } catch (const std::exception&) {
      // no quasi-static answer: the comparison is skipped and said so below
    }
  } else {
    qStatic = out_.qStart;
  }
  mech::EndCondition loaded = problem.endCondition();
  loaded.value += spec.value * problem.direction();
  mech::SuddenLoadOptions opt;
  opt.integration = integrationOptions();
  if (spec.massPerLength > 0) {
    opt.scene.inertia = mech::InertiaData::uniformRods(out_.chain, spec.massPerLength);
    if (spec.damping > 0) opt.scene.jointDamping.assign(size_t(n), spec.damping);
  }
  // with weight or point loads: from rest under them at the start value, the path's loads (on a
  // gravity path the weight itself) at `value` at once
  if (problem.bodyLoads().active())
    opt.scene.body = std::make_shared<const mech::BodyLoads>(problem.bodyLoads().atParameter(spec.value));
  try {
    const mech::SuddenLoadResult r = mech::simulateSuddenLoad(out_.chain, loaded, qRest, qStatic, opt);
    rec.success = r.success;
    rec.message = r.message;
    rec.inertial = r.inertial;
    rec.rest = r.rest;
    for (size_t i = 0; i < r.contactSides.size(); ++i)
      if (r.contactSides[i] != 0) rec.contacts.push_back({int(i), r.contactSides[i], r.contactTorques[Eigen::Index(i)]});
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

mech::EquilibriumBranchOptions CaseRunner::branchOptions(double lambdaLo, double lambdaHi) {
  mech::EquilibriumBranchOptions opt;
  opt.tracer = solverOptions();
  opt.tracer.lambdaMin = lambdaLo;
  opt.tracer.lambdaMax = lambdaHi;
  opt.tracer.computeStability = true;
  // Only the smallest eigenvalue is reported (min_eig); the locator asks for the crossing
  // eigenvalue where it needs more.
  opt.tracer.lowestEigenvalues = 1;
  opt.switchingDepth = scene_.analyses.continuation.depth(throughLoad());
  opt.contact = scene_.analyses.continuation.contact;
  opt.mirror = scene_.analyses.continuation.mirror;
  opt.report = reportOptions();
  if (const int first = scene_.analyses.continuation.branchPoints; first > 0) {
    // the first `first` simple branch points along the branch, not counting the one it starts from
    opt.switchAt = [first](const cont::Branch& branch, const cont::SpecialPoint& bp) {
      const double s0 = branch.points.empty() ? 0.0 : branch.points.front().arclength;
      int before = 0;
      for (const cont::SpecialPoint& sp : branch.specialPoints)
        if (sp.type == cont::SpecialPointType::BranchPoint && sp.multiplicity == 1 && sp.arclength > s0 &&
            sp.arclength < bp.arclength)
          ++before;
      return before < first;
    };
  }
  if (const int points = scene_.analyses.continuation.childPoints; points > 0) {
    opt.childTracer = opt.tracer;
    opt.childTracer->maxPoints = points;
  }
  opt.onBranch = [this, depth = opt.switchingDepth](const cont::BranchTree& t, const cont::Branch& b) {
    branchesSoFar_ = static_cast<int>(t.branches.size());
    branchAdded(b, depth);
  };
  return opt;
}

void CaseRunner::continuation() {
  if (spec_.path.task) {
    taskPath();
    return;
  }
  double s0 = out_.startValue;
  mech::EndCondition end = spec_.end.condition;
  Eigen::Vector3d direction = spec_.path.direction;
  double lambdaLo = std::min(spec_.path.from, spec_.path.to), lambdaHi = std::max(spec_.path.from, spec_.path.to);
  std::vector<double> targets{spec_.path.to, spec_.path.from};
  const int c = spec_.path.coordinate;
  mech::EquilibriumOptions equilibriumOptions;
  // with contact and the wall, the base wall is a unilateral constraint like the joint stops (contact.h)
  equilibriumOptions.wallAsBoundary = scene_.analyses.continuation.contact && scene_.analyses.continuation.wall;
  if (throughLoad()) {
    // trace with the held coordinate's reaction as parameter (PathSpec::throughReaction), each
    // branch ending where the coordinate leaves the path's range
    const double limit = reactionLoadLimit();
    if (!(limit > 0.0)) return;  // said in run_.problems
    end.control[size_t(c)] = mech::Control::Load;
    end.value[c] = 0.0;
    direction = Eigen::Vector3d::Zero();
    direction[c] = 1.0;
    s0 = 0.0;
    // both signs of the reaction: with an unstable start (κ < 0) the branch points lie on the
    // tension side, and their branches still move the end into the requested range
    targets = {-limit, limit};
    lambdaLo = -limit;
    lambdaHi = limit;
    equilibriumOptions.heldRange = {c, std::min(spec_.path.from, spec_.path.to), std::max(spec_.path.from, spec_.path.to)};
  }
  end.value -= s0 * direction;  // prescribed(λ) = start values + (λ − s0)·direction
  mech::EquilibriumProblem problem(out_.chain, end, direction, equilibriumOptions, controlDirection(), bodyLoads());

  mech::EquilibriumBranchOptions opt = branchOptions(lambdaLo, lambdaHi);
  if (opt.switchingDepth > 0 && !spec_.path.control && !spec_.path.gravity) {
    std::vector<double> ends;
    for (double target : targets) ends.push_back(target - s0);
    warnOfLargeTree(mech::criticalLoading(end, c, direction), ends, opt.switchingDepth);
  }

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
                      (throughLoad() ? std::string(kEndLoadNames[size_t(c)]) + " (through the reaction)"
                                     : spec_.path.parameter));
  }
  // Each branch is recorded as soon as it is final (EquilibriumBranchOptions::onReport), so its
  // traced points are released while the tree goes on; the records are put in branch order after.
  const size_t firstBranch = out_.branches.size(), firstPoint = out_.points.size(),
               firstSpecial = out_.specials.size();
  // the curves a disconnected branch may join (disconnectedBranches), kept before their points go
  const bool keepCurves = scene_.analyses.equilibria.branches && !throughLoad();
  opt.onReport = [&](const cont::Branch& b, mech::BranchReport&& report) {
    branchSettled(b.id);
    if (keepCurves) {
      if (traced_.size() <= size_t(b.id)) traced_.resize(size_t(b.id) + 1);
      traced_[size_t(b.id)] = b;
    }
    if (b.stopReason == cont::StopReason::StartFailed) return;  // said below, in words
    const std::string origin = b.parentId < 0 ? origins[size_t(b.id)]
                                              : "BP " + std::to_string(b.parentSpecialPoint) + " of branch " +
                                                    std::to_string(b.parentId) +
                                                    (b.direction > 0 ? ", + side" : ", - side");
    record(b, report, problem, origin);
  };
  const mech::EquilibriumBranches result = mech::traceEquilibria(problem, out_.qStart, s0, starts, opt);
  const auto& branches = result.tree.branches;
  if (!branches.empty() && branches.front().stopReason == cont::StopReason::StartFailed) {
    traced_.clear();  // no tree: every equilibrium seeds (disconnectedBranches)
    run_.complete = false;
    std::ostringstream os;
    os << "case \"" << spec_.label << "\": no equilibrium found at the start " << spec_.path.parameter << " = " << s0
       << " from the unloaded shape: " << solverFailureInWords(branches.front().stopMessage);
    run_.problems.push_back(os.str());
    return;
  }
  const auto byBranch = [](const auto& a, const auto& b) { return a.branch < b.branch; };
  std::stable_sort(out_.branches.begin() + long(firstBranch), out_.branches.end(),
                   [](const BranchRecord& a, const BranchRecord& b) { return a.id < b.id; });
  std::stable_sort(out_.points.begin() + long(firstPoint), out_.points.end(), byBranch);
  std::stable_sort(out_.specials.begin() + long(firstSpecial), out_.specials.end(), byBranch);
  if (keepCurves) traced_.resize(branches.size());
  if (result.tree.interrupted) interrupted();
  if (throughLoad() && !result.tree.interrupted) checkHeldCoordinateMoved(firstPoint);
}

void CaseRunner::criticalForces() {
  const mech::CriticalLoading loading =
      mech::criticalLoading(spec_.end.condition, spec_.path.coordinate, spec_.path.direction);
  mech::LinearBucklingOptions opt;
  opt.count = scene_.analyses.criticalForces.modes;
  opt.direction = loading.direction;
  try {
    out_.critical = mech::linearBuckling(out_.chain, out_.q0, loading.end, opt);
    out_.haveCritical = true;
  } catch (const std::invalid_argument& e) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": critical forces: " + e.what());
    return;
  }
  if (mech::clampedPinned3Applies(out_.chain, out_.q0, loading)) {
    const mech::SegmentParameters& s = out_.chain.segment(0).parameters();
    out_.analytic = mech::analyticClampedPinned3(s.a1, s.b1, s.k1, s.L1_0);
    out_.haveAnalytic = true;
  }
}

void CaseRunner::energyCurves() {
  const EnergyCurvesSpec& e = scene_.analyses.energyCurves;
  mech::LandscapeOptions opt;
  opt.samples = e.points;
  opt.q1Min = std::max(e.q1From, out_.chain.lowerLimits()[0]);
  opt.q1Max = std::min(e.q1To, out_.chain.upperLimits()[0]);
  opt.body = bodyLoads().atParameter(out_.startValue);  // E + V with the weight and point loads (eq B1)
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

}  // namespace buckle::scene
