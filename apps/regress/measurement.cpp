#include "regress/measurement.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "buckle/mechanics/shape_name.h"
#include "problems/auto_cases.h"
#include "scene/runner.h"
#include "scene/scene.h"

namespace buckle::regress {

namespace cont = buckle::continuation;

double Measurement::medianSeconds() const {
  if (seconds.empty()) return 0.0;
  std::vector<double> s = seconds;
  std::sort(s.begin(), s.end());
  return s[s.size() / 2];
}

const std::vector<std::string>& problemNames() { return problems::caseNames(); }

namespace {

MeasuredCase fromScene(const scene::CaseResult& c) {
  MeasuredCase m;
  m.label = c.label;
  for (const scene::SpecialPointResult& s : c.specials)
    m.specials.push_back({s.branch, mechanics::label(s.type), s.parameter, s.shape, s.accuracy,
                          s.koiter.valid ? mechanics::postBucklingName(s.koiter) : std::string()});
  // the located results of the analyses without branches, on pseudo-branch -1
  if (c.haveCritical)
    for (const mechanics::BucklingMode& mode : c.critical.modes) m.specials.push_back({-1, "CRIT", mode.lambda, mode.shape, 0.0, {}});
  if (c.haveLandscape)
    for (const mechanics::LandscapeEquilibrium& e : c.landscape.equilibria)
      m.specials.push_back({-1, "EQ", e.q1, e.shape + (e.stable ? " stable" : " unstable"), 0.0, {}});
  // codimension-two points of the two-parameter curves (value: μ, shape: the point's label)
  for (const mechanics::CriticalCurve& curve : c.criticalCurves)
    for (const mechanics::Codim2Point& p : curve.special)
      if (p.converged) m.specials.push_back({-1, p.label, p.mu, p.label, p.accuracy, {}});
  for (const scene::EquilibriumSet& set : c.equilibriumSets) {
    // every equilibrium at one state (ascending Π): Π, shape, stability and index
    for (const mechanics::FoundEquilibrium& e : set.found.equilibria)
      m.specials.push_back({-1, "ALLEQ", e.potential,
                            e.shape + (e.stable ? " stable" : " unstable") + ", index " + std::to_string(e.index), 0.0, {}});
    // equilibria "branches": the branch through each equilibrium (value: its id, -1 none), so a
    // disconnected branch traced from another seed, or none, is a drift
    for (size_t i = 0; i < set.onBranch.size(); ++i)
      m.specials.push_back({-1, "EQBRANCH", double(set.onBranch[i]), "equilibrium " + std::to_string(i + 1), 0.0, {}});
  }
  if (c.haveWorkspace) {
    // the workspace map: its stable grid values and its bounding curves by cause (counts)
    int stable = 0;
    for (const mechanics::WorkspaceCell& cell : c.workspace.cells) stable += cell.stable();
    m.specials.push_back({-1, "WSSTABLE", double(stable), "stable grid values", 0.0, {}});
    std::map<std::string, int> curves;
    for (const mechanics::WorkspaceCurve& curve : c.workspace.curves) ++curves[mechanics::boundaryCauseName(curve.cause)];
    for (const auto& [cause, count] : curves) m.specials.push_back({-1, "WSCURVES", double(count), cause, 0.0, {}});
  }
  if (c.haveTorque)
    for (const auto& [q, stable] : c.torque.equilibria) m.specials.push_back({-1, "TEQ", q, stable ? "stable" : "unstable", 0.0, {}});
  if (c.haveSudden && c.sudden.success) {
    const std::string shape = mechanics::shapeName(c.sudden.rest, 1e-6) + (c.sudden.stable ? " stable" : " unstable");
    for (Eigen::Index i = 0; i < c.sudden.rest.size(); ++i) m.specials.push_back({-1, "REST", c.sudden.rest[i], shape, 0.0, {}});
  }
  // the natural frequencies (`frequencies`) at the case's start point, on pseudo-branch -1
  if (!c.points.empty())
    for (Eigen::Index i = 0; i < c.points.front().omega.size(); ++i)
      if (std::isfinite(c.points.front().omega[i]))
        m.specials.push_back({-1, "OMEGA", c.points.front().omega[i], "mode " + std::to_string(i + 1), 0.0, {}});
  for (const mechanics::PointReport& p : c.points) {
    if (m.branches.empty() || m.branches.back().id != p.branch) m.branches.push_back({p.branch, {}, {}, {}});
    MeasuredBranch& b = m.branches.back();
    b.index.push_back(p.index);
    b.lambda.push_back(p.parameter);
    b.q.push_back(p.q);
  }
  return m;
}

Measurement measureScene(const std::string& file, int repetitions, double timeLimit) {
  scene::Scene sc;
  try {
    sc = scene::loadScene(file);
  } catch (const scene::SceneError& e) {
    throw SourceError{std::string("bad scene: ") + e.what()};
  }
  Measurement m;
  for (int r = 0; r < repetitions; ++r) {
    scene::RunControl control;
    if (timeLimit > 0.0) control.interrupt = continuation::Interrupt::after(timeLimit);
    const scene::RunResult run = scene::runScene(sc, control);
    m.seconds.push_back(run.totalSeconds);
    if (r > 0) continue;
    m.complete = run.complete;
    m.interrupted = run.interrupted;
    m.problems = run.problems;
    for (const scene::CaseResult& c : run.cases) m.cases.push_back(fromScene(c));
  }
  return m;
}

// The problem's last traced branch (the one its benchmark times), named like the scene runner
// names special points; the start point is not a result.
MeasuredCase fromProblem(const problems::CaseResult& r) {
  MeasuredCase m;
  m.label = r.name;
  const int n = r.segments;
  const cont::Branch& b = r.branch;
  for (const cont::SpecialPoint& sp : b.specialPoints) {
    if (sp.type == cont::SpecialPointType::Endpoint) continue;
    MeasuredSpecial s;
    s.type = cont::label(sp.type);
    s.branch = b.id;
    s.lambda = sp.lambda;
    s.accuracy = sp.lambdaAccuracy;
    // as the scene runner does: a branch point by the mode it bifurcates into
    s.shape = sp.type == cont::SpecialPointType::BranchPoint && sp.nullVectors.cols() >= 2
                  ? mechanics::modeShapeName(sp.nullVectors.col(1).head(n))
                  : mechanics::shapeName(sp.u.head(n), 1e-6);
    m.specials.push_back(s);
  }
  MeasuredBranch mb{b.id, {}, {}, {}};
  for (size_t i = 0; i < b.points.size(); ++i) {
    mb.index.push_back(int(i));
    mb.lambda.push_back(b.points[i].lambda);
    mb.q.push_back(b.points[i].u.head(n));
  }
  m.branches.push_back(std::move(mb));
  return m;
}

Measurement measureProblem(const std::string& name, int repetitions) {
  Measurement m;
  for (int r = 0; r < repetitions; ++r) {
    problems::CaseResult result;
    if (!problems::runCase(name, problems::Settings(), result)) throw SourceError{"unknown benchmark problem \"" + name + "\""};
    m.seconds.push_back(result.seconds);
    if (r > 0) continue;
    if (result.points <= 0) {
      m.complete = false;
      m.problems.push_back("problem " + name + ": no continuation point (" +
                           cont::toString(result.branch.stopReason) + ")");
    }
    m.cases.push_back(fromProblem(result));
  }
  return m;
}

}  // namespace

Measurement measure(const Source& source, const std::string& scenesDir, int repetitions, bool limited) {
  repetitions = std::max(1, repetitions);
  if (source.kind == Source::Kind::Problem) return measureProblem(source.name, repetitions);
  return measureScene((std::filesystem::path(scenesDir) / source.name).string(), repetitions,
                      limited ? source.timeLimit : 0.0);
}

}  // namespace buckle::regress
