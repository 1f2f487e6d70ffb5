#include <optional>
#include "buckle/continuation/locator.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace buckle::continuation {

namespace {

int crossingIndex(const ContinuationPoint &lo, const ContinuationPoint &hi) {
  return std::min(lo.stability.negative, hi.stability.negative);
}

// The eigenvalue with this ascending index is the one that passes through zero inside the
// bracket: with k negative eigenvalues on one side and k+m on the other, μ_k changes sign.
bool crossingEigenvalue(const ContinuationPoint &p, int index, double &value) {
  if (!p.stability.valid() || index < 0 || index >= p.stability.lowest.size()) return false;
  value = p.stability.lowest[index];
  return true;
}

// The crossing eigenvalue's index may exceed what the tracer recorded (it may record the inertia
// only): recompute the stability of a bracket end with enough eigenvalues.
void ensureEigenvalues(Problem &problem, ContinuationPoint &p, int count) {
  if (!p.stability.valid() || p.stability.lowest.size() >= count) return;
  StabilityInfo info;
  if (problem.stability(p.u, p.lambda, count, info)) p.stability = info;
}

std::string format(const char *pattern, double value) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, pattern, value);
  return buffer;
}

}  // namespace

Locator::Locator(Problem &problem, Corrector &corrector, PointEvaluator &evaluator, const LocatorOptions &options)
    : problem_(problem), corrector_(corrector), evaluator_(evaluator), options_(options), n_(problem.dimension()) {
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
  tight.residualTolerance = std::min(saved.residualTolerance, options_.newtonTolerance);
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
  if (!evaluator_.complete(out.point, ta_) && !evaluator_.lastWasSingular()) return false;
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
    root.failure = "test function does not change sign";
    return false;
  }
  StepSample left = lo, right = hi;
  IllinoisBracket bracket;
  bracket.left = lo.s;
  bracket.right = hi.s;
  bracket.fLeft = fLo;
  bracket.fRight = fHi;
  double previousS = 0.0, previousLambda = 0.0;
  const double tolS = (relativeTolerance > 0.0 ? relativeTolerance : options_.tolerance) *
                      std::max(1.0, std::abs(0.5 * (lo.point.lambda + hi.point.lambda)));
  StepSample trial;
  for (int it = 0; it < options_.maxIterations; ++it) {
    double s = bracket.next();
    CorrectorSummary summary;
    bool sampled = sample(s, trial, &summary);
    if (!sampled && s != bracket.midpoint()) {
      s = bracket.midpoint();  // a secant point can sit where Newton is poorly posed
      sampled = sample(s, trial, &summary);
    }
    if (!sampled) {
      root.failure = std::string("corrector failed while locating (") + summary.flagName + ")";
      return root.evaluations > 0;
    }
    double f = 0.0;
    if (!test(trial.point, f)) {
      root.failure = "test function could not be evaluated";
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
  if (!root.converged) root.failure = "secant iteration limit reached";
  return true;
}

double Locator::residualNorm(ConstVectorRef u, double lambda) {
  if (!problem_.residual(u, lambda, residual_)) return std::numeric_limits<double>::infinity();
  return residual_.norm();
}

std::vector<SpecialPoint> Locator::locateSpecialPoints(const IntervalCrossings &crossings) {
  std::vector<SpecialPoint> found;
  // Eigenvalue tests follow μ_k, k = the smaller negative count: make every sample carry it.
  const int savedEigenvalues = evaluator_.lowestEigenvalues();
  if (crossings.branchPointCrossings > 0 && a_.point.stability.valid() && b_.point.stability.valid()) {
    const int needed = std::max({3, savedEigenvalues, crossingIndex(a_.point, b_.point) + 2});
    evaluator_.setLowestEigenvalues(needed);
    ensureEigenvalues(problem_, a_.point, needed);
    ensureEigenvalues(problem_, b_.point, needed);
  }
  if (crossings.fold && options_.detectFolds) keep(found, locateFold(a_, b_));
  if (crossings.branchPointCrossings > 0 && options_.detectBranchPoints) {
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
  evaluator_.setLowestEigenvalues(savedEigenvalues);
  std::sort(found.begin(), found.end(),
            [](const SpecialPoint &p, const SpecialPoint &q) { return p.arclength < q.arclength; });
  return found;
}

void Locator::locateBetween(const std::vector<StepSample> &samples, std::vector<SpecialPoint> &found) {
  const int savedEigenvalues = evaluator_.lowestEigenvalues();
  int needed = std::max(3, savedEigenvalues);
  for (const StepSample &x : samples)
    if (x.point.stability.valid()) needed = std::max(needed, x.point.stability.negative + 2);
  evaluator_.setLowestEigenvalues(needed);
  std::vector<StepSample> ends = samples;
  for (StepSample &x : ends) ensureEigenvalues(problem_, x.point, needed);
  std::vector<std::pair<StepSample, StepSample>> simple, multiple;
  for (size_t i = 0; i + 1 < ends.size(); ++i) {
    // Two folds close together (near a cusp of the fold curve) are a pair of opposite crossings too.
    if (options_.detectFolds && foldBetween(ends[i].point, ends[i + 1].point))
      keep(found, locateFold(ends[i], ends[i + 1]));
    if (options_.detectBranchPoints) separateCrossings(ends[i], ends[i + 1], simple, multiple, 0);
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
  evaluator_.setLowestEigenvalues(savedEigenvalues);
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
  if ((loAmbiguous || hiAmbiguous) && hi.s - lo.s > options_.separationFraction * std::abs(stepLength_) &&
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
  if (hi.s - lo.s <= options_.separationFraction * std::abs(stepLength_) || depth > 200) {
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
    sp.arclength = at.point.arclength;
    sp.u = at.point.u;
    sp.lambda = at.point.lambda;
    sp.tangent = at.point.tangent;
    sp.testFunctionValue = at.point.foldTest;
    sp.lambdaAccuracy = found ? root.lastDLambda : std::abs(hi.point.lambda - lo.point.lambda);
    sp.locationIterations = evaluations;
    sp.note = root.failure.empty() ? "" : "fold secant: " + root.failure;
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
  if (!root.failure.empty()) sp.note += (sp.note.empty() ? "" : "; ") + ("secant: " + root.failure);
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
      augmentedNewton(system, z, n, options_.tolerance, options_.maxRefinementIterations, maxDistance);
  sp.locationIterations += result.iterations;
  if (!result.converged) {
    sp.note += (sp.note.empty() ? "" : "; ") + std::string("fold refinement: ") + result.failure;
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
    sp.note += (sp.note.empty() ? "" : "; ") + std::string("fold refinement (structured): ") + result.failure;
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
  return std::min(options_.coarseTolerance, fraction * std::abs(hi.s - lo.s) / scale);
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

SpecialPoint Locator::locateSimpleBranchPoint(const StepSample &lo, const StepSample &hi) {
  SpecialPoint sp;
  sp.type = SpecialPointType::BranchPoint;
  sp.multiplicity = 1;
  sp.inertiaBefore = lo.point.stability.negative;
  sp.inertiaAfter = hi.point.stability.negative;

  Matrix A(options_.denseAlgebra ? n_ + 1 : 0, options_.denseAlgebra ? n_ + 1 : 0);
  MinimallyAugmentedTest psi;
  TestFunction test;
  double fLo = 0.0, fHi = 0.0;
  bool haveTest = false;
  if (lo.point.determinantSign * hi.point.determinantSign < 0) {
    if (options_.denseAlgebra && evaluator_.borderedJacobian(lo.point.u, lo.point.lambda, lo.point.tangent, A)) {
      psi.initialize(A);
      test = [&](const ContinuationPoint &p, double &f) {
        return evaluator_.borderedJacobian(p.u, p.lambda, p.tangent, A) && psi.evaluate(A, f);
      };
      haveTest = test(lo.point, fLo) && test(hi.point, fHi) && !sameSign(fLo, fHi);
    }
    if (!haveTest) {
      // ψ's frozen border lost transversality: fall back to the determinant, scaled to O(1).
      const double reference = std::max(lo.point.logAbsDeterminant, hi.point.logAbsDeterminant);
      test = [reference](const ContinuationPoint &p, double &f) {
        f = p.determinantSign * std::exp(p.logAbsDeterminant - reference);
        return true;
      };
      test(lo.point, fLo);
      test(hi.point, fHi);
      haveTest = !sameSign(fLo, fHi);
    }
  } else {
    const int index = crossingIndex(lo.point, hi.point);
    test = [index](const ContinuationPoint &p, double &f) { return crossingEigenvalue(p, index, f); };
    haveTest = test(lo.point, fLo) && test(hi.point, fHi) && !sameSign(fLo, fHi);
    sp.note = "inertia change without determinant sign change; located on the crossing eigenvalue";
  }

  Root root;
  bool ok = false;
  if (haveTest) ok = findRoot(lo, fLo, hi, fHi, test, root, bracketingTolerance(lo, hi, 1e-3));
  int evaluations = root.evaluations;
  const std::string testNote = sp.note;
  auto adopt = [&](bool found) {
    const StepSample &at = found ? root.at : lo;
    sp.arclength = at.point.arclength;
    sp.u = at.point.u;
    sp.lambda = at.point.lambda;
    sp.tangent = at.point.tangent;
    sp.testFunctionValue = found ? root.value : fLo;
    sp.lambdaAccuracy = found ? root.lastDLambda : std::abs(hi.point.lambda - lo.point.lambda);
    sp.locationIterations = evaluations;
    sp.note = testNote;
    if (!haveTest) sp.note += (sp.note.empty() ? "" : "; ") + std::string("no usable test function");
    else if (!root.failure.empty()) sp.note += (sp.note.empty() ? "" : "; ") + ("branch point secant: " + root.failure);
  };
  adopt(ok);
  // Several branch points in one step (a cluster at n = 10 000, or a coarse step): the bracket
  // holds one of them, but Newton from the secant's point may still converge to a neighbour
  // outside it, which would then be reported twice and this one missed. A refined point outside
  // the bracket is rejected; the secant goes on inside the bracket, 1000 times tighter, and the
  // refinement is tried again from there.
  bool refined = false;
  std::optional<SpecialPoint> outside;  // the first refined point, outside the bracket
  for (double fraction = 1e-3;; fraction *= 1e-3) {
    const SpecialPoint located = sp;
    refined = options_.denseAlgebra ? refineBranchPoint(sp, a_.point.tangent)
                                    : refineBranchPointStructured(sp, a_.point.tangent);
    if (!refined || insideBracket(sp, lo, hi)) break;
    if (!outside) outside = sp;
    const int iterations = sp.locationIterations;
    sp = located;
    sp.locationIterations = iterations;
    sp.note += (sp.note.empty() ? "" : "; ") + std::string("refinement left the bracket (to a neighbouring point)");
    refined = false;
    if (!(ok && root.fLeft * root.fRight < 0.0) || fraction < 1e-8) break;
    const Root coarse = root;
    ok = findRoot(coarse.left, coarse.fLeft, coarse.right, coarse.fRight, test, root,
                  bracketingTolerance(lo, hi, fraction * 1e-3));
    evaluations = sp.locationIterations + root.evaluations;
    const std::string notes = sp.note;
    adopt(ok);
    sp.note = notes;
  }
  if (!refined && outside) {
    // No tighter bracket led Newton inside: keep the refined point rather than none (a refined
    // branch point of the problem, if perhaps a neighbour's; the note says so).
    const std::string notes = sp.note;
    sp = *outside;
    sp.note = notes + "; kept the refined point outside the bracket";
    refined = true;
  }
  if (!refined && ok && root.fLeft * root.fRight < 0.0) {
    finishSecant(sp, root, test, evaluations, adopt);
    if (options_.denseAlgebra) {
      fillBranchPointGeometry(sp, a_.point.tangent);
    } else {
      Matrix K;
      Vector psi;
      if (structured().approximateKernel(sp.u, sp.lambda, sp.tangent, K, psi))
        setBranchPointGeometry(sp, a_.point.tangent, K, psi, sp.testFunctionValue);
    }
  }
  sp.residualNorm = residualNorm(sp.u, sp.lambda);
  return sp;
}

bool Locator::refineBranchPoint(SpecialPoint &sp, const Vector &tangentRef) {
  const int n = n_;
  KernelInfo kernel;
  if (!jacobianKernel(problem_, sp.u, sp.lambda, kernel)) return false;
  Vector z(2 * n + 2);
  z << sp.u, sp.lambda, 0.0, kernel.left.col(0);
  Matrix Fx(n, n + 1), dFx(n, n + 1), Hp(n + 1, n + 1);
  Vector F(n);
  const AugmentedSystem system = [&](const Vector &w, Vector &R, Matrix *J) {
    const auto u = w.head(n);
    const double lambda = w[n];
    const double beta = w[n + 1];
    const auto p = w.tail(n);
    if (!problem_.residual(u, lambda, F)) return false;
    if (!problem_.jacobian(u, lambda, Fx.leftCols(n), Fx.col(n))) return false;
    R.head(n) = F + beta * p;
    R.segment(n, n + 1) = Fx.transpose() * p;
    R[2 * n + 1] = p.squaredNorm() - 1.0;
    if (!J) return R.allFinite();
    // Hessian of pᵀF in x, one column per coordinate direction; symmetrised because the
    // default second derivatives are finite differences.
    Vector e = Vector::Zero(n + 1);
    for (int j = 0; j <= n; ++j) {
      e.setZero();
      e[j] = 1.0;
      if (!problem_.jacobianDirectionalDerivative(u, lambda, e.head(n), e[n], dFx.leftCols(n), dFx.col(n)))
        return false;
      Hp.col(j) = dFx.transpose() * p;
    }
    Hp = (0.5 * (Hp + Hp.transpose())).eval();
    J->setZero();
    J->block(0, 0, n, n + 1) = Fx;
    J->block(0, n + 1, n, 1) = p;
    J->block(0, n + 2, n, n) = beta * Matrix::Identity(n, n);
    J->block(n, 0, n + 1, n + 1) = Hp;
    J->block(n, n + 2, n + 1, n) = Fx.transpose();
    J->block(2 * n + 1, n + 2, 1, n) = 2.0 * p.transpose();
    return J->allFinite();
  };
  const double maxDistance = 4.0 * dx_.norm() + 1e-8 + 4.0;
  const AugmentedNewtonResult result =
      augmentedNewton(system, z, n, options_.tolerance, options_.maxRefinementIterations, maxDistance);
  sp.locationIterations += result.iterations;
  if (result.converged) {
    sp.refined = true;
    sp.u = z.head(n);
    sp.lambda = z[n];
    sp.lambdaAccuracy = result.lastDLambda;
    sp.augmentedResidualNorm = result.residualNorm;
    sp.arclength = a_.point.arclength + tangentRef.dot((Vector(n + 1) << sp.u, sp.lambda).finished() - xa_);
  } else {
    sp.note += (sp.note.empty() ? "" : "; ") + std::string("Moore refinement: ") + result.failure;
  }
  fillBranchPointGeometry(sp, tangentRef);
  return result.converged;
}

bool Locator::refineBranchPointStructured(SpecialPoint &sp, const Vector &tangentRef) {
  Vector u = sp.u, psi;
  double lambda = sp.lambda;
  Matrix K;
  const double maxDistance = 4.0 * dx_.norm() + 1e-8 + 4.0;
  const StructuredRefinementResult result = structured().branchPoint(
      u, lambda, sp.tangent.size() == n_ + 1 ? sp.tangent : tangentRef, K, psi, maxDistance);
  sp.locationIterations += result.iterations;
  if (!result.converged) {
    sp.note += (sp.note.empty() ? "" : "; ") + std::string("branch-point refinement (structured): ") + result.failure;
    return false;
  }
  sp.refined = true;
  sp.u = u;
  sp.lambda = lambda;
  sp.lambdaAccuracy = result.lastDLambda;
  sp.augmentedResidualNorm = result.residualNorm;
  sp.arclength = a_.point.arclength + tangentRef.dot((Vector(n_ + 1) << sp.u, sp.lambda).finished() - xa_);
  setBranchPointGeometry(sp, tangentRef, K, psi, result.testValue);
  return true;
}

StructuredRefinement &Locator::structured() {
  if (!structured_) {
    refinementSolver_ = problem_.makeStructuredSolver();
    if (!refinementSolver_ || refinementSolver_->maxGeneralBorder() < 2)
      refinementSolver_ = std::make_unique<DenseBorderedSolver>(problem_);
    structured_ = std::make_unique<StructuredRefinement>(problem_, *refinementSolver_, options_.tolerance,
                                                         options_.maxRefinementIterations);
  }
  return *structured_;
}

void Locator::setBranchPointGeometry(SpecialPoint &sp, const Vector &tangentRef, const Matrix &K, const Vector &psi,
                                     double testValue) {
  // As fillBranchPointGeometry for a simple point: the traced branch's own tangent is the root of
  // the bifurcation equation closest to the step's tangent (else the projection onto the kernel).
  Vector t = K * (K.transpose() * tangentRef);
  if (t.norm() < 1e-12) t = K.col(0);
  t.normalize();
  Vector d1, d2;
  if (bifurcationDirectionsApplied(problem_, sp.u, sp.lambda, psi, K.col(0), K.col(1), d1, d2))
    t = std::abs(d1.dot(tangentRef)) >= std::abs(d2.dot(tangentRef)) ? d1 : d2;
  if (t.dot(tangentRef) < 0.0) t = -t;
  Matrix basis(n_ + 1, 2);
  basis.col(0) = t;
  int filled = 1;
  for (int k = 0; k < 2 && filled < 2; ++k) {
    Vector w = K.col(k) - t.dot(K.col(k)) * t;
    if (w.norm() > 1e-6) basis.col(filled++) = w.normalized();
  }
  sp.nullVectors = basis.leftCols(filled);
  sp.tangent = t;
  sp.leftNullVector = psi;
  sp.testFunctionValue = testValue;
}

void Locator::fillBranchPointGeometry(SpecialPoint &sp, const Vector &tangentRef) {
  if (!options_.denseAlgebra) return;  // null vectors need the dense kernel
  KernelInfo kernel;
  if (!jacobianKernel(problem_, sp.u, sp.lambda, kernel)) return;
  const double scale = std::max(1.0, kernel.singularValues.maxCoeff());
  int dimension = 2;
  for (int k = 2; k < kernel.singularValues.size(); ++k)
    if (kernel.singularValues[k] <= 1e-8 * scale) dimension = k + 1;
  if (sp.multiplicity == 1) dimension = 2;
  const Matrix K = kernel.right.leftCols(dimension);
  // First basis vector: the traced branch's own tangent at the point. For a simple BP that is the
  // root of the bifurcation equation closest to the step's tangent (the projection of the step
  // tangent onto the kernel is off by O(ds·curvature)); otherwise, or if the equation fails, the
  // projection.
  Vector t = K * (K.transpose() * tangentRef);
  if (t.norm() < 1e-12) t = K.col(0);
  t.normalize();
  if (sp.multiplicity == 1) {
    Vector d1, d2;
    if (bifurcationDirections(problem_, sp.u, sp.lambda, kernel.left.col(0), K.col(0), K.col(1), d1, d2))
      t = std::abs(d1.dot(tangentRef)) >= std::abs(d2.dot(tangentRef)) ? d1 : d2;
  }
  if (t.dot(tangentRef) < 0.0) t = -t;
  Matrix basis(n_ + 1, dimension);
  basis.col(0) = t;
  int filled = 1;
  for (int k = 0; k < dimension && filled < dimension; ++k) {
    Vector w = K.col(k);
    for (int j = 0; j < filled; ++j) w -= basis.col(j).dot(w) * basis.col(j);
    if (w.norm() > 1e-6) basis.col(filled++) = w.normalized();
  }
  sp.nullVectors = basis.leftCols(filled);
  sp.tangent = t;
  sp.leftNullVector = kernel.left.col(0);
  sp.testFunctionValue = kernel.singularValues[1];
}

SpecialPoint Locator::multipleBranchPoint(const StepSample &lo, const StepSample &hi, int multiplicity) {
  SpecialPoint sp;
  sp.type = SpecialPointType::BranchPoint;
  sp.multiplicity = multiplicity;
  sp.inertiaBefore = lo.point.stability.negative;
  sp.inertiaAfter = hi.point.stability.negative;
  const int index = crossingIndex(lo.point, hi.point);
  // The mean of the m crossing eigenvalues μ_k … μ_{k+m−1}: smooth through the cluster (the
  // eigenvalues themselves may swap order inside it) and zero where all of them vanish.
  const TestFunction mean = [this, index, multiplicity](const ContinuationPoint &p, double &f) {
    Vector mu(multiplicity);
    if (!problem_.stabilityEigenvalues(p.u, p.lambda, index, mu)) return false;
    f = mu.mean();
    return std::isfinite(f);
  };
  const TestFunction single = [index](const ContinuationPoint &p, double &f) { return crossingEigenvalue(p, index, f); };
  double fLo = 0.0, fHi = 0.0;
  Root root;
  bool ok = false;
  bool onMean = mean(lo.point, fLo) && mean(hi.point, fHi) && !sameSign(fLo, fHi);
  if (onMean) ok = findRoot(lo, fLo, hi, fHi, mean, root);
  else if (single(lo.point, fLo) && single(hi.point, fHi) && !sameSign(fLo, fHi))
    ok = findRoot(lo, fLo, hi, fHi, single, root);
  const StepSample &at = ok ? root.at : lo;
  sp.arclength = at.point.arclength;
  sp.u = at.point.u;
  sp.lambda = at.point.lambda;
  sp.tangent = at.point.tangent;
  sp.testFunctionValue = ok ? root.value : fLo;
  sp.lambdaAccuracy = std::abs(hi.point.lambda - lo.point.lambda);
  if (ok && root.evaluations > 0) sp.lambdaAccuracy = std::min(sp.lambdaAccuracy, root.lastDLambda);
  sp.locationIterations = root.evaluations;
  sp.note = format("multiplicity %.0f: crossings not separable by inertia bisection (bracket |ds| = ", multiplicity) +
            format("%.3g); ", hi.s - lo.s) +
            (onMean ? "located on the mean of the crossing eigenvalues" : "located on the lowest crossing eigenvalue");
  sp.residualNorm = residualNorm(sp.u, sp.lambda);
  if (options_.denseAlgebra) {
    // The point is a multiple one when ker F_x is (m+1)-dimensional there: the m + 1 smallest
    // singular values (one is structural) vanish against the largest.
    KernelInfo kernel;
    if (ok && jacobianKernel(problem_, sp.u, sp.lambda, kernel) && kernel.singularValues.size() > multiplicity) {
      // against the scaled problem's unit (F_x itself may vanish at the point, as at κ = 0)
      const double top = std::max(kernel.singularValues.maxCoeff(), 1.0);
      const double ratio = kernel.singularValues[multiplicity] / top;
      sp.augmentedResidualNorm = ratio;
      sp.refined = ratio <= 1e-8 && (kernel.singularValues.size() <= multiplicity + 1 ||
                                     kernel.singularValues[multiplicity + 1] > 1e-8 * top);
      sp.note += format("; kernel of F_x %.0f-dimensional", multiplicity + 1) +
                 format(" to %.3g relative", ratio);
    }
  }
  fillBranchPointGeometry(sp, a_.point.tangent);
  return sp;
}

}  // namespace buckle::continuation
