// Every equilibrium of a chain at one state of the controls, not only those connected to the
// start by continuation (issue 30; docs/mechanics.md, "All equilibria at one state").
//
// Equations: those of EquilibriumProblem at λ = 0 (∂E/∂q − JᵀF = 0 and the held coordinates),
// unknowns u = (q, r). Method:
//  - deflated Newton (Farrell, Birkisson, Funke 2015): Newton on G(u) = m(q) F(u) with the
//    deflation m(q) = Π_roots (1/‖q − q*‖^p + σ), from many starts (the straight shape, the
//    unloaded shape, given shapes, the sweep's equilibria for n = 3, random shapes within the joint
//    limits from a fixed seed), restarting from the same start after each new root until Newton
//    fails; every root polished by plain Newton on F and de-duplicated. No completeness proof:
//    the list holds the equilibria reached from the starts tried.
//  - n = 3 with the end held at (x, y), rotation free (Me = 0): also the one-dimensional sweep of
//    E(q1) along the inverse-kinematics branches (energy_landscape.h, eq 6–8), which is complete
//    up to its resolution, with the Morse-type count Σ(−1)^index checked against the topology of
//    the configuration set the sweep traces (loops and arcs cut by the joint limits).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "buckle/continuation/interrupt.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/mechanics/body_loads.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/end_condition.h"

namespace buckle::mechanics {

struct AllEquilibriaOptions {
  int randomStarts = 64;            ///< random shapes a·U(q_min, q_max) joint by joint, a ~ U(0, 1)
  /// Random smooth shapes: a total turn of up to ±2π spread over the joints, slowly modulated.
  int smoothStarts = 64;
  unsigned seed = 1;                ///< of the random shapes (std::mt19937)
  std::vector<Eigen::VectorXd> starts;  ///< further starting shapes (joint angles), e.g. branch points
  bool landscapeStarts = true;      ///< n = 3 held: the sweep's equilibria as starts too
  int maxRootsPerStart = 32;        ///< new roots sought from one start before the next
  int maxIterations = 80;           ///< Newton iterations per deflated run
  double deflationPower = 2.0;      ///< p of m(q)
  double deflationShift = 1.0;      ///< σ of m(q)
  /// A root is accepted when its residual, each row in the chain's own unit (torques k̄b̄²,
  /// positions b̄, angles 1: EquilibriumProblem::scales()), is at most this after polishing.
  double tolerance = 1e-10;
  /// Two roots are one when max |Δq_i| is at most this (radians, the angles' own unit).
  double duplicateTolerance = 1e-7;
  bool landscape = true;            ///< n = 3 held at (x, y), Me = 0: also the exact sweep
  int landscapeSamples = 4001;      ///< q1 grid of the sweep
  continuation::Interrupt interrupt;  ///< checked before every Newton run; what was found is kept
  /// The links' weight and point loads at this state (body_loads.h; their rates are ignored:
  /// BodyLoads::atParameter(0)): in the equations, the stability, Π (+ V, eq B1) and the n = 3
  /// sweep (of E + V along the configuration curve).
  BodyLoads body;

  /// Empty when valid for a chain of `segments`, else what is wrong, the field named by its path.
  std::string validate(int segments, const std::string& prefix = "") const;
  bool IsValid(int segments, std::string* why) const {
    return continuation::reportValidity(validate(segments), why);
  }
};

struct FoundEquilibrium {
  Eigen::VectorXd q;
  Eigen::VectorXd reactions;        ///< of the held coordinates, in (x, y, φ) order
  Wrench wrench = Wrench::Zero();   ///< the whole end wrench: given loads and reactions
  int index = -1;                   ///< negative eigenvalues of K_q − K_g on ker J_h
  int zeroEigenvalues = 0;          ///< within the stability test's tolerance (degenerate)
  bool stable = false;
  double potential = 0.0;           ///< Π = E − Σ_loaded F_c p_c (+ V of the body loads)
  Pose pose = Pose::Zero();
  std::string shape;                ///< shapeName(q)
  double accuracy = 0.0;            ///< ‖F‖∞ in the chain's units after polishing
  bool byDeflation = false;         ///< reached by deflated Newton
  bool bySweep = false;             ///< a stationary point of the n = 3 sweep
};

/// Σ(−1)^index over the equilibria against the value the configuration set's topology implies.
struct MorseCheck {
  bool applies = false;             ///< false: no relation known here (only `sum` is reported)
  int sum = 0;                      ///< Σ(−1)^index over the equilibria found
  int expected = 0;                 ///< χ of the set less its arc ends where E decreases outward
  int loops = 0, arcs = 0;          ///< closed curves and arcs of the configuration set
  std::string basis;                ///< what `expected` rests on, or why it does not apply
  bool holds() const { return applies && sum == expected; }
};

struct AllEquilibria {
  EndCondition endCondition;        ///< the state of the controls searched
  std::vector<FoundEquilibrium> equilibria;  ///< within the joint limits, ascending Π
  std::string method;               ///< "deflated Newton" or "deflated Newton + 1-D sweep"
  std::string guarantee;            ///< what the list is guaranteed to hold
  int starts = 0;                   ///< starting shapes tried
  int newtonRuns = 0;               ///< deflated Newton runs
  int newtonFailures = 0;           ///< runs that did not converge (each start ends with one)
  int duplicates = 0;               ///< converged runs that polished onto a known root
  int outsideLimits = 0;            ///< roots in the model's domain but beyond a joint limit
  int sweepCount = -1;              ///< equilibria of the sweep (−1: not applicable)
  int sweepRefined = 0;             ///< of them, found by refining a cell or a run's end
  int sweepUnresolved = 0;          ///< sweep points plain Newton could not polish (or beyond a limit)
  int deflationOnly = 0, sweepOnly = 0;  ///< found by one method alone (sweep applies)
  MorseCheck morse;
  bool interrupted = false;
  std::string stopReason;           ///< the interrupt's description when interrupted
  double seconds = 0.0;
};

/// Every equilibrium within the joint limits of `chain` under `end` (loads and / or held
/// coordinates, the values as given). Throws std::invalid_argument naming a bad option.
AllEquilibria allEquilibria(const Chain& chain, const EndCondition& end, const AllEquilibriaOptions& options = {});

/// True when the n = 3 sweep applies: three segments, x and y held, φ loaded with Me = 0.
bool sweepApplies(const Chain& chain, const EndCondition& end);

}  // namespace buckle::mechanics
