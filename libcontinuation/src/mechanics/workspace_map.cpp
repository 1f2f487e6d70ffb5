#include "buckle/mechanics/workspace_map.h"
#include "buckle/continuation/available_cores.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "buckle/continuation/corrector.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/stiffness.h"
#include "workspace_rows.h"

namespace buckle::mechanics {

namespace cont = buckle::continuation;

const char* boundaryCauseName(BoundaryCause cause) {
  switch (cause) {
    case BoundaryCause::InputBound: return "input bound";
    case BoundaryCause::Fold: return "fold";
    case BoundaryCause::Singular: return "singular";
    case BoundaryCause::JointLimit: return "joint limit";
  }
  return "";
}

std::string WorkspaceMapOptions::validate(const std::string& prefix) const {
  const auto axis = [&](const InputAxisRange& a, const std::string& name) -> std::string {
    if (!std::isfinite(a.from) || !std::isfinite(a.to) || a.from >= a.to)
      return prefix + name + ".from: expected finite from < to";
    if (a.count < 2 || a.count > 1000) return prefix + name + ".count: expected an integer in [2, 1000]";
    return "";
  };
  for (const std::string& why : {axis(first, "first"), axis(second, "second")})
    if (!why.empty()) return why;
  if (maxCurves < 0 || maxCurves > 1000) return prefix + "maxCurves: expected an integer in [0, 1000]";
  if (maxCurvePoints < 2) return prefix + "maxCurvePoints: expected an integer >= 2";
  if (threads < 0) return prefix + "threads: expected >= 0";
  if (share.parts < 1 || share.part < 0 || share.part >= share.parts)
    return prefix + "share.part: expected 0 <= part < parts";
  return tracer.validate(prefix + "tracer.");
}

namespace {

// A branch through a start and both ways along λ within [lo, hi]; the two halves in tracing order.
struct TwoWays {
  cont::Branch up, down;
};

cont::TracerOptions rowOptions(const cont::TracerOptions& base, double lo, double hi) {
  cont::TracerOptions o = base;
  o.lambdaMin = lo;
  o.lambdaMax = hi;
  o.detection.branchPoints = false;
  o.detection.folds = true;
  o.detection.boundaries = true;
  o.detection.stability = true;
  o.detection.lowestEigenvalues = 0;
  // the rows run on several threads: the caller's callbacks are for one
  o.onStep = nullptr;
  o.onLocated = nullptr;
  return o;
}

TwoWays traceBothWays(const EquilibriumProblem& p, ConstVectorRef q, double lambda, const cont::TracerOptions& o) {
  TwoWays t;
  cont::BoundProblem bound(p);
  t.up = cont::trace(bound, q, lambda, cont::InitialDirection::increasingLambda(), o);
  t.down = cont::trace(bound, q, lambda, cont::InitialDirection::decreasingLambda(), o);
  return t;
}

// The states of a traced pair of halves at the values `targets`, each taken where the branch
// first reaches it from the start; `folds` counts the folds passed on the way (−1: not reached).
void sampleAlong(const EquilibriumProblem& p, const TwoWays& t, const std::vector<double>& targets,
                 const cont::Interrupt& stop, std::vector<Vector>& states, std::vector<int>& folds) {
  const size_t m = targets.size();
  states.assign(m, Vector());
  folds.assign(m, -1);
  detail::ScaledCorrector corrector{cont::BoundProblem(p)};
  Vector u(p.dimension());
  for (const cont::Branch* b : {&t.up, &t.down}) {
    int passed = 0;
    for (size_t k = 0; k + 1 < b->points.size(); ++k) {
      const cont::ContinuationPoint &a = b->points[k], &c = b->points[k + 1];
      if (k > 0 && (a.foldTest > 0) != (b->points[k - 1].foldTest > 0)) ++passed;
      const double lo = std::min(a.lambda, c.lambda), hi = std::max(a.lambda, c.lambda);
      for (size_t i = 0; i < m; ++i) {
        if (folds[i] >= 0 || targets[i] < lo || targets[i] > hi || stop.requested()) continue;
        // across a fold both ends lie on the same side of it and the chord between them is no
        // guess: Newton from the end reached first keeps the first-reach rule
        const bool foldInside = (a.foldTest > 0) != (c.foldTest > 0);
        const double s = foldInside || c.lambda == a.lambda ? 0.0 : (targets[i] - a.lambda) / (c.lambda - a.lambda);
        const Vector guess = a.u + s * (c.u - a.u);
        if (!corrector.atFixedParameter(guess, targets[i], u)) continue;
        states[i] = u;
        folds[i] = passed;
      }
    }
  }
}

void evaluateCell(const EquilibriumProblem& p, cont::ProblemWorkspace& ws, WorkspaceCell& cell, double lambda) {
  const int n = p.segments();
  const auto q = cell.q.head(n);
  Vector F(p.dimension());
  p.residual(ws, cell.q, lambda, F);
  cell.residual = F.norm();
  cell.pose = endPose(p.chain(), q);
  cont::StabilityInfo info;
  if (p.stability(ws, cell.q, lambda, 1, info)) {
    cell.negative = info.negative;
    cell.smallestEigenvalue = info.lowest.size() > 0 ? info.lowest[0] : info.smallest;
  }
  cell.stiffness = std::numeric_limits<double>::quiet_NaN();
  StiffnessOptions so;
  so.bodyGenerator = p.bodyLoadGenerator(q, lambda);
  const CartesianStiffness s = loadedStiffness(p.chainAt(lambda), q, p.wrench(cell.q, lambda), p.endCondition(), so);
  if (s.positiveDefinite) cell.stiffness = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(s.stiffness).eigenvalues()[0];
}

std::string stopWords(const cont::Branch& b) {
  return b.stopMessage.empty() ? std::string("stopped") : b.stopMessage;
}

// A traced pair of halves as one curve, the down half reversed; u₁ is λ on a row (axis 0), u₂
// on a column (axis 1).
WorkspaceCurve edgeCurve(const InputPlane& plane, const EquilibriumProblem& p, const TwoWays& t, int axis,
                         double other, const std::string& name) {
  WorkspaceCurve c;
  c.cause = BoundaryCause::InputBound;
  c.name = name;
  const int n = plane.segments();
  const auto add = [&](const cont::ContinuationPoint& pt) {
    WorkspaceCurvePoint w;
    w.u1 = axis == 0 ? pt.lambda : other;
    w.u2 = axis == 0 ? other : pt.lambda;
    w.q = pt.u.head(n);
    w.pose = endPose(p.chain(), w.q);
    w.negative = pt.stability.valid() ? pt.stability.negative : -1;
    w.residual = pt.residualNorm;
    c.points.push_back(w);
  };
  for (size_t k = t.down.points.size(); k-- > 1;) add(t.down.points[k]);
  for (const cont::ContinuationPoint& pt : t.up.points) add(pt);
  c.stop = stopWords(t.down) + "; " + stopWords(t.up);
  return c;
}

// The curves a traced row starts: its located folds and joint stops (x = (q, u₂, u₁), u₂ kept).
void rowCurveStarts(const InputPlane& plane, const WorkspaceMapOptions& o, const EquilibriumProblem& p,
                    const TwoWays& t, double u2, std::vector<detail::CurveStart>& starts) {
  using Condition = InputPlaneCurveProblem::Condition;
  const int n = plane.segments();
  for (const cont::Branch* b : {&t.up, &t.down})
    for (const cont::SpecialPoint& sp : b->specialPoints) {
      detail::CurveStart s;
      if (sp.type == cont::SpecialPointType::Fold && o.folds) {
        s.condition = Condition::Fold;
        s.name = "fold";
      } else if (sp.type == cont::SpecialPointType::Boundary && o.limits && !sp.boundaryName.empty()) {
        for (int k = 0; k < p.boundaryCount(); ++k)
          if (p.boundaryName(k) == sp.boundaryName) s.boundary = k;
        if (s.boundary < 0) continue;
        s.condition = Condition::Limit;
        s.name = sp.boundaryName;
      } else {
        continue;
      }
      s.x.resize(n + 2);
      s.x << sp.u.head(n), u2, sp.lambda;
      s.fixed = n;
      starts.push_back(std::move(s));
    }
}

// Row j: along u₁ at u₂ = second.value(j) from the spine's state there (file comment of the
// header); its cells into the map, the rest into `row`.
void traceRow(const InputPlane& plane, const WorkspaceMapOptions& o, int j, const std::vector<Vector>& spine,
              const std::vector<int>& spineFolds, WorkspaceMap& map, detail::WorkspaceRow& row) {
  const int c1 = o.first.count;
  const double u2 = o.second.value(j);
  WorkspaceCell* cells = &map.cells[size_t(j) * size_t(c1)];
  std::vector<double> targets(static_cast<size_t>(c1));
  for (int i = 0; i < c1; ++i) {
    targets[size_t(i)] = o.first.value(i);
    cells[i] = WorkspaceCell();
    cells[i].u1 = targets[size_t(i)];
    cells[i].u2 = u2;
  }
  row = detail::WorkspaceRow();
  if (o.tracer.interrupt.requested()) {  // the rows done are kept; the others say why not
    for (int i = 0; i < c1; ++i) cells[i].note = "not computed: " + o.tracer.interrupt.describe();
    return;
  }
  if (spineFolds[size_t(j)] < 0) {
    for (int i = 0; i < c1; ++i) cells[i].note = "the spine along " + plane.input(1).name() + " did not reach it";
    row.done = true;
    return;
  }
  try {
    const auto p = plane.along(0, u2);
    const TwoWays t = traceBothWays(*p, spine[size_t(j)], plane.origin(0), rowOptions(o.tracer, o.first.from, o.first.to));
    std::vector<Vector> states;
    std::vector<int> folds;
    sampleAlong(*p, t, targets, o.tracer.interrupt, states, folds);
    auto ws = p->createWorkspace();
    for (int i = 0; i < c1; ++i) {
      if (o.tracer.interrupt.requested()) {
        cells[i].note = "not computed: " + o.tracer.interrupt.describe();
        continue;
      }
      if (folds[size_t(i)] < 0) {
        cells[i].note = "the row ended first: " + stopWords(targets[size_t(i)] >= plane.origin(0) ? t.up : t.down);
        continue;
      }
      cells[i].reached = true;
      cells[i].q = states[size_t(i)];
      cells[i].folds = folds[size_t(i)] + spineFolds[size_t(j)];
      evaluateCell(*p, *ws, cells[i], targets[size_t(i)]);
    }
    rowCurveStarts(plane, o, *p, t, u2, row.starts);
    if ((j == 0 || j == map.count2 - 1) && !t.up.points.empty()) {  // the box's edge u₂ = from or to
      row.hasEdge = true;
      row.edge = edgeCurve(plane, *p, t, 0, u2, map.input2 + (j == 0 ? " = from" : " = to"));
    }
  } catch (const std::exception& e) {
    row.problem = "row " + plane.input(1).name() + " = " + std::to_string(u2) + ": " + e.what();
  }
  row.done = !o.tracer.interrupt.requested();  // an interrupted row is traced again by whoever can
}

// The rows `which` on o.threads threads.
void traceRows(const InputPlane& plane, const WorkspaceMapOptions& o, const std::vector<int>& which,
               const std::vector<Vector>& spine, const std::vector<int>& spineFolds, WorkspaceMap& map,
               std::vector<detail::WorkspaceRow>& rows) {
  std::atomic<size_t> next{0};
  const auto work = [&]() {
    for (size_t k = next++; k < which.size(); k = next++)
      traceRow(plane, o, which[k], spine, spineFolds, map, rows[size_t(which[k])]);
  };
  int threads = o.threads > 0 ? o.threads : continuation::availableCores();
  threads = std::min(threads, int(which.size()));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

// Every row of the map: this process's share traced here, the others' received (WorkspaceShare);
// false when only the share was wanted (rowsOnly) and the map is left incomplete.
bool computeRows(const InputPlane& plane, const WorkspaceMapOptions& o, const std::vector<Vector>& spine,
                 const std::vector<int>& spineFolds, WorkspaceMap& map, std::vector<detail::WorkspaceRow>& rows) {
  const WorkspaceShare& share = o.share;
  std::vector<int> mine;
  for (int j = 0; j < map.count2; ++j)
    if (share.owns(j)) mine.push_back(j);
  traceRows(plane, o, mine, spine, spineFolds, map, rows);
  if (!share.shared()) return true;
  std::vector<int> done;
  for (int j : mine)
    if (rows[size_t(j)].done) done.push_back(j);
  const std::vector<std::string> parts = share.exchange(detail::packWorkspaceRows(map, rows, done));
  for (size_t k = 0; k < parts.size(); ++k)
    if (int(k) != share.part) detail::unpackWorkspaceRows(parts[k], map, rows);
  if (share.rowsOnly) return false;
  std::vector<int> missing;  // the rows of parts interrupted first, or that took no part in this map
  for (int j = 0; j < map.count2; ++j)
    if (!rows[size_t(j)].done) missing.push_back(j);
  traceRows(plane, o, missing, spine, spineFolds, map, rows);
  return true;
}

// Curve starts from the grid: the rows' located folds and joint stops, and the sign changes of
// the singular condition between neighbouring reached cells on one sheet.
std::vector<detail::CurveStart> curveStarts(const InputPlane& plane, const WorkspaceMapOptions& o,
                                            const std::vector<detail::WorkspaceRow>& rows, const WorkspaceMap& map) {
  using Condition = InputPlaneCurveProblem::Condition;
  std::vector<detail::CurveStart> starts;
  const int n = plane.segments();
  for (const detail::WorkspaceRow& row : rows) starts.insert(starts.end(), row.starts.begin(), row.starts.end());
  if (!o.singular) return starts;
  InputPlaneCurveProblem singular(plane, Condition::Singular);
  auto ws = singular.createWorkspace();
  std::vector<double> c(map.cells.size(), std::numeric_limits<double>::quiet_NaN());
  for (size_t k = 0; k < map.cells.size() && !o.tracer.interrupt.requested(); ++k) {
    const WorkspaceCell& cell = map.cells[k];
    double v = 0.0;
    if (cell.reached && singular.condition(*ws, cell.q.head(n), cell.u1, cell.u2, v)) c[k] = v;
  }
  const auto edge = [&](int i1, int j1, int i2, int j2, int fixed) {
    const size_t a = size_t(j1) * size_t(map.count1) + size_t(i1), b = size_t(j2) * size_t(map.count1) + size_t(i2);
    if (!std::isfinite(c[a]) || !std::isfinite(c[b]) || (c[a] > 0) == (c[b] > 0)) return;
    if (map.cells[a].folds != map.cells[b].folds) return;  // not one sheet between them
    const double s = c[a] / (c[a] - c[b]);
    detail::CurveStart st;
    st.condition = Condition::Singular;
    st.name = "singular";
    st.x.resize(n + 2);
    st.x << map.cells[a].q.head(n) + s * (map.cells[b].q.head(n) - map.cells[a].q.head(n)),
        map.cells[a].u2 + s * (map.cells[b].u2 - map.cells[a].u2), map.cells[a].u1 + s * (map.cells[b].u1 - map.cells[a].u1);
    st.fixed = fixed;
    starts.push_back(std::move(st));
  };
  for (int j = 0; j < map.count2; ++j)
    for (int i = 0; i + 1 < map.count1; ++i) edge(i, j, i + 1, j, n);
  for (int j = 0; j + 1 < map.count2; ++j)
    for (int i = 0; i < map.count1; ++i) edge(i, j, i, j + 1, n + 1);
  return starts;
}

}  // namespace

WorkspaceMap computeWorkspaceMap(const InputPlane& plane, ConstVectorRef q0, const WorkspaceMapOptions& o) {
  const std::string why = o.validate();
  if (!why.empty()) throw std::invalid_argument("workspace map: " + why);
  const int n = plane.segments();
  if (q0.size() != n) throw std::invalid_argument("workspace map: q0 needs one angle per segment");
  for (int axis = 0; axis < 2; ++axis) {
    const InputAxisRange& a = axis == 0 ? o.first : o.second;
    const double u0 = plane.origin(axis);
    const double tol = 1e-12 * std::max(1.0, std::abs(u0));
    if (u0 < a.from - tol || u0 > a.to + tol) {
      std::ostringstream os;
      os << "workspace map: " << (axis == 0 ? "first" : "second") << ".from/to: expected a range that contains the "
         << "chain's own value " << plane.input(axis).name() << " = " << u0;
      throw std::invalid_argument(os.str());
    }
    const auto [lo, hi] = plane.admissibleRange(axis);
    if (!(a.from > lo && a.to < hi)) {
      std::ostringstream os;
      os << "workspace map: " << (axis == 0 ? "first" : "second") << ".from/to: expected a range inside (" << lo << ", "
         << hi << "), where every free length " << plane.input(axis).name() << " moves stays > 0";
      throw std::invalid_argument(os.str());
    }
  }
  WorkspaceMap map;
  map.input1 = plane.input(0).name();
  map.input2 = plane.input(1).name();
  map.count1 = o.first.count;
  map.count2 = o.second.count;
  map.cells.resize(size_t(map.count1) * size_t(map.count2));

  // the spine: along u₂ through u₁⁰, sampled at the rows' u₂
  std::vector<double> u2s(static_cast<size_t>(map.count2));
  for (int j = 0; j < map.count2; ++j) u2s[size_t(j)] = o.second.value(j);
  const auto spineProblem = plane.along(1, plane.origin(0));
  const TwoWays spine =
      traceBothWays(*spineProblem, q0, plane.origin(1), rowOptions(o.tracer, o.second.from, o.second.to));
  std::vector<Vector> starts;
  std::vector<int> startFolds;
  sampleAlong(*spineProblem, spine, u2s, o.tracer.interrupt, starts, startFolds);

  std::vector<detail::WorkspaceRow> rows(static_cast<size_t>(map.count2));
  const bool whole = computeRows(plane, o, starts, startFolds, map, rows);
  for (const detail::WorkspaceRow& row : rows)
    if (!row.problem.empty()) map.problems.push_back(row.problem);
  if (!whole || o.tracer.interrupt.requested()) {
    map.interrupted = o.tracer.interrupt.requested();
    return map;
  }
  // the box's edges: the first and last rows, and the columns at u₁ = from, to
  for (int j : {0, map.count2 - 1})
    if (rows[size_t(j)].hasEdge) map.curves.push_back(rows[size_t(j)].edge);
  for (int i : {0, map.count1 - 1}) {
    int best = -1;  // the reached cell of that column nearest u₂⁰, on the sheet of the start
    for (int j = 0; j < map.count2; ++j)
      if (map.cell(i, j).reached && map.cell(i, j).folds == 0 &&
          (best < 0 || std::abs(u2s[size_t(j)] - plane.origin(1)) < std::abs(u2s[size_t(best)] - plane.origin(1))))
        best = j;
    if (best < 0) continue;
    const double u1 = o.first.value(i);
    const auto p = plane.along(1, u1);
    const TwoWays column =
        traceBothWays(*p, map.cell(i, best).q, u2s[size_t(best)], rowOptions(o.tracer, o.second.from, o.second.to));
    map.curves.push_back(edgeCurve(plane, *p, column, 1, u1, map.input1 + (i == 0 ? " = from" : " = to")));
  }
  detail::traceBoundaryCurves(plane, o, curveStarts(plane, o, rows, map), map);
  map.interrupted = o.tracer.interrupt.requested();
  return map;
}

}  // namespace buckle::mechanics
