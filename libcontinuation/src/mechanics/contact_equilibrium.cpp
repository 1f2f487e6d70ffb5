// Constrained equilibria, stability and stiffness of the chain with joints locked at their
// limits and vertices held on the base wall or on other links (contact.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/wall_constraint.h"

namespace buckle::mechanics {

using continuation::ConstVectorRef;
using continuation::Factorization;

ConstrainedEquilibrium solveConstrainedEquilibrium(const EquilibriumProblem& base, const ContactSet& locked,
                                                   ConstVectorRef u0, double lambda, double tolerance,
                                                   int maxIterations) {
  ConstrainedEquilibrium out;
  const int N = base.dimension();
  if (u0.size() != N)
    throw std::invalid_argument("solveConstrainedEquilibrium: u0 must have " + std::to_string(N) + " entries, got " +
                                std::to_string(u0.size()));
  if (!std::isfinite(lambda)) throw std::invalid_argument("solveConstrainedEquilibrium: lambda must be finite");
  const ContactProblem problem(base, locked);
  const continuation::BoundProblem bound(problem);  // this solve's workspace
  const continuation::ProblemScales s = problem.scales();
  const std::unique_ptr<continuation::BorderedSolver> solver = bound.makeStructuredSolver();
  const int D = problem.dimension();  // N + the wall forces
  Vector start = u0;
  for (const LockedJoint& l : locked.joints()) start[l.joint] = limitAngle(base.chain(), l.joint, l.side);
  Vector u = problem.withWallForces(bound.workspace(), start, lambda), F(D), trial(D), b = Vector::Zero(D + 1),
         dx(D + 1), c = Vector::Zero(D + 1);
  c[D] = 1.0;  // fixed λ: the border row e_λ
  if (!u.allFinite()) u.tail(D - N).setZero();  // no free row to read the forces from: start at 0
  auto scaledNorm = [&](const Vector& r) { return r.cwiseQuotient(s.residuals).cwiseAbs().maxCoeff(); };
  if (!bound.residual(u, lambda, F)) {
    out.message = "the start is outside the model's domain";
    out.u = u.head(N);
    return out;
  }
  double norm = scaledNorm(F);
  // The best iterate is kept: near a fold of the constrained branch (a contact that changes where
  // the load turns back) the Jacobian at fixed λ is nearly singular and the halved steps, which may
  // let the residual grow twofold, can wander off an already accurate start.
  Vector best = u;
  double bestNorm = norm;
  for (out.iterations = 0; out.iterations < maxIterations && !(norm <= tolerance); ++out.iterations) {
    if (solver->factor(u, lambda, c) != Factorization::Regular) {
      out.message = "singular constrained Jacobian";
      break;
    }
    b.head(D) = F;
    if (!solver->solve(b, dx)) {
      out.message = "singular constrained Jacobian";
      break;
    }
    // Newton step, halved while it leaves the domain or increases the residual.
    double t = 1.0, trialNorm = std::numeric_limits<double>::infinity();
    for (int h = 0; h < 30; ++h, t *= 0.5) {
      trial = u - t * dx.head(D);
      if (bound.residual(trial, lambda, F) && (trialNorm = scaledNorm(F)) < std::max(norm, tolerance) * 2.0) break;
      trialNorm = std::numeric_limits<double>::infinity();
    }
    if (!std::isfinite(trialNorm)) {
      out.message = "the Newton step leaves the model's domain";
      break;
    }
    u = trial;
    norm = trialNorm;
    if (norm < bestNorm) {
      best = u;
      bestNorm = norm;
    }
  }
  if (bestNorm < norm) u = best;
  norm = bound.residual(u, lambda, F) ? scaledNorm(F) : std::numeric_limits<double>::infinity();
  out.u = u.head(N);
  out.residual = norm;
  out.converged = norm <= tolerance;
  if (!out.converged && out.message.empty()) {
    char reached[96];
    std::snprintf(reached, sizeof reached, " (scaled residual %.3g, tolerance %.3g)", norm, tolerance);
    out.message = "no convergence in " + std::to_string(maxIterations) + " iterations" + reached;
  }
  out.torques = Vector::Zero(base.segments());
  out.wallForces = u.segment(N, locked.wallCount());
  out.selfForces = u.tail(locked.selfCount());
  out.minCompression = D > N ? u.tail(D - N).minCoeff() : std::numeric_limits<double>::infinity();
  for (const LockedJoint& l : locked.joints()) {
    out.torques[l.joint] = problem.contactTorque(bound.workspace(), u, lambda, l.joint);
    out.minCompression = std::min(out.minCompression, -double(int(l.side)) * out.torques[l.joint]);
  }
  return out;
}

continuation::StabilityInfo constrainedStability(const EquilibriumProblem& base, const ContactSet& locked,
                                                 ConstVectorRef u, double lambda, int lowestCount) {
  const ContactProblem problem(base, locked);
  const continuation::BoundProblem bound(problem);  // this solve's workspace
  continuation::StabilityInfo info;
  const Vector full =
      u.size() == problem.dimension() ? Vector(u) : problem.withWallForces(bound.workspace(), u, lambda);
  if (!bound.stability(full, lambda, lowestCount, info)) info.negative = -1;
  return info;
}

void wallConstraintTerms(const Chain& chain, ConstVectorRef q, const ContactSet& contacts, ConstVectorRef wallForces,
                         const char* caller, MatrixRef rows, Vector& generator) {
  const int n = chain.size(), w = contacts.wallCount();
  if (wallForces.size() != w)
    throw std::invalid_argument(std::string(caller) + ": one wall force per vertex on the wall (" + std::to_string(w) +
                                "), got " + std::to_string(wallForces.size()));
  if (w == 0) return;
  if (generator.size() != n) generator = Vector::Zero(n);
  const Eigen::Matrix2Xd P = jointPositions(chain, q);
  Vector gradient(n), vertexGenerator(n);
  for (int k = 0; k < w; ++k) {
    const WallVertex& v = contacts.wall()[size_t(k)];
    wallVertexDerivatives(P, wallVertexPoint(chain, q, P, v), v, gradient, vertexGenerator);
    rows.row(k) = gradient.transpose();
    generator += wallForces[k] * vertexGenerator;
  }
}

void selfConstraintTerms(const Chain& chain, ConstVectorRef q, const ContactSet& contacts, ConstVectorRef selfForces,
                         const char* caller, MatrixRef rows, Vector& generator, Matrix& columns, Vector& signs) {
  const int n = chain.size(), s = contacts.selfCount();
  if (selfForces.size() != s)
    throw std::invalid_argument(std::string(caller) + ": one force per self contact (" + std::to_string(s) + "), got " +
                                std::to_string(selfForces.size()));
  if (s == 0) return;
  if (generator.size() != n) generator = Vector::Zero(n);
  columns.resize(n, 2 * s);
  signs.resize(2 * s);
  const Eigen::Matrix2Xd P = jointPositions(chain, q);
  Vector gradient(n), gapGenerator(n), c(n), w(n);
  for (int k = 0; k < s; ++k) {
    const SelfContact& contact = contacts.self()[size_t(k)];
    selfContactDerivatives(P, contact, selfContactGap(chain, q, P, contact), gradient, gapGenerator, c, w);
    rows.row(k) = gradient.transpose();
    generator += selfForces[k] * gapGenerator;
    const double sign = selfCouplingColumns(c, w, selfForces[k], columns.middleCols(2 * k, 2));
    signs[2 * k] = -sign;
    signs[2 * k + 1] = sign;
  }
}

CartesianStiffness lockedLoadedStiffness(const Chain& chain, ConstVectorRef q, const Wrench& F, const EndCondition& end,
                                         const ContactSet& locked, const StiffnessOptions& options,
                                         ConstVectorRef wallForces) {
  if (locked.empty()) return loadedStiffness(chain, q, F, end, options);
  locked.check(chain.size());
  const int n = chain.size(), w = locked.wallCount();
  Matrix E = Matrix::Zero(locked.count() + w, n);  // δq_i = 0 at the locked joints, δx_v = 0 on the wall
  for (int k = 0; k < locked.count(); ++k) E(k, locked.joints()[size_t(k)].joint) = 1.0;
  // The wall forces' −Σ μ_v ∂²x_v enters as a body-load generator γ (the Hessian's generator is
  // h − γ, stiffness.h).
  StiffnessOptions o = options;
  wallConstraintTerms(chain, q, locked, wallForces, "lockedLoadedStiffness", E.bottomRows(w), o.bodyGenerator);
  return loadedStiffness(chain, q, F, end.isHeld(EndCoordinate::Phi), E, o);
}

EventStart polishEventStart(const EquilibriumProblem& base, const ContactSet& locked,
                            const continuation::SpecialPoint& at, continuation::Tracer& tracer,
                            continuation::ConstVectorRef direction) {
  const continuation::TracerOptions& o = tracer.options();
  const ConstrainedEquilibrium fixed =
      solveConstrainedEquilibrium(base, locked, at.u, at.lambda, std::max(o.location.newtonTolerance, 1e-12));
  const int N = base.dimension(), D = tracer.problem().dimension();
  EventStart start;
  start.u.resize(D);
  start.u.head(N) = fixed.u;
  start.u.segment(N, locked.wallCount()) = fixed.wallForces;
  start.u.tail(locked.selfCount()) = fixed.selfForces;
  start.lambda = at.lambda;
  start.polished = fixed.converged || fixed.residual <= o.corrector.tolerance;
  if (start.polished) return start;
  if (direction.size() != D + 1 || !(direction.norm() > 0.0)) {
    start.message = "the equilibrium could not be polished (" + fixed.message + ")";
    return start;
  }
  // from the polish's best iterate, in the corrector's (scaled) units
  continuation::ContinuationPoint p;
  p.u = start.u;
  p.lambda = start.lambda;
  tracer.units().toScaled(p);
  continuation::Vector x0(D + 1), x(D + 1);
  x0 << p.u, p.lambda;
  const continuation::Vector t = tracer.units().directionToScaled(direction).normalized();
  const continuation::CorrectorSummary across = tracer.corrector().correct(x0, t, x);
  if (!across.converged || !x.allFinite()) {
    start.message = "the equilibrium could not be polished (" + fixed.message + "; across the branch: " +
                    (across.message.empty() ? std::string(across.flagName) : across.message) + ")";
    return start;
  }
  p.u = x.head(D);
  p.lambda = x[D];
  tracer.units().toUser(p);
  start.u = p.u;
  start.lambda = p.lambda;
  start.polished = start.acrossBranch = true;
  return start;
}

}  // namespace buckle::mechanics
