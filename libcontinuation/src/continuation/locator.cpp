// The locator (locator.h): samples of a step on its hyperplane, the roots of test functions
// between them, and folds (secant location, Moore refinement); branch points in
// locator_branch_points.cpp, hidden crossings in locator_hidden.cpp.
#include "buckle/continuation/internal/locator.h"

#include "locator_internal.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace buckle::continuation {

using namespace locator_detail;

Locator::Locator(const BoundProblem &problem, Corrector &corrector, PointEvaluator &evaluator,
                 const LocatorOptions &options)
    : problem_(problem), corrector_(corrector), evaluator_(evaluator), options_(options), n_(problem.dimension()) {
  std::string why;
  if (!options_.IsValid(&why)) throw std::invalid_argument("LocatorOptions: " + why);
  predictor_ = Vector::Zero(n_ + 1);
  x_ = Vector::Zero(n_ + 1);
  residual_ = Vector::Zero(n_);
}

void Locator::setStep(const ContinuationPoint &a, const ContinuationPoint &b) {
  a_.s = 0.0;
  a_.point = a;
  xa_ = a.state();
  dx_ = b.state() - xa_;
  ta_ = a.tangent;
  tb_ = b.tangent;
  stepLength_ = a.tangent.dot(dx_);
  b_.s = stepLength_;
  b_.point = b;
}

bool Locator::sample(double s, StepSample &out, CorrectorSummary *summary) {
  if (options_.interrupt.requested()) {
    if (summary) summary->flagName = "interrupted";
    return false;
  }
  // Cubic Hermite predictor through (x_a, t_a) and (x_b, t_b): near a branch point a second
  // branch crosses the hyperplane t_aᵀ(x − x_a) = s close by, and Newton started from the chord
  // (error O(ds²)) can converge to it; the Hermite error is O(ds⁴). The hyperplane is the same.
  const double theta = stepLength_ != 0.0 ? s / stepLength_ : 0.0;
  const double theta2 = theta * theta, theta3 = theta2 * theta;
  const double chord = dx_.norm();
  predictor_ = (2.0 * theta3 - 3.0 * theta2 + 1.0) * xa_ + (theta3 - 2.0 * theta2 + theta) * chord * ta_ +
               (-2.0 * theta3 + 3.0 * theta2) * (xa_ + dx_) + (theta3 - theta2) * chord * tb_;
  const CorrectorOptions saved = corrector_.options();
  CorrectorOptions tight = saved;
  tight.tolerance = std::min(saved.tolerance, options_.location.newtonTolerance);
  tight.maxIterations = std::max(saved.maxIterations, 15);
  corrector_.setOptions(tight);
  const CorrectorSummary result = corrector_.correct(predictor_, ta_, x_);
  corrector_.setOptions(saved);
  if (summary) *summary = result;
  if (!result.converged) return false;
  out.s = s;
  out.point.u = x_.head(n_);
  out.point.lambda = x_[n_];
  out.point.arclength = a_.point.arclength + s;
  out.point.stepSize = s;
  out.point.newtonIterations = result.iterations;
  out.point.residualNorm = result.residualNorm;
  // A sample's stability is its inertia alone (what the crossings' count and separation read): a
  // test that follows an eigenvalue asks for it (crossingEigenvalue), and the one sample that
  // becomes a traced point, a stop event's, gets the tracer's eigenvalues there (locateStopEvent).
  if (!evaluator_.complete(out.point, ta_, true) && !evaluator_.lastWasSingular()) return false;
  // A sample whose tangent disagrees with the interpolated one AND that Newton moved far from
  // the predictor converged onto the crossing branch. Within a tiny distance of the branch
  // point the computed tangent itself is unreliable (F_x nearly rank-deficient), but there both
  // branches are close to the point we look for and the augmented refinement takes over.
  const Vector expected = ((1.0 - theta) * ta_ + theta * tb_).normalized();
  const double correction = (x_ - predictor_).norm();
  if (!evaluator_.lastWasSingular() && out.point.tangent.dot(expected) < options_.minSampleCosine &&
      correction > 1e-3 * chord) {
    if (summary) summary->flagName = "sample on a crossing branch";
    return false;
  }
  return true;
}

bool Locator::findRoot(const StepSample &lo, double fLo, const StepSample &hi, double fHi, const TestFunction &test,
                       Root &root, double relativeTolerance) {
  root = Root();
  root.left = lo;
  root.right = hi;
  root.fLeft = fLo;
  root.fRight = fHi;
  if (fLo == 0.0 || fHi == 0.0) {
    root.at = fLo == 0.0 ? lo : hi;
    root.converged = true;
    return true;
  }
  if (sameSign(fLo, fHi)) {
    root.message = "test function does not change sign";
    return false;
  }
  StepSample left = lo, right = hi;
  IllinoisBracket bracket;
  bracket.left = lo.s;
  bracket.right = hi.s;
  bracket.fLeft = fLo;
  bracket.fRight = fHi;
  double previousS = 0.0, previousLambda = 0.0;
  const double tolS = (relativeTolerance > 0.0 ? relativeTolerance : options_.location.tolerance) *
                      std::max(1.0, std::abs(0.5 * (lo.point.lambda + hi.point.lambda)));
  StepSample trial;
  for (int it = 0; it < options_.location.maxIterations; ++it) {
    double s = bracket.next();
    CorrectorSummary summary;
    bool sampled = sample(s, trial, &summary);
    if (!sampled && s != bracket.midpoint()) {
      s = bracket.midpoint();  // a secant point can sit where Newton is poorly posed
      sampled = sample(s, trial, &summary);
    }
    if (!sampled) {
      root.message = std::string("corrector failed while locating (") + summary.flagName + ")";
      return root.evaluations > 0;
    }
    double f = 0.0;
    if (!test(trial.point, f)) {
      root.message = "test function could not be evaluated";
      return root.evaluations > 0;
    }
    if (root.evaluations == 0) {
      root.lastDs = right.s - left.s;
      root.lastDLambda = std::abs(right.point.lambda - left.point.lambda);
    } else {
      root.lastDs = std::abs(s - previousS);
      root.lastDLambda = std::abs(trial.point.lambda - previousLambda);
    }
    ++root.evaluations;
    previousS = s;
    previousLambda = trial.point.lambda;
    root.at = trial;
    root.value = f;
    if (f == 0.0) {  // an exact zero of the test function: nothing left to refine
      root.lastDs = 0.0;
      root.lastDLambda = 0.0;
      root.converged = true;
      break;
    }
    // The bracket's ends are the samples left.s and right.s.
    (bracket.update(s, f) < 0 ? left : right) = trial;
    root.left = left;
    root.right = right;
    root.fLeft = bracket.fLeft;
    root.fRight = bracket.fRight;
    if (bracket.width() <= tolS || (root.evaluations > 1 && root.lastDs <= tolS)) {
      root.converged = true;
      break;
    }
  }
  if (!root.converged) root.message = "secant iteration limit reached";
  return true;
}

double Locator::residualNorm(ConstVectorRef u, double lambda) {
  if (!problem_.residual(u, lambda, residual_)) return std::numeric_limits<double>::infinity();
  return residual_.norm();
}

std::vector<SpecialPoint> Locator::locateSpecialPoints(const IntervalCrossings &crossings) {
  std::vector<SpecialPoint> found;
  if (crossings.fold && options_.detection.folds) keep(found, locateFold(a_, b_));
  if (crossings.branchPointCrossings > 0 && options_.detection.branchPoints) {
    std::vector<std::pair<StepSample, StepSample>> simple, multiple;
    separateCrossings(a_, b_, simple, multiple, 0);
    // As in locateBetween: an interrupt ends the location between two branch points.
    for (const auto &bracket : simple) {
      if (options_.interrupt.requested()) break;
      keep(found, locateSimpleBranchPoint(bracket.first, bracket.second));
    }
    for (const auto &bracket : multiple) {
      if (options_.interrupt.requested()) break;
      const int m = std::abs(bracket.second.point.stability.negative - bracket.first.point.stability.negative);
      keep(found, multipleBranchPoint(bracket.first, bracket.second, std::max(m, 2)));
    }
  }
  std::sort(found.begin(), found.end(),
            [](const SpecialPoint &p, const SpecialPoint &q) { return p.arclength < q.arclength; });
  return found;
}

void Locator::locateBetween(const std::vector<StepSample> &samples, std::vector<SpecialPoint> &found) {
  std::vector<std::pair<StepSample, StepSample>> simple, multiple;
  for (size_t i = 0; i + 1 < samples.size(); ++i) {
    // Two folds close together (near a cusp of the fold curve) are a pair of opposite crossings too.
    if (options_.detection.folds && foldBetween(samples[i].point, samples[i + 1].point))
      keep(found, locateFold(samples[i], samples[i + 1]));
    if (options_.detection.branchPoints) separateCrossings(samples[i], samples[i + 1], simple, multiple, 0);
  }
  // An interrupt ends the location between two branch points (below the dense crossover each
  // refinement is O(N³) work, and a step over a cluster holds many): the tracer then drops
  // the half-located step, so the time limit is kept within one refinement.
  for (const auto &bracket : simple) {
    if (options_.interrupt.requested()) break;
    keep(found, locateSimpleBranchPoint(bracket.first, bracket.second));
  }
  for (const auto &bracket : multiple) {
    if (options_.interrupt.requested()) break;
    const int m = std::abs(bracket.second.point.stability.negative - bracket.first.point.stability.negative);
    keep(found, multipleBranchPoint(bracket.first, bracket.second, std::max(m, 2)));
  }
}

void Locator::keep(std::vector<SpecialPoint> &found, SpecialPoint &&sp) const {
  found.push_back(std::move(sp));
  if (options_.onLocated) options_.onLocated(found.back());
}

void Locator::separateCrossings(const StepSample &lo, const StepSample &hi,
                                std::vector<std::pair<StepSample, StepSample>> &simple,
                                std::vector<std::pair<StepSample, StepSample>> &multiple, int depth) {
  // The count of the tracer's step test (classifyInterval): the determinant's sign change, or the
  // inertia change less one for a fold (reported or not), zero-band eigenvalues settled alike.
  const int crossings = classifyInterval(lo.point, hi.point, true, true).branchPointCrossings;
  if (crossings == 0) return;
  // An end in the middle of a crossing (an eigenvalue in the count's zero band: the step, or a
  // bisection point, landed on a branch point to rounding) is a poor bracket end: the test
  // functions vanish there too, and the secant and the refinement return that end's point, whichever
  // crossing the bracket holds. Split the ambiguous end off by a sample at 1e-3 of the bracket from
  // it (a few levels down to separationFraction): a crossing at the end itself is then located in
  // its own small bracket, the bracket's other crossings away from it.
  const bool loAmbiguous = lo.point.stability.zero > 0, hiAmbiguous = hi.point.stability.zero > 0;
  if ((loAmbiguous || hiAmbiguous) && hi.s - lo.s > options_.location.separationFraction * std::abs(stepLength_) &&
      depth <= 200) {
    const double offset = loAmbiguous && hiAmbiguous ? 0.5 : 1e-3;
    const double s = loAmbiguous ? lo.s + offset * (hi.s - lo.s) : hi.s - offset * (hi.s - lo.s);
    StepSample inner;
    if (sample(s, inner)) {
      separateCrossings(lo, inner, simple, multiple, depth + 1);
      separateCrossings(inner, hi, simple, multiple, depth + 1);
      return;
    }
  }
  if (crossings == 1) {
    simple.emplace_back(lo, hi);
    return;
  }
  // Bisection on the inertia count: each half keeps the crossings it contains.
  if (hi.s - lo.s <= options_.location.separationFraction * std::abs(stepLength_) || depth > 200) {
    multiple.emplace_back(lo, hi);
    return;
  }
  StepSample mid;
  if (!sample(0.5 * (lo.s + hi.s), mid)) {
    multiple.emplace_back(lo, hi);
    return;
  }
  separateCrossings(lo, mid, simple, multiple, depth + 1);
  separateCrossings(mid, hi, simple, multiple, depth + 1);
}

SpecialPoint Locator::locateFold(const StepSample &lo, const StepSample &hi) {
  SpecialPoint sp;
  sp.type = SpecialPointType::Fold;
  sp.inertiaBefore = lo.point.stability.negative;
  sp.inertiaAfter = hi.point.stability.negative;
  Root root;
  const TestFunction test = [](const ContinuationPoint &p, double &f) {
    f = p.foldTest;
    return true;
  };
  bool ok = findRoot(lo, lo.point.foldTest, hi, hi.point.foldTest, test, root, bracketingTolerance(lo, hi, 1e-3));
  int evaluations = root.evaluations;
  auto adopt = [&](bool found) {
    const StepSample &at = found ? root.at : (std::abs(lo.point.foldTest) < std::abs(hi.point.foldTest) ? lo : hi);
    placeAt(sp, at.point, at.point.foldTest);
    sp.lambdaAccuracy = found ? root.lastDLambda : std::abs(hi.point.lambda - lo.point.lambda);
    sp.locationIterations = evaluations;
    sp.note = root.message.empty() ? "" : "fold secant: " + root.message;
  };
  adopt(ok);
  const bool refined =
      options_.denseAlgebra ? refineFold(sp, a_.point.tangent) : refineFoldStructured(sp, a_.point.tangent);
  if (!refined && ok && root.fLeft * root.fRight < 0.0) finishSecant(sp, root, test, evaluations, adopt);
  sp.residualNorm = residualNorm(sp.u, sp.lambda);
  return sp;
}

void Locator::finishSecant(SpecialPoint &sp, Root &root, const TestFunction &test, int &evaluations,
                           const std::function<void(bool)> &adopt) {
  // No augmented refinement: the secant goes on from its coarse bracket to the full tolerance.
  // The refinement's own note (why it failed) is kept; adopt() rewrites the point.
  const std::string refinementNote = sp.note;
  const int refinementSteps = sp.locationIterations - evaluations;
  const Root coarse = root;
  const bool ok = findRoot(coarse.left, coarse.fLeft, coarse.right, coarse.fRight, test, root);
  evaluations += root.evaluations + refinementSteps;
  adopt(ok);
  sp.note = refinementNote;
  if (!root.message.empty()) sp.note += (sp.note.empty() ? "" : "; ") + ("secant: " + root.message);
}

bool Locator::refineFold(SpecialPoint &sp, const Vector &tangentRef) {
  const int n = n_;
  Matrix Fu(n, n);
  Vector Fl(n);
  if (!problem_.jacobian(sp.u, sp.lambda, Fu, Fl)) return false;
  // c: F_u's right singular vector of its smallest singular value, the normalization cᵀv = 1
  // and the start of v. Inverse iteration from the tangent when that value is isolated (the
  // same vector up to rounding, and its sign does not matter: (v, c) → (−v, −c) negates the
  // Newton iterates' v exactly and leaves their (u, λ) bit for bit); the SVD otherwise (two
  // small singular values, e.g. a fold beside a crossing branch, where a different start may
  // leave Newton on the other point).
  Vector c;
  const Vector start = sp.tangent.size() == n + 1 && sp.tangent.head(n).norm() > 0.0 ? Vector(sp.tangent.head(n))
                       : tangentRef.size() == n + 1 ? Vector(tangentRef.head(n))
                                                    : Vector(Vector::Ones(n));
  if (!smallestSingularVector(Fu, start, c)) {
    Eigen::BDCSVD<Matrix> svd(Fu, Eigen::ComputeFullV);
    c = svd.matrixV().col(n - 1);
  }
  Vector z(2 * n + 1);
  z << sp.u, sp.lambda, c;
  Matrix dFu(n, n);
  Vector dFl(n), F(n);
  const AugmentedSystem system = [&](const Vector &w, Vector &R, Matrix *J) {
    const auto u = w.head(n);
    const double lambda = w[n];
    const auto v = w.tail(n);
    if (!problem_.residual(u, lambda, F)) return false;
    if (!problem_.jacobian(u, lambda, Fu, Fl)) return false;
    R.head(n) = F;
    R.segment(n, n) = Fu * v;
    R[2 * n] = c.dot(v) - 1.0;
    if (!J) return R.allFinite();
    // d(F_u v)/du · du = F_uu[v, du]: one directional derivative along (v, 0) gives both the
    // u-block and the λ-column (F_uλ v = F_λu v).
    if (!problem_.jacobianDirectionalDerivative(u, lambda, v, 0.0, dFu, dFl)) return false;
    J->setZero();
    J->block(0, 0, n, n) = Fu;
    J->block(0, n, n, 1) = Fl;
    J->block(n, 0, n, n) = dFu;
    J->block(n, n, n, 1) = dFl;
    J->block(n, n + 1, n, n) = Fu;
    J->block(2 * n, n + 1, 1, n) = c.transpose();
    return J->allFinite();
  };
  const double maxDistance = 4.0 * dx_.norm() + 1e-8 + 4.0 * c.norm();
  const AugmentedNewtonResult result =
      augmentedNewton(system, z, n, options_.location.tolerance, options_.location.maxRefinementIterations, maxDistance);
  sp.locationIterations += result.iterations;
  if (!result.converged) {
    sp.note += (sp.note.empty() ? "" : "; ") + std::string("fold refinement: ") + result.message;
    sp.nullVectors = c;
    return false;
  }
  sp.u = z.head(n);
  sp.lambda = z[n];
  adoptRefinedFold(sp, tangentRef, z.tail(n), result.lastDLambda, result.residualNorm);
  return true;
}

bool Locator::refineFoldStructured(SpecialPoint &sp, const Vector &tangentRef) {
  Vector u = sp.u, v;
  double lambda = sp.lambda;
  const double maxDistance = 4.0 * dx_.norm() + 1e-8 + 4.0;
  const StructuredRefinementResult result = structured().fold(
      u, lambda, sp.tangent.size() == n_ + 1 ? sp.tangent : tangentRef, v, maxDistance);
  sp.locationIterations += result.iterations;
  if (!result.converged) {
    sp.note += (sp.note.empty() ? "" : "; ") + std::string("fold refinement (structured): ") + result.message;
    return false;
  }
  sp.u = u;
  sp.lambda = lambda;
  adoptRefinedFold(sp, tangentRef, v, result.lastDLambda, result.residualNorm);
  return true;
}

void Locator::adoptRefinedFold(SpecialPoint &sp, const Vector &tangentRef, const Vector &v, double lastDLambda,
                               double augmentedResidual) {
  const int n = n_;
  sp.refined = true;
  sp.lambdaAccuracy = lastDLambda;
  sp.augmentedResidualNorm = augmentedResidual;
  sp.nullVectors = v.normalized();
  ContinuationPoint p;
  p.u = sp.u;
  p.lambda = sp.lambda;
  if (evaluator_.complete(p, tangentRef)) {
    sp.tangent = p.tangent;
    sp.testFunctionValue = p.foldTest;
  } else {
    sp.tangent = Vector::Zero(n + 1);
    sp.tangent.head(n) = v.normalized();
    if (sp.tangent.dot(tangentRef) < 0.0) sp.tangent = -sp.tangent;
    sp.testFunctionValue = 0.0;
  }
  // Along the located fold the arclength is interpolated in the step coordinate.
  sp.arclength = a_.point.arclength + tangentRef.dot(
                     (Vector(n + 1) << sp.u, sp.lambda).finished() - xa_);
}

double Locator::bracketingTolerance(const StepSample &lo, const StepSample &hi, double fraction) const {
  // findRoot's tolerance is relative to max(1, |λ|); the bracket's own width is not.
  const double scale = std::max(1.0, std::abs(0.5 * (lo.point.lambda + hi.point.lambda)));
  return std::min(options_.location.coarseTolerance, fraction * std::abs(hi.s - lo.s) / scale);
}

bool Locator::insideBracket(const SpecialPoint &sp, const StepSample &lo, const StepSample &hi) const {
  // All three in the step coordinate ta·(x − xa) (the refined point's arclength is that). The
  // samples' own s is the Hermite predictor's parameter, which on a curved branch is not.
  auto coordinate = [&](const ContinuationPoint &p) {
    return a_.point.tangent.head(n_).dot(p.u - xa_.head(n_)) + a_.point.tangent[n_] * (p.lambda - xa_[n_]);
  };
  const double s = sp.arclength - a_.point.arclength, sLo = coordinate(lo.point), sHi = coordinate(hi.point);
  const double margin = 1e-6 * std::abs(sHi - sLo) + tolerance(sp.lambda);
  return s >= std::min(sLo, sHi) - margin && s <= std::max(sLo, sHi) + margin;
}

}  // namespace buckle::continuation
