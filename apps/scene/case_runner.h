// One case of a scene, stage by stage: what each analysis asks of the library, and its reports
// collected into the case's result (runner.h). Internal to the scene runner.
#pragma once

#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/landing.h"
#include "buckle/mechanics/critical_loading.h"
#include "buckle/mechanics/vibration.h"
#include "scene/runner.h"

namespace buckle::scene {

/// A message of the solver in words for the user: which equations could not be solved and what
/// to change, with the solver's own message (its KINSOL flag) kept as the detail at the end.
/// Messages without a KINSOL flag are returned as they are.
std::string solverFailureInWords(const std::string& solverMessage);

class CaseRunner {
 public:
  CaseRunner(const Scene& scene, const CaseSpec& spec, CaseResult& out, RunResult& run, const RunControl& control)
      : scene_(scene), spec_(spec), out_(out), run_(run), control_(control) {}

  /// Along a control path: the start shape qStart, the chain under /end's payload reached from the
  /// unloaded shape by a quasi-static load history (case_runner_control.cpp). False (recorded in
  /// the run's problems) when it cannot be reached.
  bool actuationStart();
  void continuation();
  /// A task path (case_runner_task.cpp): the continuation stage of a case whose /path has a task.
  void taskPath();
  void loadHistory();
  void suddenLoad();
  void criticalForces();
  /// two_parameter (two_parameter.cpp)
  void twoParameter();
  void energyCurves();
  void torqueAngle();
  /// equilibria (case_runner_equilibria.cpp)
  void equilibria();
  /// workspace (case_runner_workspace.cpp): the maps over two control inputs under the payload.
  void workspaceMap();
  /// `jump` (after the branches are traced): where the chain lands from every fold of them.
  void jumps();
  /// The branches through the equilibria that the continuation's tree does not reach
  /// (equilibria with "branches": true; case_runner_equilibria.cpp), after continuation().
  void disconnectedBranches();

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
  /// One set of the equilibria analysis at path-parameter value `at`, and the branches through it.
  void equilibriaAt(double at);
  void disconnectedBranchesAt(EquilibriumSet& set);
  void record(const continuation::Branch& b, mechanics::BranchReport report, const std::string& origin);
  /// One branch's points (in order) into the case: all of them, or streamed (RunControl::streamTo)
  /// their rows written and a sample kept (point_sample.h).
  void keepPoints(std::vector<mechanics::PointReport>&& points);

  /// `frequencies` (case_frequencies.cpp): the signed natural frequencies at joint angles q under
  /// the total end wrench F with the joints of `locked` locked, its wall vertices and self
  /// contacts held by the forces `wallForces`, `selfForces` (NaN when they are not known;
  /// `parameter`: for a message).
  Eigen::VectorXd naturalFrequencies(const Eigen::VectorXd& q, const mechanics::Wrench& F,
                                     const mechanics::ContactSet& locked, const Eigen::VectorXd& wallForces,
                                     const Eigen::VectorXd& selfForces, double parameter);
  bool throughLoad() const { return spec_.path.throughReaction; }
  /// Through the reaction (case_runner_reaction.cpp): the load limit, the scene's or derived from
  /// the critical reactions (into out_); 0, said in the run's problems, when none can be had.
  double reactionLoadLimit();
  /// Through the reaction: says in the run's problems why the end never moved, if it did not
  /// (points from out_.points[firstPoint] on).
  void checkHeldCoordinateMoved(size_t firstPoint);
  /// The continuation's tree options over the parameter range [lambdaLo, lambdaHi] (the tracer's
  /// stability, branch switching and contact settings of /analyses/continuation).
  mechanics::EquilibriumBranchOptions branchOptions(double lambdaLo, double lambdaHi);
  /// The scene's /solver settings as tracer options (the λ range is set by each analysis).
  continuation::TracerOptions solverOptions() const {
    continuation::TracerOptions opt = scene_.solver.tracer;
    opt.interrupt = control_.interrupt;
    if (control_.progress) {
      Progress* progress = control_.progress;
      const CaseResult* out = &out_;
      const int* branches = &branchesSoFar_;
      const int* queued = &ahead_.queued;
      opt.onStep = [progress, out, branches, queued](const continuation::StepInfo& step) {
        progress->step(*branches + 1, step.pointCount, step.point.lambda,
                       static_cast<int>(out->specials.size()) + step.specialPointCount, *queued);
        return continuation::StepAction::Continue;
      };
      // a step over a cluster of branch points can refine for seconds without a new point
      opt.onLocated = [progress, branches](const continuation::SpecialPoint& sp) {
        std::ostringstream what;
        what.precision(6);
        what << "branch " << *branches + 1 << ", located " << continuation::label(sp.type) << " at parameter "
             << sp.lambda;
        progress->note(what.str());
      };
    }
    return opt;
  }
  /// With contact and the wall, the base wall x = 0 is a unilateral constraint: the continuation
  /// holds the vertices that reach it, and the dynamics slide on it and land on it (JumpOptions::wall).
  bool tracesWall() const { return scene_.analyses.continuation.contact && scene_.analyses.continuation.wall; }
  /// With contact and `self`, the chain's contact with itself is a unilateral constraint of the
  /// continuation: a vertex that reaches another link's triangle is held on its edge (SH / SR).
  bool tracesSelf() const { return scene_.analyses.continuation.contact && scene_.analyses.continuation.self; }
  /// Integration settings of the dynamics with the run's interrupt.
  mechanics::IntegrationOptions integrationOptions(mechanics::IntegrationOptions opt = mechanics::IntegrationOptions()) const {
    opt.interrupt = control_.interrupt;
    return opt;
  }
  /// The scene's path of the end condition: prescribed(λ) = start values + (λ − s0)·direction.
  mechanics::LoadPath loadPath() const { return {spec_.end.condition, spec_.path.direction, out_.startValue}; }
  /// The path as an EquilibriumProblem; with `contact` the base wall and the chain's contact with
  /// itself are constraints as the scene traces them (tracesWall(), tracesSelf()).
  mechanics::EquilibriumProblem pathProblem(bool contact = false) const {
    mechanics::EquilibriumOptions options;
    options.wallAsBoundary = contact && tracesWall();
    options.selfContactAsBoundary = contact && tracesSelf();
    return mechanics::EquilibriumProblem(out_.chain, loadPath().problemEnd(), spec_.path.direction, options,
                                         controlDirection(), bodyLoads());
  }
  /// The case's weight and point loads along the path (case_body.cpp): g(λ) = λ·direction on a
  /// gravity path, else fixed; point loads force + (λ − s0)·rate; the payload's weight at the end.
  mechanics::BodyLoads bodyLoads() const;
  /// The links' masses of the case (uniform rods of `massPerLength`, the payload on the end link).
  mechanics::InertiaData caseInertia(double massPerLength) const;
  /// Along a control path the free lengths' direction (origin: the start value); else none.
  mechanics::ControlDirection controlDirection() const {
    return spec_.path.control ? spec_.path.controlDirection : mechanics::ControlDirection();
  }
  /// How the mechanics layer reports this case's branches (branch_report.h).
  mechanics::ReportOptions reportOptions() const {
    mechanics::ReportOptions o;
    o.stiffness = scene_.analyses.stiffness;
    o.stiffnessMeasure = scene_.analyses.stiffnessMeasure;
    o.interrupt = control_.interrupt;
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
  /// The tree's size ahead, for progress reports: per branch id its depth, the branch points on it
  /// the tree will switch at and those it has switched at (or settled: the branch is final), and
  /// the difference summed (branchPointsQueued_). Fed by the tree's onBranch and onReport.
  struct TreeAhead {
    std::vector<int> depth, found, settled;
    std::vector<char> paused;  // a root traced up to a branch point only: reported again when traced further
    int queued = 0;
  } ahead_;
  std::pair<int, int> tracedParent_{-1, -1};  // (parent, branch point) of the last branch added
  void branchAdded(const continuation::Branch& b, int maxDepth);
  void branchSettled(int id);
  /// Moves the computation's deadline earlier by the time writing the points recorded so far
  /// will take beyond the runner's fixed reserve (case_runner.cpp).
  void keepTimeForWriting(size_t points);
  double storedValues_ = 0.0;  // values of the points this case recorded so far
  /// The case's index in the scene (branches.csv's `case`).
  size_t caseIndex() const { return size_t(&spec_ - scene_.cases.data()); }
  /// Streamed (RunControl::streamTo): the memory of the sample of points kept, over the run's cases.
  static constexpr size_t kSampleBudget = size_t(64) << 20;
  size_t sampleBytes_ = 0;  // of this case's sample
  /// Warns at the start when the path's load, `ends` away from the start both ways, passes hundreds of
  /// critical loads of the unloaded shape that a tree of this depth would switch at
  /// (case_runner_ahead.cpp).
  void warnOfLargeTree(const mechanics::CriticalLoading& loading, const std::vector<double>& ends, int depth);
  /// A warning when the start shape already has two links' bodies overlapping (contact_geometry.h):
  /// self contact is detected, not enforced, so the chain starts as a ghost there.
  void warnOfOverlappingStart();
  std::vector<continuation::Branch> traced_;  // the continuation's tree (not through a reaction)
  /// `frequencies`: the case's chain with its rods (built at the first point)
  std::unique_ptr<mechanics::VibrationAnalysis> vibration_;
  /// `frequencies` with body loads: the path's problem, for their γ at each point
  std::unique_ptr<mechanics::EquilibriumProblem> bodyProblem_;
  bool vibrationFailed_ = false;  // a point's frequencies failed: reported once per case
};

}  // namespace buckle::scene
