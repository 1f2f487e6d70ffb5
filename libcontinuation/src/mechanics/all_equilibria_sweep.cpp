#include "all_equilibria_sweep.h"

#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "buckle/mechanics/energy_landscape.h"

namespace buckle::mechanics::detail {

namespace {

bool feasible(const LandscapeSample& s) { return s.status == LandscapeStatus::Feasible; }
bool usable(const LandscapeSample& s) { return feasible(s) && std::isfinite(s.dEdq1); }

// The landscape's own test that two neighbouring samples lie on one piece of the curve.
bool onePiece(const LandscapeSample& a, const LandscapeSample& b) {
  return std::abs(std::remainder(b.q[1] - a.q[1], 2.0 * M_PI)) <= 0.5 && std::abs(b.q[2] - a.q[2]) <= 0.5;
}

bool opposite(double a, double b) { return (a < 0.0) != (b < 0.0); }

// The configuration curve with the end held at (x, y) and what acts on the chain: its samples
// (energy_landscape.h), E + V with the body loads.
struct SweepCurve {
  const Chain& chain;
  double x, y;
  BodyLoadTerms* body;  // null: none (landscapeSample overwrites its last update)
  LandscapeSample at(double q1, int branch) const { return landscapeSample(chain, x, y, q1, branch, body); }
};

// Bisection of the sign change of f (a member of the sample) on [lo, hi], f(lo) of sign `fLo`.
// Bisection alone: the refined cells are those where Newton's derivative changes sign.
template <class Value>
bool bisect(const SweepCurve& c, int branch, double lo, double hi, double fLo, Value value,
            LandscapeSample& out) {
  for (int it = 0; it < 200 && hi - lo > 4.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(lo));
       ++it) {
    const double mid = 0.5 * (lo + hi);
    const LandscapeSample s = c.at(mid, branch);
    if (!usable(s) || !std::isfinite(value(s))) return false;
    if (opposite(value(s), fLo) || value(s) == 0.0) {
      hi = mid;
    } else {
      lo = mid;
    }
  }
  out = c.at(0.5 * (lo + hi), branch);
  return usable(out);
}

// A cell where dE/dq1 keeps its sign but d²E/dq1² changes it holds an extremum of dE/dq1: where
// that extremum crosses zero, two roots share the cell and the sign test missed both.
void refineCells(const SweepCurve& c, const std::vector<LandscapeSample>& s, int branch,
                 std::vector<SweepPoint>& out) {
  auto d1 = [](const LandscapeSample& p) { return p.dEdq1; };
  auto d2 = [](const LandscapeSample& p) { return p.d2Edq1; };
  for (size_t i = 0; i + 1 < s.size(); ++i) {
    const LandscapeSample &a = s[i], &b = s[i + 1];
    if (!usable(a) || !usable(b) || !onePiece(a, b)) continue;
    if (a.dEdq1 == 0.0 || b.dEdq1 == 0.0 || opposite(a.dEdq1, b.dEdq1)) continue;
    if (!std::isfinite(a.d2Edq1) || !std::isfinite(b.d2Edq1) || !opposite(a.d2Edq1, b.d2Edq1)) continue;
    LandscapeSample m;
    if (!bisect(c, branch, a.q1, b.q1, a.d2Edq1, d2, m) || !opposite(m.dEdq1, a.dEdq1)) continue;
    LandscapeSample r;
    if (bisect(c, branch, a.q1, m.q1, a.dEdq1, d1, r)) out.push_back({r.q, r.d2Edq1 > 0.0, true});
    if (bisect(c, branch, m.q1, b.q1, m.dEdq1, d1, r)) out.push_back({r.q, r.d2Edq1 > 0.0, true});
  }
}

// One maximal run of feasible samples on one branch; its ends are junctions with the other
// branch (the next sample has no inverse kinematics: S3 = 0, where the branches meet) or
// limits (the next sample violates a joint limit or is beyond joint 1's range).
struct Run {
  int branch = 0, first = 0, last = 0;
  bool junction[2] = {false, false};  // [0] left end (first), [1] right end (last)
  bool paired[2] = {false, false};    // a junction met by a run of the other branch
  LandscapeSample boundary[2];        // the last feasible point towards the next sample
};

const std::vector<LandscapeSample>& samplesOf(const EnergyLandscape& L, int branch) {
  return branch > 0 ? L.positive : L.negative;
}

// The last feasible point between a feasible q1 and an infeasible one, by bisection, moved back
// towards the feasible side until dE/dq1 is defined (it is not at a junction itself, where the
// q1-parametrisation turns).
LandscapeSample boundarySample(const SweepCurve& c, int branch, double inside, double out) {
  double in = inside;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (in + out);
    (feasible(c.at(mid, branch)) ? in : out) = mid;
  }
  for (double fraction = 1e-9; fraction < 1.0; fraction *= 4.0) {
    const LandscapeSample s = c.at(in + fraction * (inside - in), branch);
    if (usable(s)) return s;
  }
  return c.at(inside, branch);
}

// The runs of both branches with their ends' boundary points; false (with the reason) when the
// curve jumps between two samples.
bool findRuns(const SweepCurve& c, const EnergyLandscape& L, std::vector<Run>& runs, std::string& why) {
  for (int branch : {+1, -1}) {
    const std::vector<LandscapeSample>& s = samplesOf(L, branch);
    const int N = int(s.size());
    for (int i = 0; i < N;) {
      if (!feasible(s[size_t(i)])) {
        ++i;
        continue;
      }
      Run r;
      r.branch = branch;
      r.first = i;
      while (i + 1 < N && feasible(s[size_t(i + 1)])) {
        if (!onePiece(s[size_t(i)], s[size_t(i + 1)])) {
          why = "the sweep's curve jumps between two samples (a wrap of q2): topology not traced";
          return false;
        }
        ++i;
      }
      r.last = i++;
      for (int side : {0, 1}) {
        const int end = side == 0 ? r.first : r.last, next = side == 0 ? end - 1 : end + 1;
        r.boundary[side] = s[size_t(end)];
        if (next < 0 || next >= N) continue;  // joint 1's own limit: the sample is on it
        r.junction[side] = s[size_t(next)].status == LandscapeStatus::NoInverseKinematics;
        r.boundary[side] = boundarySample(c, branch, s[size_t(end)].q1, s[size_t(next)].q1);
      }
      runs.push_back(r);
    }
  }
  for (Run& a : runs)
    for (Run& b : runs)
      for (int side : {0, 1})
        if (a.branch > 0 && b.branch < 0 && a.junction[side] && b.junction[side] &&
            (side == 0 ? a.first == b.first : a.last == b.last))
          a.paired[side] = b.paired[side] = true;
  return true;
}

// Roots the cell test cannot see at the ends of a run: between the last sample and the run's
// boundary point, and on the short piece through a junction, where q1 turns back and the curve
// passes onto the other branch (E's rate along the curve is +dE/dq1 outward on one branch and
// −dE/dq1 coming back on the other: a root lies between when both dE/dq1 have one sign).
void refineEnds(const SweepCurve& c, const EnergyLandscape& L, const std::vector<Run>& runs,
                std::vector<SweepPoint>& out) {
  auto d1 = [](const LandscapeSample& p) { return p.dEdq1; };
  for (const Run& r : runs)
    for (int side : {0, 1}) {
      const LandscapeSample& e = samplesOf(L, r.branch)[size_t(side == 0 ? r.first : r.last)];
      const LandscapeSample& B = r.boundary[side];
      if (!usable(e) || !usable(B) || B.q1 == e.q1 || !opposite(e.dEdq1, B.dEdq1)) continue;
      const LandscapeSample& lo = e.q1 < B.q1 ? e : B;
      const double hi = e.q1 < B.q1 ? B.q1 : e.q1;
      LandscapeSample root;
      if (bisect(c, r.branch, lo.q1, hi, lo.dEdq1, d1, root))
        out.push_back({root.q, root.d2Edq1 > 0.0, true});
    }
  for (const Run& a : runs)
    for (const Run& b : runs)
      for (int side : {0, 1}) {
        if (a.branch <= 0 || b.branch >= 0 || !a.paired[side] || !b.paired[side]) continue;
        if ((side == 0 ? a.first != b.first : a.last != b.last)) continue;
        const LandscapeSample &Bp = a.boundary[side], &Bm = b.boundary[side];
        if (usable(Bp) && usable(Bm) && (Bp.dEdq1 < 0.0) == (Bm.dEdq1 < 0.0))
          out.push_back({Bp.q, false, true});  // within the junction piece: polished by the caller
      }
}

int endSign(const EnergyLandscape& L, const Run& r, int side) {
  // dE/dq1 times the outward direction at the end: at the boundary point, else walking inward.
  const int dir = side == 0 ? -1 : +1;
  if (std::isfinite(r.boundary[side].dEdq1) && r.boundary[side].dEdq1 != 0.0)
    return r.boundary[side].dEdq1 * dir < 0.0 ? -1 : +1;
  const std::vector<LandscapeSample>& s = samplesOf(L, r.branch);
  for (int k = 0; k <= r.last - r.first; ++k) {
    const LandscapeSample& p = s[size_t(side == 0 ? r.first + k : r.last - k)];
    if (std::isfinite(p.dEdq1) && p.dEdq1 != 0.0) return (p.dEdq1 * dir < 0.0) ? -1 : +1;
  }
  return 0;
}

int findRoot(std::vector<int>& parent, int k) {
  while (parent[size_t(k)] != k) k = parent[size_t(k)] = parent[size_t(parent[size_t(k)])];
  return k;
}

// Topology of the feasible configuration set {q in the limits : (x, y) reached} traced by the
// sweep: runs joined at junctions into loops (χ = 0) and arcs (χ = 1). On an arc whose end lies on
// a joint limit, E decreasing outward there removes one from the count of the interior
// critical points (1-D Morse theory with boundary): Σ(−1)^index = Σ_arcs (1 − #ends decreasing).
void topology(const EnergyLandscape& L, const std::vector<Run>& runs, MorseCheck& morse) {
  if (runs.empty()) {
    morse.basis = "no feasible sample: the configuration set is empty or finer than the sweep (e.g. a single point "
                  "with the end at full reach)";
    return;
  }
  for (const Run& r : runs)
    if (r.first == r.last) {
      morse.basis = "a piece of the configuration set shorter than the sweep's resolution: topology not traced";
      return;
    }
  std::vector<int> parent(runs.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (size_t a = 0; a < runs.size(); ++a)
    for (size_t b = 0; b < runs.size(); ++b)
      for (int side : {0, 1})
        if (runs[a].branch > 0 && runs[b].branch < 0 && runs[a].paired[side] && runs[b].paired[side] &&
            (side == 0 ? runs[a].first == runs[b].first : runs[a].last == runs[b].last))
          parent[size_t(findRoot(parent, int(a)))] = findRoot(parent, int(b));
  std::vector<int> limitEnds(runs.size(), 0), decreasing(runs.size(), 0);
  for (size_t r = 0; r < runs.size(); ++r)
    for (int side : {0, 1}) {
      if (runs[r].paired[side]) continue;  // an unpaired junction: the curve leaves the limits there
      const int root = findRoot(parent, int(r));
      ++limitEnds[size_t(root)];
      const int sign = endSign(L, runs[r], side);
      if (sign == 0) {
        morse.basis = "no sign of dE/dq1 at an end of the configuration set";
        return;
      }
      if (sign < 0) ++decreasing[size_t(root)];
    }
  morse.expected = 0;
  for (size_t r = 0; r < runs.size(); ++r) {
    if (findRoot(parent, int(r)) != int(r)) continue;
    if (limitEnds[r] == 0) {
      ++morse.loops;
    } else if (limitEnds[r] == 2) {
      ++morse.arcs;
      morse.expected += 1 - decreasing[r];
    } else {
      morse.basis = "a piece of the configuration set with " + std::to_string(limitEnds[r]) + " ends";
      return;
    }
  }
  morse.applies = true;
  morse.basis = "1-D Morse count on the configuration set of the end held at (x, y): " + std::to_string(morse.loops) +
                " closed curve(s) (chi = 0), " + std::to_string(morse.arcs) +
                " arc(s) cut by the joint limits (chi = 1, less one per end where E decreases outward)";
}

}  // namespace

SweepResult sweepEquilibria(const Chain& chain, double x, double y, int samples, const BodyLoads& body) {
  LandscapeOptions options;
  options.samples = samples;
  options.body = body;
  const EnergyLandscape L = energyLandscape(chain, x, y, options);
  BodyLoadTerms terms(chain, body.atParameter(0.0));
  const SweepCurve c{chain, x, y, terms.active() ? &terms : nullptr};
  SweepResult result;
  for (const LandscapeEquilibrium& e : L.equilibria) result.equilibria.push_back({e.q, e.stable, false});
  refineCells(c, L.positive, +1, result.equilibria);
  refineCells(c, L.negative, -1, result.equilibria);
  std::vector<Run> runs;
  if (findRuns(c, L, runs, result.morse.basis)) {
    refineEnds(c, L, runs, result.equilibria);
    topology(L, runs, result.morse);
  }
  return result;
}

}  // namespace buckle::mechanics::detail
