// A Problem bound to a workspace: the one handle through which the continuation core evaluates.
//
// A Problem is read-only and evaluates into a ProblemWorkspace the caller owns (problem.h). The
// core binds the two once per computation (a trace, a tree, a located point, a derivative check)
// and then calls the evaluations without the workspace argument, as on the problem alone.
// A BoundProblem is a handle: its copies share one workspace, so a copy must stay on the thread
// of the original. Made from a problem alone it owns a new workspace (problem.createWorkspace());
// made from a problem and a workspace it borrows the workspace, which then must outlive it: a
// caller that runs several computations on one problem passes its own workspace to keep the
// problem's warm starts and caches across them.
#pragma once

#include <memory>
#include <string>

#include "buckle/continuation/problem.h"

namespace buckle::continuation {

class BoundProblem {
 public:
  /// Owns a new workspace of `problem` (implicit: a function taking a BoundProblem accepts a
  /// problem and evaluates it in a workspace of its own).
  BoundProblem(const Problem &problem)  // NOLINT(google-explicit-constructor)
      : problem_(&problem), ws_(problem.createWorkspace()) {}
  /// Borrows `ws` (made by problem.createWorkspace(), outliving this handle and its copies).
  BoundProblem(const Problem &problem, ProblemWorkspace &ws)
      : problem_(&problem), ws_(std::shared_ptr<ProblemWorkspace>(), &ws) {}

  const Problem &problem() const { return *problem_; }
  ProblemWorkspace &workspace() const { return *ws_; }

  int dimension() const { return problem_->dimension(); }
  bool residual(ConstVectorRef u, double lambda, VectorRef F) const { return problem_->residual(*ws_, u, lambda, F); }
  bool jacobian(ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Flambda) const {
    return problem_->jacobian(*ws_, u, lambda, Fu, Flambda);
  }
  bool jacobianWritesAllEntries() const { return problem_->jacobianWritesAllEntries(); }
  bool jacobianDirectionalDerivative(ConstVectorRef u, double lambda, ConstVectorRef du, double dlambda, MatrixRef dFu,
                                     VectorRef dFlambda) const {
    return problem_->jacobianDirectionalDerivative(*ws_, u, lambda, du, dlambda, dFu, dFlambda);
  }
  bool jacobianApply(ConstVectorRef u, double lambda, ConstVectorRef x, VectorRef y) const {
    return problem_->jacobianApply(*ws_, u, lambda, x, y);
  }
  bool jacobianTransposeApply(ConstVectorRef u, double lambda, ConstVectorRef w, VectorRef y) const {
    return problem_->jacobianTransposeApply(*ws_, u, lambda, w, y);
  }
  bool secondDerivativeTransposeApply(ConstVectorRef u, double lambda, ConstVectorRef x, ConstVectorRef w,
                                      VectorRef y) const {
    return problem_->secondDerivativeTransposeApply(*ws_, u, lambda, x, w, y);
  }
  bool secondDerivativeApply(ConstVectorRef u, double lambda, ConstVectorRef x, ConstVectorRef z, VectorRef y) const {
    return problem_->secondDerivativeApply(*ws_, u, lambda, x, z, y);
  }
  bool hasStabilityOperator() const { return problem_->hasStabilityOperator(); }
  bool stabilityOperator(ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const {
    return problem_->stabilityOperator(*ws_, u, lambda, H, C);
  }
  bool stability(ConstVectorRef u, double lambda, int lowestCount, StabilityInfo &info) const {
    return problem_->stability(*ws_, u, lambda, lowestCount, info);
  }
  bool stabilityEigenvalues(ConstVectorRef u, double lambda, int first, VectorRef values) const {
    return problem_->stabilityEigenvalues(*ws_, u, lambda, first, values);
  }
  bool stabilityRateBound(ConstVectorRef u, double lambda, ConstVectorRef du, double dlambda, double &bound) const {
    return problem_->stabilityRateBound(*ws_, u, lambda, du, dlambda, bound);
  }
  bool stabilitySlopes(ConstVectorRef u, double lambda, ConstVectorRef du, double dlambda, int first,
                       ConstVectorRef values, VectorRef slopes) const {
    return problem_->stabilitySlopes(*ws_, u, lambda, du, dlambda, first, values, slopes);
  }
  std::unique_ptr<BorderedSolver> makeStructuredSolver() const;
  int boundaryCount() const { return problem_->boundaryCount(); }
  double boundary(int k, ConstVectorRef u, double lambda) const { return problem_->boundary(*ws_, k, u, lambda); }
  void boundaries(ConstVectorRef u, double lambda, VectorRef g) const { problem_->boundaries(*ws_, u, lambda, g); }
  std::string boundaryName(int k) const { return problem_->boundaryName(k); }
  ProblemScales scales() const { return problem_->scales(); }

 private:
  const Problem *problem_;
  std::shared_ptr<ProblemWorkspace> ws_;  // owned, or aliasing a borrowed workspace (no owner)
};

}  // namespace buckle::continuation
