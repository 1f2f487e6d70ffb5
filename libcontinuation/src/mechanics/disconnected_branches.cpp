#include "buckle/mechanics/disconnected_branches.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>

namespace buckle::mechanics {

namespace cont = buckle::continuation;

namespace {

// A traced curve in the scaled variables x = (u / D_u, λ / λ₀), with unit tangents there.
struct Curve {
  int id = -1;
  bool pending = false;  // finished in the trace under way (its id still the trace's own)
  std::vector<Eigen::VectorXd> x, t;
};

struct Scaling {
  Eigen::VectorXd state;  // D_u and λ₀, size N + 1
  Eigen::VectorXd point(const cont::ContinuationPoint& p) const {
    Eigen::VectorXd x(state.size());
    x << p.u, p.lambda;
    return x.cwiseQuotient(state);
  }
  Eigen::VectorXd tangent(const cont::ContinuationPoint& p) const {
    if (p.tangent.size() != state.size()) return Eigen::VectorXd::Zero(state.size());
    const Eigen::VectorXd t = p.tangent.cwiseQuotient(state);
    return t.norm() > 0.0 ? Eigen::VectorXd(t / t.norm()) : t;
  }
};

Curve curveOf(const cont::Branch& b, const Scaling& s) {
  Curve c;
  c.id = b.id;
  for (const cont::ContinuationPoint& p : b.points) {
    c.x.push_back(s.point(p));
    c.t.push_back(s.tangent(p));
  }
  return c;
}

// Distance from x to the chord [a, b].
double toChord(const Eigen::VectorXd& x, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::VectorXd d = b - a;
  const double dd = d.squaredNorm();
  const double s = dd > 0.0 ? std::clamp((x - a).dot(d) / dd, 0.0, 1.0) : 0.0;
  return (a + s * d - x).norm();
}

// Where the step [a, b] (tangent tb at b) meets curve c: `near` when a point of c lies within
// the fraction f of the step from it or b within f of one of c's chords; `parallel` when also
// the tangents there are (|cos| ≥ minCos).
struct Meeting {
  bool near = false, parallel = false;
};
Meeting meet(const Curve& c, const Eigen::VectorXd& a, const Eigen::VectorXd& b, const Eigen::VectorXd& tb, double f,
             double minCos) {
  Meeting m;
  const double floor = 1e-9 * (1.0 + b.norm());
  const double step = (b - a).norm();
  auto note = [&](const Eigen::VectorXd& t) {
    m.near = true;
    // a curve without a tangent (a single point) is parallel to any step through it
    if (t.squaredNorm() == 0.0 || std::abs(t.dot(tb)) >= minCos) m.parallel = true;
  };
  for (size_t j = 0; j < c.x.size() && !m.parallel; ++j) {
    if (toChord(c.x[j], a, b) <= f * step + floor) note(c.t[j]);
    if (j + 1 < c.x.size() && toChord(b, c.x[j], c.x[j + 1]) <= f * (c.x[j + 1] - c.x[j]).norm() + floor)
      note((b - c.x[j]).norm() < (b - c.x[j + 1]).norm() ? c.t[j] : c.t[j + 1]);
  }
  return m;
}

// The join test of the branches being traced. A branch starts on its own seed, the second
// direction on the first one's start, a contact stretch at its branch's end: a step counts as
// joining one of the seed's own curves (ids from groupFrom, those of the trace under way, and its
// seed point) only once the branch has been away from it. Any other
// curve it joins at once: a child switched at a branch point where a traced curve crosses, and
// that goes along it, is that curve.
class JoinWatch {
 public:
  JoinWatch(const Scaling& s, const DisconnectedBranchOptions& o) : scaling_(s), options_(o) {}
  std::vector<Curve> curves;
  int groupFrom = 0, seedCurve = -1;

  cont::StepAction step(const cont::StepInfo& step) {
    const cont::ContinuationPoint& p = step.point;
    const Eigen::VectorXd b = scaling_.point(p), tb = scaling_.tangent(p);
    // A new branch (or contact stretch, or switched child that starts with points of its own)
    // begins: the earlier points may still be in the tracer's scaled variables, so the watch
    // starts from its newest point.
    const bool fresh = step.branch != branch_ || size_t(step.pointCount) <= std::max<size_t>(2, size_) ||
                       step.startLambda != firstLambda_;
    branch_ = step.branch;
    size_ = size_t(step.pointCount);
    firstLambda_ = step.startLambda;
    if (fresh) {
      away_.clear();
      last_ = b;
      return cont::StepAction::Continue;
    }
    for (size_t c = away_.size(); c < curves.size(); ++c)
      away_.push_back(!(curves[c].pending || curves[c].id >= groupFrom || curves[c].id == seedCurve));
    for (size_t c = 0; c < curves.size(); ++c) {
      const Meeting m = meet(curves[c], last_, b, tb, options_.joinFraction, options_.joinCosine);
      if (m.parallel && away_[c]) return cont::StepAction::Join;
      if (!m.near) away_[c] = true;
    }
    last_ = b;
    return cont::StepAction::Continue;
  }

 private:
  const Scaling& scaling_;
  const DisconnectedBranchOptions& options_;
  std::vector<bool> away_;
  Eigen::VectorXd last_;
  const void* branch_ = nullptr;  // the branch of the last step, its size and first λ
  size_t size_ = 0;
  double firstLambda_ = 0.0;
};

// The curve a joined branch ended on: the first one (not the branch itself) its last step meets
// parallel; −1 when none does (a contact stretch that joined a curve not kept as one).
int joinedCurve(const std::vector<Curve>& curves, const cont::Branch& b, const Scaling& s,
                const DisconnectedBranchOptions& o) {
  if (b.points.size() < 2) return -1;
  const Eigen::VectorXd a = s.point(b.points[b.points.size() - 2]), x = s.point(b.points.back());
  const Eigen::VectorXd t = s.tangent(b.points.back());
  for (const Curve& c : curves)
    if (c.id != b.id && meet(c, a, x, t, o.joinFraction, o.joinCosine).parallel) return c.id;
  return -1;
}

// Newton at fixed λ from u; the polished u, or empty when it does not converge to the residual
// scale.
Eigen::VectorXd polishAt(EquilibriumProblem& problem, Eigen::VectorXd u, double lambda) {
  const int N = problem.dimension();
  const cont::ProblemScales scales = problem.scales();
  Eigen::VectorXd F(N), Fl(N);
  Eigen::MatrixXd Fu(N, N);
  const cont::BoundProblem bound(problem);  // this polish's workspace
  for (int it = 0; it < 30; ++it) {
    if (!bound.residual(u, lambda, F)) return {};
    if (F.cwiseQuotient(scales.residuals).cwiseAbs().maxCoeff() <= 1e-11) return u;
    if (!bound.jacobian(u, lambda, Fu, Fl)) return {};
    Eigen::PartialPivLU<Eigen::MatrixXd> lu(Fu);
    const Eigen::VectorXd du = lu.solve(-F);
    if (!du.allFinite()) return {};
    u += du;
  }
  return {};
}

}  // namespace

std::vector<Crossing> crossings(EquilibriumProblem& problem, const cont::Branch& branch, double lambda) {
  std::vector<Crossing> out;
  const int n = problem.segments();
  const cont::ProblemScales scales = problem.scales();
  Scaling s;
  s.state.resize(problem.dimension() + 1);
  s.state << scales.unknowns, scales.parameter;
  for (size_t i = 0; i + 1 < branch.points.size(); ++i) {
    const cont::ContinuationPoint &a = branch.points[i], &b = branch.points[i + 1];
    const double da = a.lambda - lambda, db = b.lambda - lambda;
    if (da * db > 0.0 || (da == 0.0 && db == 0.0) || a.u.size() != b.u.size()) continue;
    const double w = da == db ? 0.0 : da / (da - db);
    const Eigen::VectorXd u = (1.0 - w) * a.u + w * b.u;
    Crossing c;
    c.chord = (s.point(b) - s.point(a)).norm();
    const Eigen::VectorXd polished = polishAt(problem, u, lambda);
    c.polished = polished.size() == u.size();
    c.q = (c.polished ? polished : u).head(n);
    if (c.polished) c.offset = (polished - u).cwiseQuotient(scales.unknowns).cwiseAbs().maxCoeff();
    out.push_back(std::move(c));
  }
  return out;
}

namespace {

// Equilibrium q lies on the branch with these crossings: a polished crossing that moved less
// than its chord (it polished onto this branch, not across to another) equal to q within tol,
// or an unpolished interpolant within the join fraction of its chord.
bool lies(const std::vector<Crossing>& cs, const Eigen::VectorXd& q, const Eigen::VectorXd& angleScale, double tol,
          double fraction) {
  for (const Crossing& c : cs) {
    const double d = (c.q - q).cwiseAbs().maxCoeff();
    if (c.polished && c.offset <= c.chord && d <= tol) return true;
    if (!c.polished && (c.q - q).cwiseQuotient(angleScale).norm() <= fraction * c.chord) return true;
  }
  return false;
}

// Appends `from` to `to`, ids, parents and mirror sources moved by `offset`.
void append(EquilibriumBranches&& from, int offset, EquilibriumBranches& to) {
  for (cont::Branch& b : from.tree.branches) {
    b.id += offset;
    if (b.parentId >= 0) b.parentId += offset;
    if (b.mirrorOf >= 0) b.mirrorOf += offset;
    to.tree.branches.push_back(std::move(b));
  }
  for (auto& r : from.reports) to.reports.push_back(std::move(r));
  for (auto& c : from.classifications) to.classifications.push_back(std::move(c));
  for (auto& c : from.contact) to.contact.push_back(std::move(c));
  to.tree.interrupted = to.tree.interrupted || from.tree.interrupted;
  if (from.tree.interrupted) to.tree.message = from.tree.message;
}

}  // namespace

std::string DisconnectedBranchOptions::validate(const std::string& prefix) const {
  return cont::firstProblem({branches.validate(prefix + "branches."),
                             cont::requirePositive(prefix, "onBranchTolerance", onBranchTolerance),
                             cont::require(joinFraction > 0.0 && joinFraction < 1.0, prefix, "joinFraction",
                                           "must lie in (0, 1)"),
                             cont::require(joinCosine > 0.0 && joinCosine <= 1.0, prefix, "joinCosine",
                                           "must lie in (0, 1]")});
}

DisconnectedBranches traceDisconnectedBranches(EquilibriumProblem& problem, const std::vector<Eigen::VectorXd>& q,
                                               double lambda, const std::vector<bool>& stable,
                                               const std::vector<cont::Branch>& known,
                                               const DisconnectedBranchOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("DisconnectedBranchOptions: " + why);
  const int n = problem.segments();
  const cont::ProblemScales scales = problem.scales();
  Scaling scaling;
  scaling.state.resize(problem.dimension() + 1);
  scaling.state << scales.unknowns, scales.parameter;
  const Eigen::VectorXd angleScale = scales.unknowns.head(n);

  DisconnectedBranches out;
  out.lambda = lambda;
  out.onBranch.assign(q.size(), -1);
  for (const cont::Branch& b : known) out.firstId = std::max(out.firstId, b.id + 1);

  JoinWatch watch(scaling, options);
  auto markCrossed = [&](const cont::Branch& b) {
    const std::vector<Crossing> cs = crossings(problem, b, lambda);
    for (size_t i = 0; i < q.size(); ++i)
      if (out.onBranch[i] < 0 && lies(cs, q[i], angleScale, options.onBranchTolerance, options.joinFraction))
        out.onBranch[i] = b.id;
  };
  for (const cont::Branch& b : known) {
    markCrossed(b);
    watch.curves.push_back(curveOf(b, scaling));
  }

  EquilibriumBranchOptions o = options.branches;
  const cont::StepCallback userStep = o.tracer.onStep;
  const auto userBranch = o.tree.onBranch;
  auto onStep = [&watch, userStep](const cont::StepInfo& step) {
    if (userStep && userStep(step) == cont::StepAction::Stop) return cont::StepAction::Stop;
    return watch.step(step);
  };
  o.tracer.onStep = onStep;
  if (o.tree.childTracer) o.tree.childTracer->onStep = onStep;
  // a finished branch is a curve the next ones may join (children, the other direction, later seeds)
  o.tree.onBranch = [&watch, &scaling, &userBranch](const cont::BranchTree& t, const cont::Branch& b) {
    if (userBranch) userBranch(t, b);
    watch.curves.push_back(curveOf(b, scaling));
    watch.curves.back().pending = true;
  };

  std::vector<int> seedBranch(q.size(), -1);  // the first branch traced from each seed
  std::vector<size_t> order(q.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&stable](size_t a, size_t b) {
    return a < stable.size() && b < stable.size() && stable[a] && !stable[b];
  });
  for (size_t i : order) {
    if (out.onBranch[i] >= 0) continue;
    if (o.tracer.interrupt.requested()) {
      out.interrupted = true;
      break;
    }
    out.seeds.push_back(int(i));
    // The seed is a curve of one point, parallel to anything (no tangent): a branch back at it
    // has closed an isola, and the other direction is the same curve.
    Curve seedPoint;
    seedPoint.id = -2 - int(i);
    const int firstOfSeed = out.firstId + int(out.traced.tree.branches.size());
    seedBranch[i] = firstOfSeed;
    watch.groupFrom = firstOfSeed;
    watch.seedCurve = seedPoint.id;
    cont::ContinuationPoint p0;
    p0.u = problem.initialGuess(q[i], lambda);
    p0.lambda = lambda;
    seedPoint.x.push_back(scaling.point(p0));
    seedPoint.t.push_back(Eigen::VectorXd::Zero(p0.u.size() + 1));
    watch.curves.push_back(seedPoint);
    for (const cont::InitialDirection& d :
         {cont::InitialDirection::increasingLambda(), cont::InitialDirection::decreasingLambda()}) {
      const int offset = out.firstId + int(out.traced.tree.branches.size());
      const size_t firstCurve = watch.curves.size();
      EquilibriumBranches t = traceEquilibria(problem, q[i], lambda, d, o);
      if (t.tree.branches.empty() || t.tree.branches.front().stopReason == cont::StopReason::StartFailed) {
        watch.curves.resize(firstCurve);
        break;
      }
      for (size_t c = firstCurve; c < watch.curves.size(); ++c) {
        watch.curves[c].id += offset;
        watch.curves[c].pending = false;
      }
      append(std::move(t), offset, out.traced);
      bool closed = false;
      for (size_t b = size_t(offset - out.firstId); b < out.traced.tree.branches.size(); ++b) {
        const cont::Branch& branch = out.traced.tree.branches[b];
        out.seed.push_back(int(i));
        int joined = branch.stopReason == cont::StopReason::Joined ? joinedCurve(watch.curves, branch, scaling, options) : -1;
        if (joined <= -2) {  // a seed point: the seed's first branch
          closed = closed || (branch.parentId < 0 && joined == seedPoint.id);
          joined = seedBranch[size_t(-2 - joined)];
        }
        out.joined.push_back(joined);
      }
      out.interrupted = out.interrupted || out.traced.tree.interrupted;
      if (closed || out.interrupted) break;
    }
    for (size_t b = 0; b < out.traced.tree.branches.size(); ++b)
      if (out.seed[b] == int(i)) markCrossed(out.traced.tree.branches[b]);
  }
  return out;
}

}  // namespace buckle::mechanics
