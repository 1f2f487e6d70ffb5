// The locator's branch points (locator.h): simple ones by the bisection of their crossing
// eigenvalue and Moore's refinement, their kernel geometry, and points of multiplicity m >= 2.
#include "buckle/continuation/internal/locator.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "locator_internal.h"

namespace buckle::continuation {

using namespace locator_detail;

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
    test = [this, index](const ContinuationPoint &p, double &f) { return crossingEigenvalue(problem_, p, index, f); };
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
    placeAt(sp, at.point, found ? root.value : fLo);
    sp.lambdaAccuracy = found ? root.lastDLambda : std::abs(hi.point.lambda - lo.point.lambda);
    sp.locationIterations = evaluations;
    sp.note = testNote;
    if (!haveTest) sp.note += (sp.note.empty() ? "" : "; ") + std::string("no usable test function");
    else if (!root.message.empty()) sp.note += (sp.note.empty() ? "" : "; ") + ("branch point secant: " + root.message);
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
      fillBranchPointGeometry(sp, a_.point.tangent, true);
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
      augmentedNewton(system, z, n, options_.location.tolerance, options_.location.maxRefinementIterations, maxDistance);
  sp.locationIterations += result.iterations;
  if (result.converged) {
    sp.refined = true;
    sp.u = z.head(n);
    sp.lambda = z[n];
    sp.lambdaAccuracy = result.lastDLambda;
    sp.augmentedResidualNorm = result.residualNorm;
    sp.arclength = a_.point.arclength + tangentRef.dot((Vector(n + 1) << sp.u, sp.lambda).finished() - xa_);
  } else {
    sp.note += (sp.note.empty() ? "" : "; ") + std::string("Moore refinement: ") + result.message;
  }
  fillBranchPointGeometry(sp, tangentRef, options_.denseAlgebra);
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
    sp.note += (sp.note.empty() ? "" : "; ") + std::string("branch-point refinement (structured): ") + result.message;
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
    structured_ = std::make_unique<StructuredRefinement>(problem_, *refinementSolver_, options_.location.tolerance,
                                                         options_.location.maxRefinementIterations);
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

void Locator::fillBranchPointGeometry(SpecialPoint &sp, const Vector &tangentRef, bool dense) {
  if (!dense) return;  // null vectors need the dense kernel
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
  const TestFunction single = [this, index](const ContinuationPoint &p, double &f) {
    return crossingEigenvalue(problem_, p, index, f);
  };
  double fLo = 0.0, fHi = 0.0;
  Root root;
  bool ok = false;
  bool onMean = mean(lo.point, fLo) && mean(hi.point, fHi) && !sameSign(fLo, fHi);
  if (onMean) ok = findRoot(lo, fLo, hi, fHi, mean, root);
  else if (single(lo.point, fLo) && single(hi.point, fHi) && !sameSign(fLo, fHi))
    ok = findRoot(lo, fLo, hi, fHi, single, root);
  const StepSample &at = ok ? root.at : lo;
  placeAt(sp, at.point, ok ? root.value : fLo);
  sp.lambdaAccuracy = std::abs(hi.point.lambda - lo.point.lambda);
  if (ok && root.evaluations > 0) sp.lambdaAccuracy = std::min(sp.lambdaAccuracy, root.lastDLambda);
  sp.locationIterations = root.evaluations;
  sp.note = format("multiplicity %.0f: crossings not separable by inertia bisection (bracket |ds| = ", multiplicity) +
            format("%.3g); ", hi.s - lo.s) +
            (onMean ? "located on the mean of the crossing eigenvalues" : "located on the lowest crossing eigenvalue");
  sp.residualNorm = residualNorm(sp.u, sp.lambda);
  const bool dense = options_.denseAlgebra || options_.denseMultiplePoints;
  if (dense) {
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
  fillBranchPointGeometry(sp, a_.point.tangent, dense);
  return sp;
}

}  // namespace buckle::continuation
