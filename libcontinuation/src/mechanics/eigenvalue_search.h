// The certified eigenvalue search shared by the chain structure (chain_structure.h) and the
// vibration pencil (pencil_structure.h): isolation of each eigenvalue by counts, Newton on the
// determinant from a warm start, Illinois polish. Private to libcontinuation/src/mechanics.
//
// `evaluate(σ, countOnly)` returns a ShiftEvaluation: the number of eigenvalues below σ (exact,
// from a factorization's inertia) and, unless countOnly, the determinant of a matrix whose roots
// in σ are exactly the eigenvalues wanted (log|det|, its sign, and d log|det|/dσ, NaN when not
// carried: Newton then gives way to the counts). A count alone is all the certification of a
// converged Newton iterate reads, and costs less (no determinant, no derivative).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "buckle/continuation/root_finding.h"
#include "buckle/mechanics/chain_structure.h"

namespace buckle::mechanics::search {

/// At most this many eigenvalues per searchEigenvalues call (the brackets live on the stack).
constexpr int kMaxSearch = ChainStructure::kMaxBorder;

/// Count below σ and log|det|, sign of det K_σ (or of det(T − σM) without constraints), and the
/// logarithmic derivative d log|det|/dσ: det K_σ = c·Π(ν_j − σ) over the eigenvalues ν_j wanted
/// (chain_structure.h, pencil_structure.h), so σ − 1/dLog is Newton's step towards the nearest of them.
struct ShiftEvaluation {
  int below = 0;
  double logAbsDet = 0.0;
  int sign = 1;
  double dLog = 0.0;
  bool determinant = true;  ///< false: `below` only (a count asked for with countOnly)
};

/// Newton on det K_σ from σ0 towards eigenvalue `index` (ascending, counted by the evaluations),
/// every evaluation narrowing (lo, hi) by its count. True when a step fell below tol/4 and counts
/// bracket the eigenvalue within width < tol around the limit: `record` has then seen shifts
/// a, b with count(a) ≤ index < count(b), b − a < tol. False (the caller's
/// isolation and Illinois polish take over from what was recorded, around `last`, the latest
/// iterate, with `lastStep` its step) when an iterate leaves the bracket, a step fails to halve
/// the one before, or after `maxSteps` evaluations.
///
/// From the second evaluation in the same gap between eigenvalues on, the step is that of the
/// model d log|det|/dσ = 1/(σ − ν) + R fitted to the last two evaluations (ν the eigenvalue
/// wanted, R the other eigenvalues' Σ 1/(σ − ν_j), nearly constant near ν: the secular-equation
/// solvers' one-pole model, Bunch, Nielsen & Sorensen 1978). Plain Newton takes R = 0, and where
/// many eigenvalues lie on one side (the lowest of a chain with hundreds below zero) R dominates
/// and Newton creeps towards ν linearly, as on a root of high multiplicity; the model's step
/// lands within a few per cent at once.
template <class Evaluate, class Record>
bool newtonFrom(Evaluate&& evaluateShift, int index, double sigma0, double tol, int maxSteps, double lo, double hi,
                Record&& record, double& last, double& lastStepOut) {
  auto evaluate = [&](double s, bool countOnly) {
    const ShiftEvaluation ev = evaluateShift(s, countOnly);
    record(s, ev);
    if (ev.below > index) {
      if (s < hi) hi = s;
    } else if (s > lo) {
      lo = s;
    }
    return ev;
  };
  double c = sigma0, lastStep = std::numeric_limits<double>::infinity();
  double previous = 0.0, previousDLog = 0.0;  // the evaluation before, for the model
  int previousBelow = -1;
  last = c;
  lastStepOut = std::numeric_limits<double>::infinity();
  for (int step = 0; step < maxSteps; ++step) {
    if (!(c > lo && c < hi)) return false;
    const ShiftEvaluation ev = evaluate(c, false);
    last = c;
    if (!std::isfinite(ev.dLog) || ev.dLog == 0.0) return false;
    double next = c - 1.0 / ev.dLog;  // Newton: the model with R = 0
    // The count says on which side of c the eigenvalue lies; Newton may point the other way
    // (R dominating) and then steps as far towards it instead: a second evaluation in the same
    // gap, for the model.
    const bool below = ev.below > index;
    const auto towards = [&](double x) { return below ? x < c : x > c; };
    if (!towards(next)) next = 2.0 * c - next;
    const bool model = previousBelow == ev.below && c != previous;
    if (model) {
      // 1/(σp − ν) − 1/(c − ν) = dp − d with x = c − ν, h = c − σp:  (dp − d)·x² − (dp − d)·h·x − h = 0
      const double h = c - previous, dd = previousDLog - ev.dLog;
      const double disc = dd * dd * h * h + 4.0 * dd * h;
      if (dd != 0.0 && disc >= 0.0) {
        const double root = std::sqrt(disc);
        const double nu1 = c - (dd * h + root) / (2.0 * dd), nu2 = c - (dd * h - root) / (2.0 * dd);
        // of the two roots those towards the eigenvalue inside the bracket, the nearer to c
        const bool ok1 = std::isfinite(nu1) && towards(nu1) && nu1 > lo && nu1 < hi;
        const bool ok2 = std::isfinite(nu2) && towards(nu2) && nu2 > lo && nu2 < hi;
        if (ok1 && (!ok2 || std::abs(nu1 - c) <= std::abs(nu2 - c))) next = nu1;
        else if (ok2) next = nu2;
      }
    }
    previous = c;
    previousDLog = ev.dLog;
    previousBelow = ev.below;
    if (std::isfinite(next) && next > lo && next < hi) last = next;  // the best estimate so far
    const double size = std::abs(next - c);
    // The halving test from the model's second step on: its first step corrects Newton's
    // underestimate (it may be the longer), after that the steps shrink superlinearly.
    if (!std::isfinite(next) || (size > 0.5 * lastStep && !(model && step == 1))) return false;
    lastStepOut = size;
    // Quadratic convergence: the error left after this step is about (size/lastStep)²·size.
    const double predicted = std::isfinite(lastStep) ? size * (size / lastStep) * (size / lastStep) : size;
    lastStep = size;
    if (size <= 0.25 * tol || predicted <= 0.01 * tol) {
      // Converged, quadratically: the root is far closer to `next` than the step. Certify by the
      // counts at next ∓ 0.45 tol (the bracket then narrower than tol after rounding), or at
      // lo / hi where they already lie that close: count(a) ≤ index < count(b) puts eigenvalue
      // `index` in [a, b), alone or in a cluster narrower than tol (a chain whose load the base
      // wall takes has hundreds at κ within rounding), its value to tol either way.
      const double a = next - 0.45 * tol, b = next + 0.45 * tol;
      if (!(lo >= a) && !(a > lo && evaluate(a, true).below <= index)) return false;
      return hi <= b || evaluate(b, true).below > index;
    }
    c = next;
  }
  return false;
}

/// The eigenvalues first … first + k − 1 (k = min(count, dim − first) ≤ kMaxSearch) to absolute
/// accuracy tolerance · scale; all eigenvalues are expected in [−bound, bound] (widened by the
/// counts when not). Written to out[0 … k − 1]; returns k.
template <class Evaluate>
int searchEigenvalues(Evaluate&& evaluateShift, int dim, double scale, double bound, int first, int count,
                      VectorRef out, double tolerance, const Vector* guess) {
  if (first < 0) return 0;
  const int k = std::max(0, std::min(count, dim - first));
  if (k == 0) return 0;
  const double tol = tolerance * scale;
  // All eigenvalues lie in [−bound, bound]; widen against rounding until the counts confirm it.
  // Confirmed only when a bracket is not isolated from the warm start alone (`outer`): an
  // isolation by the counts at both ends of a bracket needs no outer bound.
  double lo0 = -bound * (1.0 + 1e-10) - tol, hi0 = bound * (1.0 + 1e-10) + tol;
  // Brackets: eigenvalue first + j lies in [lo[j], hi[j]) with count(lo[j]) ≤ first + j < count(hi[j]),
  // with the evaluations at their ends (the Illinois iteration starts from them).
  ChainStructure::SmallVector lo = ChainStructure::SmallVector::Constant(k, lo0);
  ChainStructure::SmallVector hi = ChainStructure::SmallVector::Constant(k, hi0);
  ChainStructure::SmallVector cntLo = ChainStructure::SmallVector::Zero(k);
  ChainStructure::SmallVector cntHi = ChainStructure::SmallVector::Constant(k, double(dim));
  std::array<ShiftEvaluation, ChainStructure::kMaxBorder> evLo, evHi;
  std::array<bool, ChainStructure::kMaxBorder> haveLo{}, haveHi{};
  // (a count alone moves the bracket; Illinois evaluates the determinant at such an end anew)
  auto record = [&](double s, const ShiftEvaluation& e) {
    for (int j = 0; j < k; ++j) {
      if (e.below > first + j) {
        if (s < hi[j]) { hi[j] = s; cntHi[j] = e.below; evHi[size_t(j)] = e; haveHi[size_t(j)] = e.determinant; }
      } else if (s > lo[j]) {
        lo[j] = s;
        cntLo[j] = e.below;
        evLo[size_t(j)] = e;
        haveLo[size_t(j)] = e.determinant;
      }
    }
  };
  bool outerConfirmed = false;
  auto outer = [&]() {
    if (outerConfirmed) return;
    outerConfirmed = true;
    const double lo1 = lo0, hi1 = hi0;
    ShiftEvaluation e;
    while ((e = evaluateShift(lo0, false)).below > 0) lo0 = 2.0 * lo0 - scale;
    const ShiftEvaluation eLo = e;
    while ((e = evaluateShift(hi0, false)).below < first + k) hi0 = 2.0 * hi0 + scale;
    for (int j = 0; j < k; ++j) {  // ends still at the unconfirmed bounds take the confirmed ones
      if (lo[j] == lo1) { lo[j] = lo0; evLo[size_t(j)] = eLo; haveLo[size_t(j)] = true; }
      if (hi[j] == hi1) { hi[j] = hi0; evHi[size_t(j)] = e; haveHi[size_t(j)] = true; }
    }
  };
  auto isolated = [&](int j) { return int(cntLo[j]) == first + j && int(cntHi[j]) == first + j + 1; };
  for (int j = 0; j < k; ++j) {
    if (j > 0 && out[j - 1] - tol > lo[j]) {
      lo[j] = out[j - 1] - tol;
      haveLo[size_t(j)] = false;
    }
    // Warm start: Newton on det K_σ from the guess, certified by the counts either side of its
    // limit. A guess a step δ along the branch away (the spectral monitor's second evaluation) or
    // one continuation step away is within Newton's quadratic range, so this costs three to five
    // factorizations where isolation and Illinois took ten or more.
    double centre = std::numeric_limits<double>::quiet_NaN(), width = std::numeric_limits<double>::infinity();
    if (guess && j < guess->size() && std::isfinite((*guess)[j]) && (*guess)[j] > lo[j] && (*guess)[j] < hi[j]) {
      centre = (*guess)[j];
      if (newtonFrom(evaluateShift, first + j, (*guess)[j], tol, 8, lo[j], hi[j], record, centre, width) &&
          hi[j] - lo[j] <= tol) {
        out[j] = 0.5 * (lo[j] + hi[j]);
        continue;
      }
    }
    // Otherwise counts around the guess (or Newton's latest iterate, nearer), widening by 8 from
    // twice its last step or 2 % of it. (A width tied to ‖H‖ instead isolates nothing on a long or
    // strongly loaded chain, whose lowest eigenvalues are spaced ~κ/n² ≪ 1e−3‖H‖_F, and bisection
    // then pays ~log2(‖H‖ n²/κ) counts per eigenvalue.)
    // Widening stops once [a, b] brackets the eigenvalue, isolated or not: inside a cluster of
    // eigenvalues closer than the widths tried (an unloaded stretch of the chain: hundreds at κ),
    // a wider bracket only holds more of them, and the bisection below goes on from this one.
    // An iterate the counts left outside the bracket (Newton creeping towards a cluster stops
    // a few tol short of it, the counts then put the eigenvalue beyond) widens from the
    // bracket's end, from 16 tol.
    const bool outside = std::isfinite(centre) && !(centre > lo[j] && centre < hi[j]);
    if (outside) centre = std::min(std::max(centre, lo[j]), hi[j]);
    if (std::isfinite(centre)) {
      double delta = outside ? std::max(16.0 * tol, 2.0 * width)
                             : std::max(1e-9 * scale, std::min(0.02 * std::abs(centre), 2.0 * width));
      for (int attempt = 0; attempt < 12 && !isolated(j); ++attempt, delta *= 8.0) {
        const double a = centre - delta, b = centre + delta;
        if (a > lo[j]) record(a, evaluateShift(a, false));
        if (b < hi[j]) record(b, evaluateShift(b, false));
        if (lo[j] >= a && hi[j] <= b) break;
      }
    }
    if (!isolated(j)) outer();
    // isolate: exactly one eigenvalue (j) in [lo, hi)
    while (!isolated(j) && hi[j] - lo[j] > tol) {
      const double mid = 0.5 * (lo[j] + hi[j]);
      if (mid <= lo[j] || mid >= hi[j]) break;
      record(mid, evaluateShift(mid, false));
    }
    // Isolated: the model iteration from the bracket's middle (a failed try has at least halved
    // the bracket by its first count), a few times, before Illinois.
    for (int attempt = 0; attempt < 4 && isolated(j) && hi[j] - lo[j] > tol; ++attempt) {
      double at = 0.0, step = 0.0;
      const double mid = 0.5 * (lo[j] + hi[j]);
      if (newtonFrom(evaluateShift, first + j, mid, tol, 8, lo[j], hi[j], record, at, step) && isolated(j) &&
          hi[j] - lo[j] <= tol)
        break;
    }
    if (isolated(j) && hi[j] - lo[j] > tol) {
      // Illinois on det, one simple root in the bracket; the counts keep the bracket honest.
      // (Newton from here, far from the root, fails its halving test almost always: 10 of 345
      // brackets in the n = 300 race.)
      const ShiftEvaluation ea = haveLo[size_t(j)] ? evLo[size_t(j)] : evaluateShift(lo[j], false);
      const ShiftEvaluation eb = haveHi[size_t(j)] ? evHi[size_t(j)] : evaluateShift(hi[j], false);
      const double ref = 0.5 * (ea.logAbsDet + eb.logAbsDet);
      auto value = [&](const ShiftEvaluation& e) {
        return e.sign * std::exp(std::max(-700.0, std::min(700.0, e.logAbsDet - ref)));
      };
      // Illinois on the determinant, the side of the root decided by the count (exact)
      continuation::IllinoisBracket br{lo[j], hi[j], value(ea), value(eb), 0};
      for (int it = 0; it < 200 && br.width() > tol; ++it) {
        // keep progress: never closer than tol/4 to an end
        const double c = std::min(std::max(br.next(), br.left + 0.25 * tol), br.right - 0.25 * tol);
        const ShiftEvaluation ec = evaluateShift(c, false);
        const double fc = value(ec);
        br.replace(ec.below > first + j ? 1 : -1, c, fc);  // the root is below c: c is the new right end
        if (fc == 0.0) {
          br.left = br.right = c;
          break;
        }
      }
      lo[j] = br.left;
      hi[j] = br.right;
    }
    out[j] = 0.5 * (lo[j] + hi[j]);
  }
  return k;
}

}  // namespace buckle::mechanics::search
