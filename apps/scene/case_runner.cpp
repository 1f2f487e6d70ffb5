#include "scene/case_runner.h"
#include "buckle/continuation/available_cores.h"

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
#include "scene/branch_stream.h"
#include "scene/point_sample.h"

namespace buckle::scene {

namespace cont = buckle::continuation;
namespace mech = buckle::mechanics;

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

void CaseRunner::record(const cont::Branch& b, mech::BranchReport report, const std::string& origin) {
  BranchRecord br;
  br.id = b.id;
  br.parent = b.parentId;
  br.origin = origin;
  br.stopReason = report.stopReason;
  br.stopMessage = report.stopMessage;
  br.points = static_cast<int>(report.points.size());  // those reported (in the path's range)
  br.finished = report.finished;
  br.mirrorOf = b.mirrorOf;
  // a switched branch that used up its requested "child_points" ended where it was asked to
  const bool childBudget = b.parentId >= 0 && scene_.analyses.continuation.childPoints > 0 &&
                           b.stopReason == cont::StopReason::MaxPoints;
  if (childBudget) br.finished = true;
  br.skipped = report.skipped;
  if (b.stopReason == cont::StopReason::Interrupted || !report.skipped.empty()) {
    interrupted();  // reported once for the run, not per branch
  } else if (!br.finished) {
    run_.complete = false;
    // the point budget is the user's: say which key moves it
    const std::string advice =
        b.stopReason != cont::StopReason::MaxPoints ? ""
        : b.parentId >= 0 ? "; raise /solver/max_points to follow it further, or set "
                            "/analyses/continuation/child_points to end switched branches there as asked"
                          : "; raise /solver/max_points to follow it further";
    run_.problems.push_back("case \"" + spec_.label + "\", branch " + std::to_string(b.id) + " (" + origin +
                            ") stopped early: " + br.stopReason +
                            (b.stopMessage.empty() ? "" : " — " + solverFailureInWords(b.stopMessage)) + advice);
  }
  out_.branches.push_back(br);

  const bool frequencies = scene_.analyses.frequencies.enabled;
  for (const mech::SpecialPointReport& sp : report.specialPoints) {
    SpecialPointResult s{sp, {}};
    s.branch = b.id;
    // at the located point itself (plots mark it there), the contacts as at the traced point before it
    if (frequencies && sp.q.size() == out_.chain.size() && !report.points.empty() && !interrupted()) {
      const mech::PointReport* before = &report.points.front();
      for (const mech::PointReport& p : report.points)
        if (p.index <= sp.index) before = &p;
      s.omega = naturalFrequencies(sp.q, sp.F, before->locked, sp.wallForces, sp.selfForces, sp.parameter);
    }
    if (sp.source >= 0) run_.worstLocation = std::max(run_.worstLocation, sp.accuracy);
    out_.specials.push_back(std::move(s));
  }
  for (mech::PointReport& p : report.points) {
    p.branch = b.id;
    if (frequencies && !interrupted()) p.omega = naturalFrequencies(p.q, p.F, p.locked, p.wallForces, p.selfForces, p.parameter);
  }
  run_.worstResidual = std::max(run_.worstResidual, report.worstResidual);
  keepPoints(std::move(report.points));
}

void CaseRunner::keepPoints(std::vector<mech::PointReport>&& points) {
  out_.recordedPoints += points.size();
  keepTimeForWriting(points.size());
  if (run_.stream) {
    // the rows written now, a bounded sample kept for the plots and report.html
    run_.stream->add(caseIndex(), out_, points);
    const size_t budget = kSampleBudget / std::max<size_t>(1, scene_.cases.size());
    keepSample(out_.points, std::move(points), out_.pointStride, sampleBytes_, budget);
  } else {
    out_.points.insert(out_.points.end(), std::make_move_iterator(points.begin()), std::make_move_iterator(points.end()));
  }
}

// The `jump` analysis, a stage of its own once the branches are traced: from every fold whose
// stable side ends there, the chain released with the loads frozen (jumpFromFold) — the fold of
// a mirror image branch lands as the mirror image of its source's landing.
void CaseRunner::jumps() {
  if (throughLoad()) return;  // no jump under displacement control traced through the reaction
  mech::EquilibriumProblem problem = pathProblem();
  const std::vector<int> held = problem.endCondition().heldIndices();
  std::map<int, int> mirrorOf;  // branch id → the id of its mirror source
  for (const BranchRecord& b : out_.branches) mirrorOf[b.id] = b.mirrorOf;
  std::map<std::pair<int, int>, mech::Landing> landings;  // (branch, special point of its trace)
  for (SpecialPointResult& s : out_.specials) {
    if (!s.jumps || s.source < 0 || s.landing.tried || s.q.size() != out_.chain.size()) continue;
    if (interrupted()) {
      s.landing.message = "not simulated: " + run_.interruption;
      continue;
    }
    // the fold's unknowns u = (q, reactions of the held coordinates: the wrench's components there)
    cont::SpecialPoint fold;
    fold.lambda = s.lambda;
    fold.u.resize(problem.dimension());
    fold.u.head(s.q.size()) = s.q;
    for (size_t k = 0; k < held.size(); ++k) fold.u[s.q.size() + Eigen::Index(k)] = s.F[held[k]];
    if (control_.progress) control_.progress->note("jump from the fold at " + std::to_string(fold.lambda));
    const int source = mirrorOf.count(s.branch) ? mirrorOf[s.branch] : -1;
    const auto image = landings.find({source, s.source});
    if (source >= 0 && image != landings.end()) {
      s.landing = mech::mirrored(image->second);
    } else {
      mech::JumpOptions opt;
      opt.perturbation = scene_.analyses.jump.perturbation;
      opt.integration = integrationOptions(mech::jumpIntegrationDefaults(out_.chain.size()));
      opt.integration.recordTrajectory = false;
      opt.wall = tracesWall();
      opt.self = tracesSelf();
      s.landing = mech::jumpFromFold(problem, fold, opt);
    }
    landings[{s.branch, s.source}] = s.landing;
    if (s.landing.interrupted) {
      interrupted();
    } else if (s.landing.wallBlocked) {  // a known outcome: the chain cannot pass the base wall
      run_.warnings.push_back("case \"" + spec_.label + "\": jump from the fold at " + spec_.path.parameter + " = " +
                              std::to_string(fold.lambda) + " not landed: " + s.landing.message);
    } else if (!s.landing.success) {
      run_.complete = false;
      run_.problems.push_back("case \"" + spec_.label + "\": jump from the fold at " + spec_.path.parameter + " = " +
                              std::to_string(fold.lambda) + " did not land on a stable equilibrium: " + s.landing.message);
    }
  }
}

// The load history of the scene: stable quasi-static pieces joined by jumps. Each piece is a
// branch of the output; each jump a special point "JUMP" (field "jumping") with its landing,
// drawn as an arrow in the bifurcation plots.
void CaseRunner::loadHistory() {
  // its pieces are held at the base wall as the continuation's branches are
  mech::EquilibriumProblem problem = pathProblem(true);
  mech::LoadHistoryOptions opt;
  opt.tracer = solverOptions();
  opt.jump.perturbation = scene_.analyses.loadHistory.perturbation;
  opt.jump.integration = integrationOptions(mech::jumpIntegrationDefaults(out_.chain.size()));
  opt.jump.wall = tracesWall();
  opt.jump.self = tracesSelf();
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
    record(b, mech::reportBranch(problem, b, reportOptions(), h.segmentContacts[k]), origin.str());
  }
  for (const mech::JumpRecord& j : h.jumps) {
    SpecialPointResult& s = out_.specials.emplace_back();
    static_cast<mech::SpecialPointReport&>(s) = mech::reportJump(problem, j, spec_.path.parameter);
    s.branch = j.fromSegment >= 0 ? base + j.fromSegment : base;
    s.landing = mech::landingOf(problem, j);
  }
  if (!h.success && !interrupted()) {
    // a jump that cannot land because of the base wall ends the history, a known outcome
    const bool wall = !h.jumps.empty() && h.jumps.back().wallBlocked;
    if (!wall) run_.complete = false;
    (wall ? run_.warnings : run_.problems)
        .push_back("case \"" + spec_.label + "\": load history stopped: " + (wall ? "not landed: " : "") + h.message);
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
    opt.jump.wall = tracesWall();
    opt.jump.self = tracesSelf();
    try {
      mech::EquilibriumProblem held = pathProblem(true);  // held at the wall as the history is
      const mech::LoadHistoryResult h = mech::followLoadHistory(held, out_.qStart, {s0, spec.value}, opt);
      if (h.success && !h.segments.empty()) qStatic = h.segments.back().points.back().u.head(n);
      if (problem.bodyLoads().active() && !h.segments.empty() && !h.segments.front().points.empty())
        qRest = h.segments.front().points.front().u.head(n);
    } catch (const std::exception&) {
      // no quasi-static answer: the comparison is skipped and said so below
    }
  } else {
    qStatic = out_.qStart;
  }
  const mech::EndCondition loaded = loadPath().at(spec.value);
  mech::SuddenLoadOptions opt;
  opt.integration = integrationOptions(mech::jumpIntegrationDefaults(n));  // the stiff steppers of long chains
  opt.wall = tracesWall();
  opt.self = tracesSelf();
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
    for (size_t k = 0; k < r.wallContacts.size() && Eigen::Index(k) < r.wallForces.size(); ++k)
      rec.wall.push_back({r.wallContacts[k], r.wallForces[Eigen::Index(k)]});
    for (size_t k = 0; k < r.selfContacts.size() && Eigen::Index(k) < r.selfForces.size(); ++k)
      rec.self.push_back({r.selfContacts[k], r.selfForces[Eigen::Index(k)]});
    rec.events = r.dynamics.contactEvents;
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

void CaseRunner::keepTimeForWriting(size_t points) {
  // Writing a point costs in proportion to its values (its n joint angles, its columns of
  // branches.csv and its share of the special points, the plots and the report); the rows are
  // formatted as the branches finish (branch_stream.h), so what is left at the end is copying
  // them, the special points, plots and report. kSecondsPerValue is 2.5 times the largest cost of
  // those measured (benchmarks/RESULTS.md, the issue 27 rows): a loaded machine's. The
  // computation stops that much earlier than the fixed reserve (runner.cpp) allows, so that a
  // fast tree's many points are written within the limit too. At most half the limit.
  constexpr double kSecondsPerValue = 6e-8;
  constexpr int kValuesPerPoint = 200;  // a point's columns, special points and report share
  storedValues_ += double(points) * double(out_.chain.size() + kValuesPerPoint);
  const double limit = std::min(scene_.solver.timeLimit, 1e9);
  const double reserved = std::min(0.2 * limit, 1.0);  // runner.cpp's
  const double needed = std::min(storedValues_ * kSecondsPerValue, 0.5 * limit);
  if (needed > reserved) control_.interrupt.keepBeforeDeadline(needed - reserved);
}

mech::EquilibriumBranchOptions CaseRunner::branchOptions(double lambdaLo, double lambdaHi) {
  mech::EquilibriumBranchOptions opt;
  opt.tracer = solverOptions();
  opt.tracer.lambdaMin = lambdaLo;
  opt.tracer.lambdaMax = lambdaHi;
  opt.tracer.detection.stability = true;
  // Only the smallest eigenvalue is reported (min_eig); the locator asks for the crossing
  // eigenvalue where it needs more.
  opt.tracer.detection.lowestEigenvalues = 1;
  opt.tree.branchSwitching = scene_.analyses.continuation.depth(throughLoad());
  opt.contact = scene_.analyses.continuation.contact;
  opt.mirror = scene_.analyses.continuation.mirror;
  opt.tree.threads = scene_.analyses.continuation.threads;
  if (opt.tree.threads == 0) opt.tree.threads = control_.shared.threads;
  if (opt.tree.threads == 0) opt.tree.threads = cont::availableCores();
  opt.report = reportOptions();
  if (const int first = scene_.analyses.continuation.branchPoints; first > 0) {
    // the first `first` simple branch points along the branch, not counting the one it starts from
    opt.tree.switchAt = [first](const cont::Branch& branch, const cont::SpecialPoint& bp) {
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
    opt.tree.childTracer = opt.tracer;
    opt.tree.childTracer->maxPoints = points;
  }
  opt.tree.onBranch = [this, depth = opt.tree.branchSwitching](const cont::BranchTree& t, const cont::Branch& b) {
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
  mech::LoadPath path = loadPath();
  double lambdaLo = std::min(spec_.path.from, spec_.path.to), lambdaHi = std::max(spec_.path.from, spec_.path.to);
  std::vector<double> targets{spec_.path.to, spec_.path.from};
  const int c = spec_.path.coordinate;
  mech::EquilibriumOptions equilibriumOptions;
  // with contact and the wall, the base wall is a unilateral constraint like the joint stops (contact.h)
  equilibriumOptions.wallAsBoundary = tracesWall();
  equilibriumOptions.selfContactAsBoundary = tracesSelf();
  if (throughLoad()) {
    // trace with the held coordinate's reaction as parameter (PathSpec::throughReaction), each
    // branch ending where the coordinate leaves the path's range
    const double limit = reactionLoadLimit();
    if (!(limit > 0.0)) return;  // said in run_.problems
    path = path.throughReaction(c);
    // both signs of the reaction: with an unstable start (κ < 0) the branch points lie on the
    // tension side, and their branches still move the end into the requested range
    targets = {-limit, limit};
    lambdaLo = -limit;
    lambdaHi = limit;
    equilibriumOptions.heldRange = {c, std::min(spec_.path.from, spec_.path.to), std::max(spec_.path.from, spec_.path.to)};
  }
  const double s0 = path.startValue;
  const mech::EndCondition end = path.problemEnd();
  mech::EquilibriumProblem problem(out_.chain, end, path.direction, equilibriumOptions, controlDirection(), bodyLoads());

  mech::EquilibriumBranchOptions opt = branchOptions(lambdaLo, lambdaHi);
  if (opt.tree.branchSwitching > 0 && !spec_.path.control && !spec_.path.gravity) {
    std::vector<double> ends;
    for (double target : targets) ends.push_back(target - s0);
    warnOfLargeTree(mech::criticalLoading(end, c, path.direction), ends, opt.tree.branchSwitching);
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
               firstSpecial = out_.specials.size(), firstPiece = run_.stream ? run_.stream->pieces(caseIndex()) : 0;
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
    record(b, std::move(report), origin);
  };
  warnOfOverlappingStart();
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
  if (run_.stream) run_.stream->sortByBranch(caseIndex(), firstPiece);
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
