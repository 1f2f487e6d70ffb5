#include "buckle/continuation/corrector.h"

#include "buckle/continuation/internal/finite.h"
#include "buckle/continuation/internal/serial_vector_ops.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace buckle::continuation {

std::string CorrectorOptions::validate(const std::string &prefix) const {
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) return prefix + "tolerance must be positive and finite";
  if (!(stepTolerance > 0.0) || !std::isfinite(stepTolerance))
    return prefix + "stepTolerance must be positive and finite";
  if (maxIterations < 1) return prefix + "maxIterations must be at least 1";
  if (!(maxNewtonStep >= 0.0) || !std::isfinite(maxNewtonStep)) return prefix + "maxNewtonStep must be finite and >= 0";
  if (!(stagnationFactor >= 1.0) || !std::isfinite(stagnationFactor))
    return prefix + "stagnationFactor must be finite and >= 1";
  return {};
}

bool CorrectorOptions::IsValid(std::string *why) const { return reportValidity(validate(), why); }

Corrector::Corrector(const BoundProblem &problem, const CorrectorOptions &options, BorderedSolver *structured)
    : problem_(problem),
      structured_(structured),
      options_(options),
      n_(problem.dimension()),
      writesAll_(problem.jacobianWritesAllEntries()) {
  std::string why;
  if (!options_.IsValid(&why)) throw std::invalid_argument("CorrectorOptions: " + why);
  if (n_ < 1) throw std::invalid_argument("Problem::dimension() must be positive");
  const sunindextype m = n_ + 1;
  predictor_ = Vector::Zero(m);
  tangent_ = Vector::Zero(m);
  lastIterate_ = Vector::Zero(m);
  unit_ = Vector::Zero(m);
  iterate_ = Vector::Zero(m);
  residual_ = Vector::Zero(m);
  step_ = Vector::Zero(m);
  trial_ = Vector::Zero(m);
  trialResidual_ = Vector::Zero(m);
  // Full Newton evaluates once per iterate plus once per recoverable halving (at most 5 each).
  stepNorms_.reserve(static_cast<std::size_t>(8 * options_.maxIterations + 16));

  context_ = makeSunContext();
  x_ = makeSerialVector(m, context_.get());
  scale_ = makeSerialVector(m, context_.get());
  // Before KINInit, which clones its work vectors from x_ (serial_vector_ops.h).
  useLeanSerialOperations(x_.get());
  useLeanSerialOperations(scale_.get());
  N_VConst(1.0, scale_.get());
  if (!structured_) dense_.emplace(static_cast<int>(m), DenseLU::Rounding::Reciprocal);
  jacobian_ = makeEmptyCustomMatrix(context_.get());
  linearSolver_ =
      makeCustomDirectLinearSolver(&Corrector::linearSolve, this, context_.get(), &Corrector::linearSetup);
  kinsol_ = makeKinsolMemory(context_.get());
  void *mem = kinsol_.get();
  if (KINInit(mem, &Corrector::systemFunction, x_.get()) != KIN_SUCCESS ||
      KINSetUserData(mem, this) != KIN_SUCCESS ||
      KINSetLinearSolver(mem, linearSolver_.get(), jacobian_.get()) != KINLS_SUCCESS ||
      KINSetJacFn(mem, &Corrector::jacobianFunction) != KINLS_SUCCESS ||
      KINSetErrHandlerFn(mem, &Corrector::errorHandler, this) != KIN_SUCCESS ||
      KINSetMaxSetupCalls(mem, 1) != KIN_SUCCESS)
    throw std::runtime_error("KINSOL set-up failed");
  applyOptions();
}

void Corrector::setOptions(const CorrectorOptions &options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("CorrectorOptions: " + why);
  options_ = options;
  const auto needed = static_cast<std::size_t>(8 * options_.maxIterations + 16);
  if (stepNorms_.capacity() < needed) stepNorms_.reserve(needed);
  applyOptions();
}

void Corrector::applyOptions() {
  void *mem = kinsol_.get();
  KINSetFuncNormTol(mem, options_.tolerance);
  KINSetScaledStepTol(mem, options_.stepTolerance);
  KINSetNumMaxIters(mem, options_.maxIterations);
  // Exact Newton with step control left to the continuation: no KINSOL step truncation.
  KINSetMaxNewtonStep(mem, options_.maxNewtonStep > 0.0 ? options_.maxNewtonStep : 1e100);
}

// NV_DATA_S in the callbacks: every vector KINSOL hands them is a serial clone of x_.
int Corrector::systemFunction(N_Vector x, N_Vector g, void *self) {
  auto *corrector = static_cast<Corrector *>(self);
  try {
    return corrector->evaluate(NV_DATA_S(x), NV_DATA_S(g));
  } catch (...) {
    corrector->pending_ = std::current_exception();
    return -1;  // unrecoverable: KINSOL returns at once and correct() rethrows
  }
}

int Corrector::jacobianFunction(N_Vector x, N_Vector, SUNMatrix, void *self, N_Vector, N_Vector) {
  auto *corrector = static_cast<Corrector *>(self);
  try {
    if (corrector->structured_) return corrector->factorStructured(NV_DATA_S(x));
    return corrector->evaluateJacobian(NV_DATA_S(x));
  } catch (...) {
    corrector->pending_ = std::current_exception();
    return -1;
  }
}

// Dense path: the factorization of the matrix the Jacobian callback wrote. A zero pivot is
// SUNLinSol_Dense's recoverable SUNLS_LUFACT_FAIL, so KINSOL reacts as it did with that solver.
int Corrector::linearSetup(SUNLinearSolver solver, SUNMatrix) {
  auto *corrector = static_cast<Corrector *>(customLinearSolverData(solver));
  if (!corrector->dense_) return SUNLS_SUCCESS;  // structured: factored in the Jacobian callback
  return corrector->dense_->factor() ? SUNLS_SUCCESS : SUNLS_LUFACT_FAIL;
}

int Corrector::linearSolve(SUNLinearSolver solver, SUNMatrix, N_Vector x, N_Vector b, realtype) {
  auto *corrector = static_cast<Corrector *>(customLinearSolverData(solver));
  const int m = corrector->n_ + 1;
  Eigen::Map<const Vector> rhs(NV_DATA_S(b), m);
  Eigen::Map<Vector> solution(NV_DATA_S(x), m);
  if (corrector->dense_) {
    solution = rhs;
    corrector->dense_->solveInPlace(solution);
    return SUNLS_SUCCESS;
  }
  try {
    return corrector->structured_->solve(rhs, solution) ? SUNLS_SUCCESS : SUNLS_PACKAGE_FAIL_UNREC;
  } catch (...) {
    corrector->pending_ = std::current_exception();
    return SUNLS_PACKAGE_FAIL_UNREC;
  }
}

int Corrector::factorStructured(const double *xData) {
  Eigen::Map<const Vector> x(xData, n_ + 1);
  return structured_->factor(x.head(n_), x[n_], tangent_) == Factorization::Regular ? 0 : -1;
}

void Corrector::errorHandler(int, const char *, const char *function, char *message, void *self) {
  auto &buffer = static_cast<Corrector *>(self)->lastError_;
  std::snprintf(buffer.data(), buffer.size(), "%s: %s", function ? function : "KINSOL", message ? message : "");
}

int Corrector::evaluate(const double *xData, double *gData) {
  const int m = n_ + 1;
  Eigen::Map<const Vector> x(xData, m);
  Eigen::Map<Vector> g(gData, m);
  ++evaluations_;
  if (haveLastIterate_ && stepNorms_.size() < stepNorms_.capacity())
    stepNorms_.push_back((x - lastIterate_).norm());
  lastIterate_ = x;
  haveLastIterate_ = true;
  if (!allFinite(xData, m) || !problem_.residual(x.head(n_), x[n_], g.head(n_))) {
    refused_ = true;
    return 1;  // recoverable: KINSOL halves the step
  }
  g[n_] = tangent_.dot(x - predictor_);
  return allFinite(gData, m) ? 0 : 1;
}

int Corrector::evaluateJacobian(const double *xData) {
  const int m = n_ + 1;
  Eigen::Map<const Vector> x(xData, m);
  Eigen::Map<Matrix> J = dense_->matrix();
  if (!writesAll_) J.setZero();
  if (!problem_.jacobian(x.head(n_), x[n_], J.topLeftCorner(n_, n_), J.col(n_).head(n_))) return -1;
  J.row(n_) = tangent_.transpose();
  return allFinite(J.data(), J.size()) ? 0 : -1;
}

namespace {
// KINSOL's norms with unit scales (fscale = uscale = 1, so its products with the scales are
// exact): the weighted 2-norm as a sequential sum of squares, the max norm as the first-largest
// |v_i| (serial_vector_ops.h, the operations KINSOL calls on our vectors).
double l2Norm(const Vector &v) {
  double sum = 0.0;
  for (Eigen::Index i = 0; i < v.size(); ++i) sum += v[i] * v[i];
  return std::sqrt(sum);
}
double maxNorm(const Vector &v) {
  double max = 0.0;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (std::abs(v[i]) > max) max = std::abs(v[i]);
  return max;
}
}  // namespace

// KINSol with KIN_NONE, our direct linear solver, unit scales, KINSetMaxSetupCalls(1) and no
// constraints, step by step (SUNDIALS 6.4 kinsol.c: KINSolInit, KINLinSolDrv, KINFullNewton,
// KINStop): the same callbacks on the same vectors in the same order, so the iterates, the
// counts and the norms are KINSOL's bit for bit. What KINSOL adds per call — its set-up, the
// N_Vector dispatch, the line-search and forcing-term bookkeeping that full Newton with a direct
// solver never reads — costs ≈ 2 k instructions per continuation point at N+1 = 4
// (benchmarks/RESULTS.md, "round 6"). Only the two plain outcomes are taken here; every other
// path (a refused or failed evaluation, a failed set-up or solve, a step at KINSOL's maximum
// length, the step tolerance, the iteration limit) returns false before anything is reported,
// and correct() runs KINSOL from the same predictor: those outcomes stay KINSOL's own.
bool Corrector::leanNewton(CorrectorSummary &summary) {
  const Eigen::Index m = n_ + 1;
  std::copy(predictor_.data(), predictor_.data() + m, iterate_.data());
  // KINSolInit: F at the initial guess; fmax = ‖F‖∞ against 0.01·fnormtol.
  if (evaluate(iterate_.data(), residual_.data()) != 0) return false;
  const double fnormtol = options_.tolerance;
  long iterations = 0;
  double fnorm = 0.0;
  int flag = KIN_SUCCESS;
  if (maxNorm(residual_) <= 0.01 * fnormtol) {
    fnorm = l2Norm(residual_);
    flag = KIN_INITIAL_GUESS_OK;
  } else {
    // KINSolInit's maximum step: the one set (KINSetMaxNewtonStep), at least 1.
    const double maxStep = std::max(1.0, options_.maxNewtonStep > 0.0 ? options_.maxNewtonStep : 1e100);
    for (;;) {
      ++iterations;
      // KINLinSolDrv: the set-up at every iterate (one setup call per Newton iteration): the
      // Jacobian callback at uu, then the solver's setup (the dense factorization).
      if (structured_) {
        if (factorStructured(iterate_.data()) != 0) return false;
      } else if (evaluateJacobian(iterate_.data()) != 0 || !dense_->factor()) {
        return false;
      }
      // b = −F (N_VScale(−1): exact), then pp = J⁻¹b as linearSolve() computes it.
      for (Eigen::Index i = 0; i < m; ++i) trial_[i] = -residual_[i];
      if (structured_) {
        if (!structured_->solve(trial_, step_)) return false;
      } else {
        std::copy(trial_.data(), trial_.data() + m, step_.data());
        dense_->solveInPlace(step_.data());
      }
      // KINFullNewton: a step beyond 0.99·mxnewtstep is truncated or counted by KINSOL.
      if (l2Norm(step_) > 0.99 * maxStep) return false;
      for (Eigen::Index i = 0; i < m; ++i) trial_[i] = iterate_[i] + step_[i];  // N_VLinearSum: uu + pp
      if (evaluate(trial_.data(), trialResidual_.data()) != 0) return false;  // KINSOL would halve the step
      const double fnormp = l2Norm(trialResidual_);
      // KINStop: converged on ‖F‖∞ ≤ fnormtol; else the scaled step ‖(unew − uu)/(1 + |unew|)‖∞
      // against scsteptol and the iteration limit, both KINSOL's to report.
      if (maxNorm(trialResidual_) <= fnormtol) {
        std::swap(iterate_, trial_);
        fnorm = fnormp;
        break;
      }
      double rlength = 0.0;
      for (Eigen::Index i = 0; i < m; ++i) {
        const double scaled = std::abs((trial_[i] - iterate_[i]) / (1.0 + std::abs(trial_[i])));
        if (scaled > rlength) rlength = scaled;
      }
      if (rlength <= options_.stepTolerance || iterations >= options_.maxIterations) return false;
      // uu ← unew; fval already holds F(unew) in KINSOL (func writes it in place)
      std::swap(iterate_, trial_);
      std::swap(residual_, trialResidual_);
    }
  }
  std::copy(iterate_.data(), iterate_.data() + m, NV_DATA_S(x_.get()));  // KINSOL's u on return
  summary.flag = flag;
  summary.iterations = static_cast<int>(iterations);
  summary.residualNorm = fnorm;
  return true;
}

CorrectorSummary Corrector::correct(ConstVectorRef predictor, ConstVectorRef tangent, VectorRef x) {
  predictor_ = predictor;
  tangent_ = tangent;
  auto reset = [this]() {
    Eigen::Map<Vector>(NV_DATA_S(x_.get()), n_ + 1) = predictor_;
    stepNorms_.clear();
    haveLastIterate_ = false;
    refused_ = false;
    evaluations_ = 0;
    lastError_[0] = '\0';
  };
  reset();
  CorrectorSummary summary;
  if (options_.leanNewton && !options_.lineSearch && leanNewton(summary)) {
    summary.flagName = kinsolFlagName(summary.flag);
  } else {
    if (options_.leanNewton && !options_.lineSearch) reset();  // KINSOL from the same start
    void *mem = kinsol_.get();
    pending_ = nullptr;
    const int flag = KINSol(mem, x_.get(), options_.lineSearch ? KIN_LINESEARCH : KIN_NONE, scale_.get(),
                            scale_.get());
    if (pending_) std::rethrow_exception(std::exchange(pending_, nullptr));
    summary.flag = flag;
    summary.flagName = kinsolFlagName(flag);
    long iterations = 0;
    KINGetNumNonlinSolvIters(mem, &iterations);
    summary.iterations = static_cast<int>(iterations);
    double fnorm = 0.0;
    KINGetFuncNorm(mem, &fnorm);
    summary.residualNorm = fnorm;
  }
  const int flag = summary.flag;
  const double fnorm = summary.residualNorm;
  summary.residualEvaluations = evaluations_;
  summary.refusedPoint = refused_;
  if (!stepNorms_.empty()) summary.lastStepNorm = stepNorms_.back();
  for (std::size_t k = 1; k < stepNorms_.size(); ++k)
    if (stepNorms_[k - 1] > 0.0) summary.contraction = std::max(summary.contraction, stepNorms_[k] / stepNorms_[k - 1]);
  // A residual whose rounding floor lies above the tolerance (a long chain's held end coordinate
  // sums thousands of terms of the chain's length) never gets below it: Newton stalls at the
  // floor, on the step tolerance or, where a nearly singular Jacobian turns the floor's noise into
  // steps, by using up its iterations. Either counts as converged within stagnationFactor·tolerance
  // (the point keeps the residual it reached: ContinuationPoint::residualNorm).
  const bool stalled = flag == KIN_STEP_LT_STPTOL || flag == KIN_MAXITER_REACHED;
  summary.converged = flag == KIN_SUCCESS || flag == KIN_INITIAL_GUESS_OK ||
                      (stalled && fnorm <= options_.stagnationFactor * options_.tolerance);
  if (flag < 0 && lastError_[0] != '\0') summary.message = lastError_.data();
  x = Eigen::Map<const Vector>(NV_DATA_S(x_.get()), n_ + 1);
  return summary;
}

CorrectorSummary Corrector::solveWithFixedCoordinate(ConstVectorRef predictor, int index, VectorRef x) {
  unit_.setZero();
  unit_[index] = 1.0;
  CorrectorSummary summary = correct(predictor, unit_, x);
  if (summary.converged) x[index] = predictor_[index];  // linear constraint: exact up to rounding
  return summary;
}

CorrectorSummary Corrector::solveAtFixedParameter(ConstVectorRef u0, double lambda, VectorRef u) {
  // Build the predictor in the KINSOL vector itself: correct() copies it into predictor_ and
  // starts from it, so nothing is allocated.
  Eigen::Map<Vector> x(NV_DATA_S(x_.get()), n_ + 1);
  x.head(n_) = u0;
  x[n_] = lambda;
  unit_.setZero();
  unit_[n_] = 1.0;
  CorrectorSummary summary = correct(x, unit_, x);
  if (summary.converged) x[n_] = lambda;
  u = x.head(n_);
  return summary;
}

}  // namespace buckle::continuation
