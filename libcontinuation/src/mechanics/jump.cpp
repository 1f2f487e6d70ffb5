#include "buckle/mechanics/jump.h"

#include "buckle/continuation/scaled_problem.h"
#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/wall_contact.h"
#include "buckle/mechanics/wall_landing.h"
#include "rest_point.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <Eigen/QR>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace buckle::mechanics {

namespace cont = continuation;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Full unknowns (q, reactions) from q or u.
Vector fullUnknowns(EquilibriumProblem& problem, ConstVectorRef u, double lambda) {
  const int n = problem.segments();
  if (u.size() == problem.dimension()) return u;
  if (u.size() == n) return problem.initialGuess(u, lambda);
  throw std::invalid_argument("u must hold the n joint angles or all " + std::to_string(problem.dimension()) +
                              " unknowns (got " + std::to_string(u.size()) + ")");
}

/// δ of the direction rule (jump.h, step 1): eigenvalues within δ of the lowest μ are one
/// multiple eigenvalue. Relative to the operator's scale (the chain's k̄b̄², the RMS eigenvalue
/// ‖H‖_F/√n, |μ|): the same δ in any units, on both routes.
double clusterWidth(double typicalScale, double rmsEigenvalue, double mu) {
  return 1e-8 * std::max({typicalScale, rmsEigenvalue, std::abs(mu)});
}

EndCondition frozenEnd(const EquilibriumProblem& problem, double lambda) {
  EndCondition e = problem.endCondition();
  e.value = problem.prescribed(lambda);
  return e;
}


/// unstableDirection() through the chain structure (chain_structure.h), O(n): the smallest
/// eigenvalue μ of ZᵀHZ from the Sturm counts (lowestEigenvalues), then inverse iteration on the
/// KKT system [[H − σI, Q], [Qᵀ, 0]] (Q the orthonormalised held rows, H − σI = U(T − σM)Uᵀ the
/// chain structure of K_q − σI) at σ = μ − δ: its solution lies in ker J_h and each iteration
/// shrinks the other eigen-components by δ / (μ_k − σ). δ = 1e-8 of the operator's scale: far
/// enough from μ for the solves to stay accurate to rounding in the wanted direction, close
/// enough for two or three iterations. Started from the reference vector z (jump.h, step 1), the
/// iteration keeps its components in the eigenspace of a multiple μ (the straight chain of
/// identical bistable segments at zero load, H = κI on ker J_y) unchanged relative to each
/// other: it returns the normalised projection of z onto that eigenspace, the rule's direction.
UnstableDirection structuredUnstableDirection(EquilibriumProblem& problem, const Vector& u, double lambda) {
  UnstableDirection d;
  const int n = problem.segments();
  ChainStructure ws(n), shifted(n);
  Matrix J(3, n);
  if (!problem.assembleStructure(*problem.createWorkspace(), u, lambda, ws, J)) return d;
  ws.typicalScale = problem.stiffnessUnit() * problem.lengthUnit() * problem.lengthUnit();
  const std::vector<int> held = problem.endCondition().heldIndices();
  Matrix C(held.size(), n);
  for (size_t k = 0; k < held.size(); ++k) C.row(Eigen::Index(k)) = J.row(held[k]);
  const int r = setConstraints(ws, C);
  if (r >= n) return d;
  Vector lowest(1);
  if (lowestEigenvalues(ws, r > 0, 1, lowest) < 1 || !std::isfinite(lowest[0])) return d;
  const double mu = lowest[0];
  const double sigma = mu - clusterWidth(ws.typicalScale, ws.frobeniusH / std::sqrt(double(n)), mu);
  Vector kappa = ws.kappa.array() - sigma;
  assemble(kappa, ws.h, shifted);
  const Matrix Qt = ws.Q.leftCols(r).transpose();
  // the rule's reference vector: every component present (no eigenvector of the chain is
  // orthogonal to it generically)
  Vector z = directionReference(n), next(n), y(r), zeroR = Vector::Zero(r);
  if (r > 0) z -= Qt.transpose() * (Qt * z);
  if (!(z.norm() > 0.0)) return d;
  z.normalize();
  for (int it = 0; it < 8; ++it) {
    const bool ok = r > 0 ? solveKKT(shifted, Qt, z, zeroR, next, y) : solve(shifted, z, next);
    if (!ok || !(next.norm() > 0.0)) return d;
    next.normalize();
    if (next.dot(z) < 0.0) next = -next;
    const double change = (next - z).cwiseAbs().maxCoeff();
    z = next;
    if (change <= 1e-14) break;
  }
  d.eigenvalue = mu;
  d.direction = z;
  d.valid = z.allFinite();
  return d;
}

/// The hand-over's basin test at the flow's state q (jump.h, step 2); on success `landing` is
/// the polished equilibrium q* it certified.
bool basinTest(EquilibriumProblem& problem, DynamicsModel& model, ConstVectorRef q, double lambda,
               const continuation::CorrectorOptions& polish, PolishResult& landing) {
  const int n = problem.segments();
  // positive definite on ker J_h: O(n) Sturm counts (no eigenvalues wanted), one workspace for
  // the test's three points
  const cont::BoundProblem bound(problem);
  auto definite = [&](const Vector& u) {
    continuation::StabilityInfo s;
    return bound.stability(u, lambda, 0, s) && s.valid() && s.stable();
  };
  if (!definite(problem.initialGuess(q, lambda))) return false;
  PolishResult p = polishEquilibrium(problem, q, lambda, polish);
  if (!p.converged || !definite(p.u)) return false;
  const Vector qStar = p.u.head(n);
  if (!definite(problem.initialGuess(0.5 * (q + qStar), lambda))) return false;
  if (!(model.potential(qStar) <= model.potential(q))) return false;
  landing = std::move(p);
  return true;
}

std::string describeContacts(const std::vector<int>& sides, const Vector& torques) {
  std::ostringstream os;
  for (size_t i = 0; i < sides.size(); ++i)
    if (sides[i] != 0)
      os << (os.str().empty() ? "" : ", ") << "joint " << i + 1 << (sides[i] > 0 ? " upper" : " lower")
         << " (contact torque " << torques[Eigen::Index(i)] << ")";
  return os.str();
}

std::string describe(const continuation::StabilityInfo& s) {
  std::ostringstream os;
  if (!s.valid()) return "stability not computed";
  os << (s.stable() ? "stable" : "not stable") << " (" << s.negative << " negative, " << s.zero
     << " zero eigenvalues, smallest " << s.smallest << ")";
  return os.str();
}

}  // namespace

IntegrationOptions jumpIntegrationDefaults(int segments) {
  IntegrationOptions o;
  if (segments >= 10) o.stepper = StepperKind::Rosenbrock4;
  // dense Rosenbrock4 costs O(n³) per step: long chains take the O(n) structured solve, and
  // (hand-over to Newton: the integration decides the basin, jump.h) the basin's tolerance
  // (and Dormand–Prince while the flow is not stiff: StructuredSwitching, jump.h)
  if (segments > kStructuredJumpFrom) {
    o.stepper = StepperKind::StructuredSwitching;
    o.absoluteTolerance = o.relativeTolerance = kLongJumpTolerance;
  }
  return o;
}

continuation::CorrectorOptions defaultPolishOptions() {
  continuation::CorrectorOptions o;
  o.tolerance = 1e-12;
  o.maxIterations = 50;
  o.lineSearch = true;
  return o;
}

PolishResult polishEquilibrium(EquilibriumProblem& problem, ConstVectorRef q, double lambda,
                               const continuation::CorrectorOptions& options) {
  PolishResult result;
  const int N = problem.dimension();
  const Vector u0 = fullUnknowns(problem, q, lambda);
  result.u.resize(N);
  // The core's KINSOL corrector in its fixed-parameter mode: exact Jacobian of the
  // EquilibriumProblem (the KKT matrix), so convergence from a rest point is quadratic. In the
  // problem's scaled variables (scaled_problem.h): the tolerance is relative, in any units.
  const continuation::UnitScaling units(problem.scales());
  const continuation::BoundScaledProblem scaledProblem(continuation::BoundProblem(problem), units);
  const continuation::BoundProblem& scaled = scaledProblem.bound();
  // Long chains: the chain's O(n) bordered solver (chain_solver.h) instead of KINSOL's dense LU.
  const std::unique_ptr<continuation::BorderedSolver> structured =
      problem.segments() > kSmallDense ? scaled.makeStructuredSolver() : nullptr;
  continuation::Corrector corrector(scaled, options, structured.get());
  const Vector& D = units.scales().unknowns;
  const continuation::CorrectorSummary summary =
      corrector.solveAtFixedParameter(u0.cwiseQuotient(D), lambda / units.parameter(), result.u);
  result.u = result.u.cwiseProduct(D);
  result.converged = summary.converged;
  result.iterations = summary.iterations;
  result.message = summary.flagName;
  if (!summary.message.empty()) result.message += ": " + summary.message;
  Vector F(N);
  result.residual = cont::BoundProblem(problem).residual(result.u, lambda, F) ? F.cwiseAbs().maxCoeff()
                                                                              : std::numeric_limits<double>::infinity();
  return result;
}

Vector directionReference(int n) {
  Vector z(n);
  for (int i = 0; i < n; ++i) z[i] = 1.0 + 0.5 * std::sin(1.0 + 2.399963 * i);
  return z;
}

UnstableDirection unstableDirection(EquilibriumProblem& problem, ConstVectorRef u, double lambda, DirectionRoute route) {
  UnstableDirection d;
  const Vector uFull = fullUnknowns(problem, u, lambda);
  // long chains: O(n) through the chain structure instead of the dense O(n³) eigen-solve
  const bool structured =
      route == DirectionRoute::Structured || (route == DirectionRoute::Automatic && problem.segments() > kSmallDense);
  if (structured) return structuredUnstableDirection(problem, uFull, lambda);
  Matrix H, C;
  if (!cont::BoundProblem(problem).stabilityOperator(uFull, lambda, H, C)) return d;
  const Eigen::Index n = H.rows();
  // Z: orthonormal basis of ker J_h (the last n − rank columns of Q in J_hᵀ = QR), as in the
  // core's projectedInertia(); the reduced Hessian Zᵀ(K_q − K_g)Z is then the stability operator.
  Matrix Z;
  if (C.rows() == 0) {
    Z = Matrix::Identity(n, n);
  } else {
    Eigen::ColPivHouseholderQR<Matrix> qr(C.transpose());
    const Matrix Q = qr.householderQ() * Matrix::Identity(n, n);
    Z = Q.rightCols(n - qr.rank());
  }
  if (Z.cols() == 0) return d;
  const Matrix reduced = Z.transpose() * H * Z;
  Eigen::SelfAdjointEigenSolver<Matrix> es(0.5 * (reduced + reduced.transpose()));
  if (es.info() != Eigen::Success) return d;
  d.eigenvalue = es.eigenvalues()[0];
  // The rule (jump.h, step 1): the reference vector projected onto the eigenspace of the
  // eigenvalues within δ of the lowest (for a simple one: its eigenvector, up to sign).
  const double scale = problem.stiffnessUnit() * problem.lengthUnit() * problem.lengthUnit();
  const double delta = clusterWidth(scale, H.norm() / std::sqrt(double(n)), d.eigenvalue);
  Eigen::Index k = 1;
  while (k < es.eigenvalues().size() && es.eigenvalues()[k] - d.eigenvalue <= delta) ++k;
  const Matrix E = Z * es.eigenvectors().leftCols(k);  // orthonormal basis of the eigenspace
  d.direction = E * (E.transpose() * directionReference(int(n)));
  // (a reference orthogonal to the eigenspace is not generic; then its first basis vector)
  if (!(d.direction.norm() > 1e-8 * std::sqrt(double(n)))) d.direction = E.col(0);
  d.direction.normalize();
  d.valid = true;
  return d;
}

std::string JumpOptions::validate(const EquilibriumProblem& problem, const std::string& prefix) const {
  if (std::string why; !scene.IsValid(problem.chain(), &why)) return prefix + "scene: " + why;
  return cont::firstProblem(
      {integration.validate(prefix + "integration."), polish.validate(prefix + "polish."),
       cont::require(std::isfinite(perturbation) && perturbation >= 0.0, prefix, "perturbation", "must be >= 0"),
       cont::require(direction.size() == 0 || direction.size() == problem.segments(), prefix, "direction",
                     "must be empty or have one entry per joint"),
       cont::require(direction.size() == 0 || (direction.allFinite() && direction.norm() > 0.0), prefix, "direction",
                     "must be finite and non-zero"),
       cont::require(std::isfinite(sameStateTolerance) && sameStateTolerance > 0.0, prefix, "sameStateTolerance",
                     "must be > 0")});
}

JumpResult simulateJump(EquilibriumProblem& problem, ConstVectorRef u, double lambda, const JumpOptions& options) {
  std::string why;
  if (!options.IsValid(problem, &why)) throw std::invalid_argument("JumpOptions: " + why);
  if (!std::isfinite(lambda)) throw std::invalid_argument("lambda must be finite");
  const int n = problem.segments();
  JumpResult result;
  result.lambda = lambda;
  result.prescribed = problem.prescribed(lambda);
  result.from = fullUnknowns(problem, u, lambda);
  const Vector qFrom = result.from.head(n);
  cont::BoundProblem(problem).stability(result.from, lambda, 3, result.stabilityFrom);

  const EndCondition end = frozenEnd(problem, lambda);
  // the chain with its control inputs (free lengths) and its body loads where it is released
  DynamicsScene scene = options.scene;
  if (problem.bodyLoads().active()) scene.body = std::make_shared<const BodyLoads>(problem.bodyLoads().atParameter(lambda));
  std::unique_ptr<DynamicsModel> model =
      makeDynamicsModel(problem.controlled() ? problem.chainAt(lambda) : problem.chain(), end, scene, qFrom);
  result.potentialFrom = model->potential(qFrom);

  // 1. The perturbation direction: the caller's, or the softest mode of the stability operator.
  Vector v;
  if (options.direction.size() == n) {
    v = options.direction.normalized();
    result.directionEigenvalue = kNaN;
  } else {
    const UnstableDirection ud = unstableDirection(problem, result.from, lambda);
    if (!ud.valid) {
      result.message = "the stability operator could not be evaluated at the start (outside the domain?)";
      return result;
    }
    v = ud.direction;
    result.directionEigenvalue = ud.eigenvalue;
  }
  // A start on a joint limit (a fold of a branch traced in contact, contact.h) starts in
  // contact: the joint stays locked until its contact torque would pull (dynamics.h).
  std::vector<int> startSides(size_t(n), 0);
  for (int i = 0; i < n; ++i) {
    const double hi = problem.chain().upperLimits()[i], lo = problem.chain().lowerLimits()[i];
    if (std::abs(qFrom[i] - hi) <= 1e-12 * std::max(1.0, std::abs(hi))) startSides[size_t(i)] = 1;
    else if (std::abs(qFrom[i] - lo) <= 1e-12 * std::max(1.0, std::abs(lo))) startSides[size_t(i)] = -1;
    if (startSides[size_t(i)] != 0) v[i] = 0.0;
  }
  if (anyContact(startSides)) {
    model->setContacts(startSides);
    if (v.norm() > 0.0) v.normalize();
  }
  // Sign: the one that lowers Π. At an unstable equilibrium both do to second order; at a fold
  // the quadratic term vanishes and the cubic term (the fold's normal form) picks the side.
  Vector qStart = qFrom;
  if (options.perturbation > 0.0) {
    Vector qPlus = qFrom + options.perturbation * v, qMinus = qFrom - options.perturbation * v;
    model->projectOntoConstraints(qPlus);
    model->projectOntoConstraints(qMinus);
    const bool plusIn = model->withinLimits(qPlus), minusIn = model->withinLimits(qMinus);
    const double piPlus = plusIn ? model->potential(qPlus) : std::numeric_limits<double>::infinity();
    const double piMinus = minusIn ? model->potential(qMinus) : std::numeric_limits<double>::infinity();
    if (!plusIn && !minusIn) {
      result.message = "both perturbed starts leave the joint limits; use a smaller perturbation";
      return result;
    }
    if (piMinus < piPlus) {
      v = -v;
      qStart = qMinus;
    } else {
      qStart = qPlus;
    }
  } else {
    model->projectOntoConstraints(qStart);
  }
  result.direction = v;

  // 2. Release: dynamics at frozen loads / targets until rest, or (gradient flow) until the
  // basin test hands over to Newton.
  IntegrationOptions integration = options.integration;
  const bool handover = model->kind() == DynamicsKind::GradientFlow &&
                        (options.handover == Handover::Always ||
                         (options.handover == Handover::Automatic && n > kStructuredJumpFrom && !options.self));
  PolishResult certified;
  if (handover)
    integration.settled = [&](ConstVectorRef q) {
      ++result.basinTests;
      return basinTest(problem, *model, q, lambda, options.polish, certified);
    };
  integration.wall = integration.wall || options.wall;
  integration.self = integration.self || options.self;
  result.dynamics = simulate(*model, qStart, Vector::Zero(n), integration);
  const DynamicsResult& dyn = result.dynamics;
  noteWallReached(*model, dyn, result.reachedWall, result.wallVertex, result.wallGap);
  result.stopReason = dyn.reason;
  result.duration = dyn.time;
  result.steps = dyn.steps;
  result.rejectedSteps = dyn.rejectedSteps;
  result.wallSeconds = dyn.wallSeconds;
  result.restPoint = dyn.q;

  // 3. Polish at fixed λ (with the joints in contact fixed) and check stability.
  const RestPoint rest = polishRestPoint(problem, model->chain(), dyn, lambda, options.polish, options.self, &certified);
  const PolishResult& polished = rest.polished;
  result.to = polished.u;
  result.polishConverged = polished.converged;
  result.polishIterations = polished.iterations;
  result.residual = polished.residual;
  const Vector qTo = result.to.head(n);
  result.polishShift = (qTo - dyn.q).cwiseAbs().maxCoeff();
  result.distance = (qTo - qFrom).cwiseAbs().maxCoeff();
  result.potentialTo = model->potential(qTo);
  result.energyReleased = result.potentialFrom - result.potentialTo;
  result.stabilityTo = rest.stability;
  result.stable = rest.stable;
  result.contactSides = rest.sides;
  result.contactTorques = rest.torques;
  result.wallContacts = rest.wall;
  result.wallForces = rest.wallForces;
  result.selfContacts = rest.self;
  result.selfForces = rest.selfForces;

  std::ostringstream os;
  os << "integration stopped: " << dyn.message << "; " << (!rest.wall.empty() ? "landing on the wall: " : "polish: ")
     << (polished.converged ? "converged" : "not converged") << " (" << polished.message << ", residual "
     << polished.residual << "); landing " << describe(result.stabilityTo);
  if (anyContact(rest.sides)) os << " with the joints locked; in contact: " << describeContacts(rest.sides, rest.torques);
  const std::string behind = polished.converged ? behindWall(model->chain(), qTo, problem.lengthUnit()) : "";
  os << behind;
  result.behindWall = !behind.empty();
  const bool arrived = arrivedAt(dyn, rest);
  if (!arrived) {
    os << "; no rest point reached";
  } else if (polished.converged && result.distance <= options.sameStateTolerance) {
    os << "; the chain came back to the start (no jump)";
  }
  result.message = os.str();
  result.success = arrived && polished.converged && result.stable && result.distance > options.sameStateTolerance;
  return result;
}

std::string SuddenLoadOptions::validate(const Chain& chain, const std::string& prefix) const {
  if (std::string why; !scene.IsValid(chain, &why)) return prefix + "scene: " + why;
  return cont::firstProblem(
      {integration.validate(prefix + "integration."), polish.validate(prefix + "polish."),
       cont::require(std::isfinite(sameStateTolerance) && sameStateTolerance > 0.0, prefix, "sameStateTolerance",
                     "must be > 0")});
}

const char* toString(LowerPotential lower) {
  switch (lower) {
    case LowerPotential::Dynamic: return "dynamic";
    case LowerPotential::Static: return "static";
    case LowerPotential::Equal: return "equal";
  }
  return "unknown";
}

SuddenLoadResult simulateSuddenLoad(const Chain& chain, const EndCondition& loaded, ConstVectorRef qUnloaded,
                                    ConstVectorRef qStatic, const SuddenLoadOptions& options) {
  std::string why;
  if (!options.IsValid(chain, &why)) throw std::invalid_argument("SuddenLoadOptions: " + why);
  const int n = chain.size();
  if (qUnloaded.size() != n) throw std::invalid_argument("qUnloaded must have one entry per joint");
  if (qStatic.size() != 0 && qStatic.size() != n) throw std::invalid_argument("qStatic must be empty or have one entry per joint");

  SuddenLoadResult result;
  // the rest shape is an equilibrium of the loaded chain with the scene's body loads, if any
  EquilibriumProblem problem(chain, loaded, Eigen::Vector3d::Zero(), {}, {},
                             options.scene.body ? *options.scene.body : BodyLoads());
  std::unique_ptr<DynamicsModel> model = makeDynamicsModel(chain, loaded, options.scene, qUnloaded);
  result.inertial = model->kind() == DynamicsKind::Inertial;
  // A held coordinate whose target differs from the unloaded shape is imposed at once: the start
  // is the nearest configuration (minimum-norm Gauss–Newton) that satisfies it.
  result.start = qUnloaded;
  if (!model->projectOntoConstraints(result.start)) {
    result.message = "the held end coordinates cannot be reached from the unloaded shape";
    return result;
  }

  IntegrationOptions integration = options.integration;
  integration.wall = integration.wall || options.wall;
  integration.self = integration.self || options.self;
  result.dynamics = simulate(*model, result.start, Vector::Zero(n), integration);
  const DynamicsResult& dyn = result.dynamics;
  double gap = 0.0;
  noteWallReached(*model, dyn, result.reachedWall, result.wallVertex, gap);
  for (const TrajectorySample& s : dyn.trajectory) {
    result.peakKinetic = std::max(result.peakKinetic, s.kinetic);
    result.maxExcursion = std::max(result.maxExcursion, (s.q - result.start).cwiseAbs().maxCoeff());
  }

  const RestPoint restPoint = polishRestPoint(problem, model->chain(), dyn, 0.0, options.polish, options.self);
  const PolishResult& polished = restPoint.polished;
  result.restUnknowns = polished.u;
  result.rest = polished.u.head(n);
  result.residual = polished.residual;
  result.polishConverged = polished.converged;
  result.stability = restPoint.stability;
  result.stable = restPoint.stable;
  result.contactSides = restPoint.sides;
  result.contactTorques = restPoint.torques;
  result.wallContacts = restPoint.wall;
  result.wallForces = restPoint.wallForces;
  result.selfContacts = restPoint.self;
  result.selfForces = restPoint.selfForces;
  result.potentialDynamic = model->potential(result.rest);

  std::ostringstream os;
  os << (result.inertial ? "inertial" : "gradient-flow") << " response; integration stopped: " << dyn.message
     << "; polish: " << (polished.converged ? "converged" : "not converged") << " (" << polished.message << ", residual " << polished.residual
     << "); rest shape " << describe(result.stability);
  if (anyContact(restPoint.sides))
    os << " with the joints locked; in contact: " << describeContacts(restPoint.sides, restPoint.torques);
  const std::string behind = polished.converged ? behindWall(model->chain(), result.rest, problem.lengthUnit()) : "";
  os << behind;
  if (qStatic.size() == n) {
    result.compared = true;
    result.staticShape = qStatic;
    result.potentialStatic = model->potential(qStatic);
    result.maxDifference = (result.rest - qStatic).cwiseAbs().maxCoeff();
    result.differs = result.maxDifference > options.sameStateTolerance;
    // the chain's energy unit k̄b̄², not 1: in any units the tie is a tie to rounding
    const double scale =
        std::max({model->torqueUnit(), std::abs(result.potentialDynamic), std::abs(result.potentialStatic)});
    if (std::abs(result.potentialDynamic - result.potentialStatic) <= 1e-12 * scale) result.lower = LowerPotential::Equal;
    else result.lower = result.potentialDynamic < result.potentialStatic ? LowerPotential::Dynamic : LowerPotential::Static;
    os << "; vs quasi-static: " << (result.differs ? "differs" : "same") << " (max |dq| " << result.maxDifference
       << "), lower potential: " << toString(result.lower);
  } else {
    result.potentialStatic = kNaN;
    result.maxDifference = kNaN;
  }
  result.message = os.str();
  result.success = arrivedAt(dyn, restPoint) && polished.converged && result.stable;
  return result;
}

}  // namespace buckle::mechanics
