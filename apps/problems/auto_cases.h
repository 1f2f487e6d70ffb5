// The AUTO-07p comparison cases (shared/peers/auto07p/README.md) run through buckle's core with
// AUTO-like settings, timed in-process: the trivial branches of the pinned 3-chain, the U and Z
// branches switched onto at its branch points, and the fold of the free end. Header-only so that
// the benchmark programs (benchmarks/cases.h) can use it without linking anything new; the CLI
// (`buckle regress`) uses it through the buckle_problems target. Depends on the core only.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::problems {

namespace cont = buckle::continuation;
using mechanics::Chain;
using mechanics::EndCondition;
using mechanics::EquilibriumProblem;
using mechanics::SegmentParameters;

/// The paper's main segment: a = 0.5, b = 1, k = 1, L0 = 2.25 (κ = 0.75).
inline SegmentParameters mainSegment(double L0 = 2.25) { return SegmentParameters::symmetric(0.5, 1.0, 1.0, L0); }

/// Eq 17: the first (U) or second (Z) critical Fx of the clamped–pinned 3-chain.
inline double analyticFx(double L0, bool zShape) {
  const double kappa = 1.0 * (1.0 * L0 - 2.0 * (1.0 - 0.25));
  const double lam = zShape ? -(std::sqrt(21.0) + 14.0) / 10.0 : (std::sqrt(21.0) - 14.0) / 10.0;
  return lam * kappa / 1.0;
}

/// Solver settings varied by the work-precision program; defaults mirror the AUTO c-files
/// (DS = 0.01, DSMAX = 0.05, DSMIN = 1e-4).
struct Settings {
  double initialStep = 0.01;
  double maxStep = 0.05;
  double minStep = 1e-4;
  double newtonTolerance = 1e-10;
  double locationTolerance = 1e-12;
  bool stability = true;
  /// Lowest eigenvalues recorded per point (TracerOptions::lowestEigenvalues). bench_cases uses
  /// 0 (inertia only, what the branch-point test needs; AUTO with IPS = 0 computes none).
  int lowestEigenvalues = 3;
  bool secondOrderPredictor = false;  ///< TracerOptions::secondOrderPredictor
  bool certifiedCounting = true;      ///< TracerOptions::certifiedCounting
  bool leanNewton = false;            ///< TracerOptions::leanNewton
};

inline cont::TracerOptions tracerOptions(const Settings& s, double lambdaMin, double lambdaMax) {
  cont::TracerOptions o;
  o.step.initialStep = s.initialStep;
  o.step.maxStep = s.maxStep;
  o.step.minStep = std::min(s.minStep, s.initialStep);
  o.corrector.tolerance = s.newtonTolerance;
  o.location.tolerance = s.locationTolerance;
  o.location.newtonTolerance = std::min(1e-13, s.newtonTolerance);
  o.detection.stability = s.stability;
  o.detection.lowestEigenvalues = s.lowestEigenvalues;
  o.step.secondOrderPredictor = s.secondOrderPredictor;
  o.detection.certifiedCounting = s.certifiedCounting;
  o.corrector.leanNewton = s.leanNewton;
  o.lambdaMin = lambdaMin;
  o.lambdaMax = lambdaMax;
  o.maxPoints = 20000;
  return o;
}

/// Clamped–pinned 3-chain, λ = Fx, optional user joint limits ±qLimit.
inline EquilibriumProblem pinned3(double L0, double qLimit = std::numeric_limits<double>::infinity()) {
  SegmentParameters p = mainSegment(L0);
  p.qMinUser = -qLimit;
  p.qMaxUser = qLimit;
  return EquilibriumProblem(Chain::uniform(3, p), EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
}

/// Free-end 3-chain with a fixed transverse load Fy, λ = Fx.
inline EquilibriumProblem free3(double L0, double Fy) {
  return EquilibriumProblem(Chain::uniform(3, mainSegment(L0)), EndCondition::freeEnd(Eigen::Vector3d(0, Fy, 0)),
                            Eigen::Vector3d(1, 0, 0));
}

struct Located {
  std::string label;  ///< BP, BP2 (multiplicity 2), LP, BD (boundary), EP
  double Fx = 0.0;
  double reference = std::numeric_limits<double>::quiet_NaN();  ///< analytic / reference value
};

struct CaseResult {
  std::string name;
  int segments = 3;      ///< joint angles are u.head(segments)
  int points = 0;        ///< continuation points (excluding the start point)
  double seconds = 0.0;  ///< in-process time of the whole case
  std::vector<Located> located;
  cont::Branch branch;   ///< last branch traced (for the branch-error measure)
};

inline void collect(const cont::Branch& b, CaseResult& r) {
  r.points += int(b.points.size()) - 1;
  for (const auto& sp : b.specialPoints) {
    Located l;
    l.label = cont::label(sp.type);  // AUTO's labels; a multiple BP as BP<m>
    if (sp.type == cont::SpecialPointType::BranchPoint && sp.multiplicity > 1) l.label += std::to_string(sp.multiplicity);
    if (sp.type == cont::SpecialPointType::Endpoint && sp.note == "start") continue;
    l.Fx = sp.lambda;
    r.located.push_back(l);
  }
}

/// Trivial branch of the pinned chain from λ0 towards lambdaEnd; BPs referenced to eq 17.
inline CaseResult trivialCase(const std::string& name, double L0, double lambda0, double lambdaEnd, const Settings& s) {
  CaseResult r;
  r.name = name;
  auto problem = pinned3(L0);
  const auto t0 = std::chrono::steady_clock::now();
  cont::Tracer tracer(problem, tracerOptions(s, std::min(lambda0, lambdaEnd), std::max(lambda0, lambdaEnd)));
  const auto dir = lambdaEnd < lambda0 ? cont::InitialDirection::decreasingLambda() : cont::InitialDirection::increasingLambda();
  r.branch = tracer.trace(Eigen::VectorXd::Zero(4), lambda0, dir);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  collect(r.branch, r);
  const double refs[2] = {analyticFx(L0, false), analyticFx(L0, true)};
  for (auto& l : r.located)
    if (l.label == "BP") {
      const double* best = std::min_element(refs, refs + 2, [&](double a, double b) { return std::abs(a - l.Fx) < std::abs(b - l.Fx); });
      l.reference = *best;
    }
  return r;
}

/// Switch at branch point `which` (0: U, 1: Z) of the main trivial branch and follow it to
/// |q_i| = 1.5 (a user joint limit: AUTO's UZSTOP qmax = 1.5) or Fx = −3.
inline CaseResult switchCase(const std::string& name, int which, const Settings& s) {
  CaseResult r;
  r.name = name;
  auto problem = pinned3(2.25, 1.5);
  cont::Tracer tracer(problem, tracerOptions(s, -3.0, 0.0));
  const cont::Branch trivial = tracer.trace(Eigen::VectorXd::Zero(4), 0.0, cont::InitialDirection::decreasingLambda());
  const auto bps = trivial.specialPointsOfType(cont::SpecialPointType::BranchPoint);
  if (int(bps.size()) <= which) return r;
  // AUTO's run restarts from the saved BP: time only the switch and the new branch.
  const auto t0 = std::chrono::steady_clock::now();
  Eigen::VectorXd direction;
  cont::bifurcatingDirection(problem, *bps[size_t(which)], direction);
  r.branch = cont::switchBranch(tracer, *bps[size_t(which)], direction, 1);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  collect(r.branch, r);
  return r;
}

/// Free end, L0 = 0.5, Fy = 0.01, Fx increasing from 0 (AUTO's I_up): the fold.
inline CaseResult foldCase(const std::string& name, const Settings& s) {
  CaseResult r;
  r.name = name;
  auto problem = free3(0.5, 0.01);
  const auto t0 = std::chrono::steady_clock::now();
  cont::Tracer tracer(problem, tracerOptions(s, -3.0, 3.0));
  r.branch = tracer.trace(Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda());
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  collect(r.branch, r);
  return r;
}

/// The names runCase knows, in their usual order.
inline const std::vector<std::string>& caseNames() {
  static const std::vector<std::string> names = {"A_triv", "A_U", "A_Z", "A_Ufine", "L_triv", "N_triv", "I_up"};
  return names;
}

/// Run a named case (A_triv, A_U, A_Z, A_Ufine, L_triv, N_triv, I_up); false for an unknown name.
inline bool runCase(const std::string& name, const Settings& base, CaseResult& out) {
  Settings s = base;
  if (name == "A_triv") out = trivialCase(name, 2.25, 0.0, -2.5, s);
  else if (name == "N_triv") out = trivialCase(name, 0.5, 0.0, 2.5, s);
  else if (name == "L_triv") out = trivialCase(name, 1.5, 0.5, -2.5, s);
  else if (name == "A_U") out = switchCase(name, 0, s);
  else if (name == "A_Z") out = switchCase(name, 1, s);
  else if (name == "A_Ufine") {
    s.initialStep = s.maxStep = 0.002;
    out = switchCase(name, 0, s);
  } else if (name == "I_up") {
    out = foldCase(name, s);
    for (auto& l : out.located)
      if (l.label == "LP") l.reference = 0.1777097421507;  // ref.py: independent Newton on the extended system
  } else {
    return false;
  }
  return true;
}

}  // namespace buckle::problems
