// The critical curves of critical_curves.h, traced on ChainParameterProblem
// (critical_curves_problem.cpp): branch-point curves with their post-buckling coefficients, fold
// curves, and the codimension-two points located on them.
#include "buckle/mechanics/critical_curves.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include "buckle/continuation/bifurcation_coefficients.h"
#include "buckle/continuation/branch_point_curve.h"
#include "buckle/continuation/curve_zeros.h"
#include "buckle/continuation/fold_curve.h"
#include "buckle/continuation/root_finding.h"
#include "buckle/continuation/internal/structured_refinement.h"
#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/linear_buckling.h"

namespace buckle::mechanics {

namespace cont = buckle::continuation;
using Kind = SecondParameter::Kind;

namespace {
double smallestStraightStiffness(const Chain& chain) {
  double kappa = std::numeric_limits<double>::infinity();
  for (int i = 0; i < chain.size(); ++i) kappa = std::min(kappa, chain.segment(i).straightStiffness());
  return kappa;
}

// The null vector's joint-angle part as a unit vector, largest-|·| component positive.
Vector unitMode(const Vector& w, int n) {
  Vector z = w.head(n);
  const double norm = z.norm();
  if (norm > 0.0) z /= norm;
  Eigen::Index k = 0;
  z.cwiseAbs().maxCoeff(&k);
  if (z[k] < 0.0) z = -z;
  return z;
}

// Right singular vector of the smallest singular value of F_u at (u, λ).
Vector nullVector(const cont::BoundProblem& problem, const Vector& u, double lambda) {
  const int N = problem.dimension();
  Matrix Fu(N, N);
  Vector Fl(N);
  if (!problem.jacobian(u, lambda, Fu, Fl)) throw std::invalid_argument("critical curve: the start point is outside the domain");
  Eigen::BDCSVD<Matrix> svd(Fu, Eigen::ComputeFullV);
  return svd.matrixV().col(N - 1);
}

// The tracer on a curve problem in both directions from W0; the second branch is reversed in
// front of the first when joined.
// Structured: the curve's O(n) solver, no fold location on the curve (its folds in μ are the
// cusps, located by their own test function), and `restart` / `accepted` called before each
// direction and after each accepted point (the minimally augmented system's borders).
std::vector<cont::Branch> traceBoth(cont::Problem& curve, const Vector& W0, double mu0, const CriticalCurveOptions& options,
                                    bool structured = false, const std::function<void()>& restart = {},
                                    const std::function<void(const cont::ContinuationPoint&)>& accepted = {}) {
  cont::TracerOptions to = options.tracer;
  to.lambdaMin = options.muMin;
  to.lambdaMax = options.muMax;
  to.detection.stability = false;
  to.detection.branchPoints = false;
  if (structured) {
    to.linearAlgebra = cont::TracerOptions::LinearAlgebra::Structured;
    to.detection.folds = false;
  }
  if (accepted) {
    const cont::StepCallback user = options.tracer.onStep;
    to.onStep = [accepted, user](const cont::StepInfo& step) {
      accepted(step.point);
      return user ? user(step) : cont::StepAction::Continue;
    };
  }
  std::vector<cont::Branch> out;
  cont::Tracer tracer(curve, to);
  if (restart) restart();
  out.push_back(tracer.trace(W0, mu0, cont::InitialDirection::increasingLambda()));
  if (restart) restart();
  if (options.bothDirections) out.push_back(tracer.trace(W0, mu0, cont::InitialDirection::decreasingLambda()));
  return out;
}

bool useStructured(const CriticalCurveOptions& options, int N) {
  using LA = cont::TracerOptions::LinearAlgebra;
  if (options.tracer.linearAlgebra == LA::Dense) return false;
  return options.tracer.linearAlgebra == LA::Structured || N >= options.structuredFromDimension;
}

// Null vector of F_u at (u, λ) near `guess` by two steps of inverse iteration with the bordered
// matrix [[F_u, g], [gᵀ, 0]] (O(n) through the structured solver, refined on the chain's products).
Vector structuredNullVector(const cont::BoundProblem& problem, const Vector& u, double lambda, const Vector& guess) {
  const int N = problem.dimension();
  const std::unique_ptr<cont::BorderedSolver> solver = problem.makeStructuredSolver();
  if (!solver) throw std::invalid_argument("critical curve: no structured solver for this problem");
  cont::RefinedBorderedSystem system(problem, *solver);
  Matrix B(N, 1), D = Matrix::Zero(1, 1);
  Vector v = guess.normalized(), rhs = Vector::Zero(N + 1), z;
  rhs[N] = 1.0;
  for (int it = 0; it < 2; ++it) {
    B.col(0) = v;
    if (!system.factor(u, lambda, B, B, D, false) || !system.solve(rhs, z))
      throw std::invalid_argument("critical curve: singular bordered matrix at the start (not a simple critical point?)");
    v = z.head(N).normalized();
  }
  return v;
}

void addZeros(cont::Problem& curve, const cont::Branch& branch, const cont::CurveTest& g, const std::string& label,
              int n, std::vector<Codim2Point>& special) {
  for (const cont::CurveZero& z : cont::locateCurveZeros(curve, branch, g)) {
    // a sign change through a pole of g (not a zero): |g| grows while the bracket shrinks
    const auto& a = branch.points[size_t(z.index)];
    const auto& b = branch.points[size_t(z.index) + 1];
    double ga = 0.0, gb = 0.0;
    if (g(a.u, a.lambda, ga) && g(b.u, b.lambda, gb) && std::abs(z.value) > std::max(std::abs(ga), std::abs(gb)))
      continue;
    Codim2Point p;
    p.label = label;
    p.mu = z.lambda;
    p.lambda = z.u[n];
    p.accuracy = z.accuracy;
    p.converged = z.converged;
    special.push_back(p);
  }
}

// "K0": where the branch-point curve crosses λ = 0 the unloaded chain is singular on ker J_h. For
// identical segments every mode's curve crosses there at once (K_q = κ·I vanishes: a multiple
// zero, where the curve's own system is singular), so the point is located in μ alone, by the
// Illinois iteration on the smallest eigenvalue of the unloaded stability operator.
void addZeroLoadPoints(ChainParameterProblem& problem, const cont::Branch& branch, int N,
                       std::vector<Codim2Point>& special) {
  const Vector u0 = Vector::Zero(N);
  const double scale = problem.secondParameterScale();
  auto smallest = [&](double mu, double& g) {
    cont::StabilityInfo info;
    if (!problem.setSecondParameter(mu) || !cont::BoundProblem(problem).stability(u0, 0.0, 1, info) ||
        info.lowest.size() < 1)
      return false;
    g = info.lowest[0];
    return true;
  };
  for (size_t i = 0; i + 1 < branch.points.size(); ++i) {
    const cont::ContinuationPoint &a = branch.points[i], &b = branch.points[i + 1];
    if (cont::sameSign(a.u[N], b.u[N])) continue;
    double ga = 0.0, gb = 0.0;
    Codim2Point p;
    p.label = "K0";
    if (!smallest(a.lambda, ga) || !smallest(b.lambda, gb) || cont::sameSign(ga, gb)) continue;
    cont::IllinoisBracket bracket{std::min(a.lambda, b.lambda), std::max(a.lambda, b.lambda),
                                  a.lambda < b.lambda ? ga : gb, a.lambda < b.lambda ? gb : ga, 0};
    for (int it = 0; it < 100 && bracket.width() > 1e-13 * scale; ++it) {
      const double mu = bracket.next();
      double g = 0.0;
      if (!smallest(mu, g)) break;
      if (g == 0.0) {
        bracket.left = bracket.right = mu;
        break;
      }
      bracket.update(mu, g);
    }
    p.mu = bracket.midpoint();
    p.lambda = 0.0;
    p.accuracy = bracket.width() / scale;
    p.converged = bracket.width() <= 1e-13 * scale;
    special.push_back(p);
  }
}

std::string stopText(const std::vector<cont::Branch>& branches) {
  std::string s;
  for (size_t i = 0; i < branches.size(); ++i) {
    if (i) s += "; ";
    s += (i == 0 ? "increasing μ: " : "decreasing μ: ") + std::string(cont::toString(branches[i].stopReason));
    if (!branches[i].stopMessage.empty()) s += " (" + branches[i].stopMessage + ")";
  }
  return s;
}

// Points of both branches in one arclength order: the decreasing one reversed, then the other.
std::vector<const cont::ContinuationPoint*> joined(const std::vector<cont::Branch>& branches) {
  std::vector<const cont::ContinuationPoint*> pts;
  if (branches.size() > 1)
    for (size_t i = branches[1].points.size(); i-- > 1;) pts.push_back(&branches[1].points[i]);
  for (const auto& p : branches[0].points) pts.push_back(&p);
  return pts;
}
}  // namespace

PostBuckling koiterKind(double a, double b, double transversality, double aTolerance) {
  if (std::abs(a) > aTolerance) return PostBuckling::Subcritical;
  return b * transversality < 0.0 ? PostBuckling::Supercritical : PostBuckling::Subcritical;
}

std::string CriticalCurveOptions::validate(const std::string& prefix) const {
  return cont::firstProblem(
      {cont::require(!std::isnan(muMin) && !std::isnan(muMax) && muMin < muMax, prefix, "muMin",
                     "must be smaller than muMax (neither NaN)"),
       tracer.validate(prefix + "tracer."),
       cont::require(structuredFromDimension >= 1, prefix, "structuredFromDimension", "must be at least 1")});
}

CriticalCurve branchPointCurve(ChainParameterProblem& problem, int mode, const CriticalCurveOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("CriticalCurveOptions: " + why);
  const EquilibriumProblem& eq = problem.equilibrium();
  const int n = eq.segments();
  const int N = eq.dimension();
  const double mu0 = problem.secondParameter();
  const Vector u0 = Vector::Zero(N);
  // the straight chain must stay an equilibrium along the load path
  const cont::ProblemScales scales = eq.scales();
  Vector F(N);
  for (double lambda : {0.0, scales.parameter}) {
    if (!cont::BoundProblem(eq).residual(u0, lambda, F) ||
        F.cwiseQuotient(scales.residuals).lpNorm<Eigen::Infinity>() > 1e-12)
      throw std::invalid_argument(
          "branch-point curve: the straight chain is not an equilibrium along the load path (unequal preloads, "
          "an off-axis load or a held coordinate off the axis)");
  }
  const bool structured = useStructured(options, N);
  LinearBucklingOptions lbo;
  lbo.direction = eq.direction();
  // structured: only the lowest modes (O(n) each, linear_buckling.h), enough to hold `mode`
  // among the compressive ones unless tensile modes come first (then all of them)
  std::vector<const BucklingMode*> compressive;
  LinearBucklingResult lb;
  for (int count : {structured && mode >= 0 ? 2 * (mode + 1) : -1, -1}) {
    lbo.count = count;
    lb = linearBuckling(eq.chain(), Vector::Zero(n), eq.endCondition(), lbo);
    compressive.clear();
    for (const BucklingMode& b : lb.modes)
      if (b.lambda < 0.0) compressive.push_back(&b);
    if (count < 0 || mode < int(compressive.size())) break;
  }
  std::stable_sort(compressive.begin(), compressive.end(),
                   [](const BucklingMode* x, const BucklingMode* y) { return std::abs(x->lambda) < std::abs(y->lambda); });
  if (mode < 0 || mode >= int(compressive.size()))
    throw std::invalid_argument("branch-point curve: the straight chain has " + std::to_string(compressive.size()) +
                                " compressive buckling modes, mode " + std::to_string(mode) + " asked");
  const double lambdaC = compressive[size_t(mode)]->lambda;
  Vector guess = Vector::Zero(N);
  guess.head(n) = compressive[size_t(mode)]->mode;
  const Vector w0 = structured ? structuredNullVector(problem, u0, lambdaC, guess) : nullVector(problem, u0, lambdaC);
  Vector c;
  const Vector W0 = cont::BranchPointCurveProblem::start(problem, lambdaC, w0, c);
  cont::BranchPointCurveProblem curve(problem, u0, c);
  curve.useStructuredSolver(structured);
  const std::vector<cont::Branch> branches = traceBoth(curve, W0, mu0, options, structured);

  CriticalCurve out;
  out.type = "BP";
  out.parameter = problem.parameter();
  out.stopMessage = stopText(branches);
  // b at a point of the curve: the Koiter coefficients with ξ the amplitude of the unit mode
  auto coefficients = [&](cont::ConstVectorRef W, double mu, cont::BifurcationCoefficients& bc) {
    if (!problem.setSecondParameter(mu)) return false;
    const Vector w = W.head(N);
    Vector cm = Vector::Zero(N);
    cm.head(n) = unitMode(w, n);
    return cont::bifurcationCoefficients(problem, u0, W[N], w, cm, bc);
  };
  for (const cont::ContinuationPoint* p : joined(branches)) {
    CriticalPoint cp;
    cp.mu = p->lambda;
    cp.lambda = p->u[N];
    cp.u = u0;
    cp.mode = unitMode(p->u.head(N), n);
    cp.cusp = std::numeric_limits<double>::quiet_NaN();
    if (!problem.setSecondParameter(cp.mu)) continue;
    cp.kappa = smallestStraightStiffness(problem.equilibrium().chain());
    cp.koiterA = cp.koiterB = std::numeric_limits<double>::quiet_NaN();
    cont::BifurcationCoefficients bc;
    if (options.coefficients && coefficients(p->u, cp.mu, bc)) {
      cp.koiterA = bc.a;
      cp.koiterB = bc.b;
      // a vanishes by symmetry; its rounding is relative to b·(mode scale)
      cp.kind = koiterKind(bc.a, bc.b, bc.transversality, 1e-8 * scales.parameter);
    } else {
      cp.kind = PostBuckling::Failed;
    }
    out.points.push_back(cp);
  }
  const cont::CurveTest pitchfork = [&](cont::ConstVectorRef W, double mu, double& g) {
    cont::BifurcationCoefficients bc;
    if (!coefficients(W, mu, bc)) return false;
    g = bc.b;
    return true;
  };
  for (const cont::Branch& b : branches) {
    addZeroLoadPoints(problem, b, N, out.special);
    if (options.coefficients) addZeros(curve, b, pitchfork, "DP", N, out.special);
  }
  problem.setSecondParameter(mu0);
  return out;
}

namespace {

// "BD": where the tracer stopped on a joint limit.
void addLimitPoints(const cont::Branch& b, int N, std::vector<Codim2Point>& special) {
  for (const cont::SpecialPoint& sp : b.specialPoints)
    if (sp.type == cont::SpecialPointType::Boundary) {
      Codim2Point bd;
      bd.label = "BD";
      bd.mu = sp.lambda;
      bd.lambda = sp.u[N];
      bd.converged = true;
      bd.note = sp.boundaryName;
      special.push_back(bd);
    }
}

// The fold curve by the minimally augmented system (O(n) per point). The borders follow the
// curve: reset to the start's before each direction and each pass over a branch, adapted at every
// accepted or evaluated point in arclength order from there, so each bordered solve has borders
// from a neighbouring point.
CriticalCurve minimalFoldCurve(ChainParameterProblem& problem, const cont::SpecialPoint& fold, const Vector& v,
                               const CriticalCurveOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("CriticalCurveOptions: " + why);
  const int N = problem.dimension();
  const int n = problem.equilibrium().segments();
  const double mu0 = problem.secondParameter();
  cont::MinimalFoldCurveProblem curve(problem, fold.u, fold.lambda, v);
  const Vector U0 = cont::MinimalFoldCurveProblem::start(fold.u, fold.lambda);
  const auto restart = [&] { curve.resetBorders(); };
  const auto accepted = [&](const cont::ContinuationPoint& p) { curve.adaptBorders(p.u, p.lambda); };
  const std::vector<cont::Branch> branches = traceBoth(curve, U0, mu0, options, true, restart, accepted);

  CriticalCurve out;
  out.type = "LP";
  out.parameter = problem.parameter();
  out.stopMessage = stopText(branches);
  // each branch from its start, in its own order; then joined as joined() does
  std::vector<std::vector<CriticalPoint>> perBranch;
  for (const cont::Branch& b : branches) {
    curve.resetBorders();
    std::vector<CriticalPoint> pts;
    for (const cont::ContinuationPoint& p : b.points) {
      CriticalPoint cp;
      cp.mu = p.lambda;
      cp.lambda = p.u[N];
      cp.u = p.u.head(N);
      cp.koiterA = cp.koiterB = std::numeric_limits<double>::quiet_NaN();
      Vector vp, wp;
      curve.adaptBorders(p.u, p.lambda);
      if (curve.nullVectors(p.u, p.lambda, vp, wp)) cp.mode = unitMode(vp, n);
      if (!curve.cuspTest(p.u, cp.mu, cp.cusp)) cp.cusp = std::numeric_limits<double>::quiet_NaN();
      if (!problem.setSecondParameter(cp.mu)) continue;
      cp.kappa = smallestStraightStiffness(problem.equilibrium().chain());
      pts.push_back(std::move(cp));
    }
    perBranch.push_back(std::move(pts));
  }
  if (perBranch.size() > 1)
    for (size_t i = perBranch[1].size(); i-- > 1;) out.points.push_back(perBranch[1][i]);
  for (CriticalPoint& p : perBranch[0]) out.points.push_back(std::move(p));

  const cont::CurveTest cusp = [&](cont::ConstVectorRef U, double mu, double& g) {
    return curve.cuspTest(U, mu, g) && curve.adaptBorders(U, mu);
  };
  for (const cont::Branch& b : branches) {
    curve.resetBorders();
    addZeros(curve, b, cusp, "CP", N, out.special);
    addLimitPoints(b, N, out.special);
  }
  problem.setSecondParameter(mu0);
  return out;
}

}  // namespace

CriticalCurve foldCurve(ChainParameterProblem& problem, const cont::SpecialPoint& fold,
                        const CriticalCurveOptions& options) {
  const int N = problem.dimension();
  const int n = problem.equilibrium().segments();
  const double mu0 = problem.secondParameter();
  if (fold.type != cont::SpecialPointType::Fold || fold.u.size() != N)
    throw std::invalid_argument("fold curve: the start is not a fold of this problem");
  const bool structured = useStructured(options, N);
  const bool haveNull = fold.nullVectors.rows() == N && fold.nullVectors.cols() >= 1;
  if (structured && !haveNull && fold.tangent.size() != N + 1)
    throw std::invalid_argument("fold curve: the fold has neither a null vector nor a tangent");
  const Vector v = haveNull     ? Vector(fold.nullVectors.col(0))
                   : structured ? structuredNullVector(problem, fold.u, fold.lambda, fold.tangent.head(N))
                                : nullVector(problem, fold.u, fold.lambda);
  if (structured) return minimalFoldCurve(problem, fold, v, options);
  Vector c;
  const Vector U0 = cont::FoldCurveProblem::start(problem, fold.u, fold.lambda, v, c);
  cont::FoldCurveProblem curve(problem, c);
  const std::vector<cont::Branch> branches = traceBoth(curve, U0, mu0, options);

  CriticalCurve out;
  out.type = "LP";
  out.parameter = problem.parameter();
  out.stopMessage = stopText(branches);
  for (const cont::ContinuationPoint* p : joined(branches)) {
    CriticalPoint cp;
    cp.mu = p->lambda;
    cp.lambda = p->u[N];
    cp.u = p->u.head(N);
    cp.mode = unitMode(p->u.tail(N), n);
    cp.koiterA = cp.koiterB = std::numeric_limits<double>::quiet_NaN();
    if (!curve.cuspTest(p->u, cp.mu, cp.cusp)) cp.cusp = std::numeric_limits<double>::quiet_NaN();
    cp.kappa = smallestStraightStiffness(problem.equilibrium().chain());
    out.points.push_back(cp);
  }
  const cont::CurveTest cusp = [&](cont::ConstVectorRef U, double mu, double& g) { return curve.cuspTest(U, mu, g); };
  for (const cont::Branch& b : branches) {
    addZeros(curve, b, cusp, "CP", N, out.special);
    addLimitPoints(b, N, out.special);
  }
  problem.setSecondParameter(mu0);
  return out;
}

}  // namespace buckle::mechanics
