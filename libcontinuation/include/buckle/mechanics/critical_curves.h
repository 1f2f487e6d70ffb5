// Two-parameter continuation of the chain (issue 15): the chain's equilibrium with a second
// parameter μ (a segment parameter of every segment or of one, a preload difference, or a
// second end load / held coordinate) as a continuation::TwoParameterProblem, and the critical
// curves traced by the generic core:
//   branch-point curves of the straight chain (branch_point_curve.h): the critical load of a
//     buckling mode as a function of μ (eq 17 for three segments), with the codimension-two
//     points on it: "K0", the critical load passes through zero (the straight chain's stiffness
//     vanishes, κ = 0), and "DP", the degenerate pitchfork where the post-buckling coefficient b
//     changes sign (supercritical ↔ subcritical);
//   fold curves (fold_curve.h) from a located fold: "CP", cusps (two folds meet), and "BD",
//     the fold reaching a joint limit (where the curve stops).
// The exact μ-derivatives come from Segment::energyJetParameterDerivative and the link lengths'
// dependence on b (chain.h: ℓ0 = b1, ℓi = b2 + b1 of the next segment, ℓn = b2).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "buckle/continuation/branch.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/continuation/tracer.h"
#include "buckle/continuation/two_parameter.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/post_buckling.h"

namespace buckle::mechanics {

/// Which chain parameter is μ.
struct SecondParameter {
  enum class Kind {
    A,                  ///< a1 = a2 = μ (triangle half-height)
    B,                  ///< b1 = b2 = μ (half-length; moves the link lengths too)
    K,                  ///< k1 = k2 = μ
    L0,                 ///< mean free length (L1_0 + L2_0)/2 = μ, the difference kept
    PreloadDifference,  ///< L1_0 − L2_0 = μ, the mean kept
    End,                ///< the end condition's value of coordinate `component` (a load or a held coordinate)
  };
  Kind kind = Kind::L0;
  int segment = -1;     ///< 0-based segment, −1: every segment (segment kinds only)
  int component = 1;    ///< End: 0 x (Fx), 1 y (Fy), 2 φ (Me)

  /// "a", "b", "k", "L0", "dL0", "x", "y", "phi" (with "[i]" for one segment, 1-based).
  std::string name() const;
  /// Parses name() (a kind name; segment is given apart). Throws std::invalid_argument naming it.
  static SecondParameter parse(const std::string& kind, int segment = -1);
};

/// The equilibrium problem of a chain (equilibrium_problem.h) with μ as a second parameter.
/// Setting μ rebuilds the chain (O(n)); μ for which a segment is invalid is refused. The O(n)
/// products and the structured solver are the chain's (chain_solver.h), the solver following the
/// rebuilt chain (it is recreated when μ has changed since its last factorization).
class ChainParameterProblem final : public continuation::TwoParameterProblem {
 public:
  /// μ starts at the value the chain has (segment `segment`, or the first, for "every segment";
  /// setting μ makes every affected segment take it). Throws std::invalid_argument for bad input.
  ChainParameterProblem(std::vector<SegmentParameters> segments, const EndCondition& end,
                        const Eigen::Vector3d& direction, const SecondParameter& parameter,
                        EquilibriumOptions options = {});

  const EquilibriumProblem& equilibrium() const { return *equilibrium_; }

  /// The workspace of the equilibrium problem at the current μ (setting μ rebuilds that problem,
  /// so its workspace is rebuilt with it: its caches belong to the previous chain).
  struct Workspace : continuation::ProblemWorkspace {
    long generation = -1;
    std::unique_ptr<continuation::ProblemWorkspace> equilibrium;
  };
  std::unique_ptr<continuation::ProblemWorkspace> createWorkspace() const override {
    return std::make_unique<Workspace>();
  }
  /// The equilibrium problem's workspace within `ws` (made for the current μ when needed).
  continuation::ProblemWorkspace& equilibriumWorkspace(continuation::ProblemWorkspace& ws) const;
  const std::vector<SegmentParameters>& segments() const { return segments_; }
  const SecondParameter& parameter() const { return parameter_; }

  double secondParameter() const override { return mu_; }
  bool setSecondParameter(double mu) override;
  bool secondParameterDerivatives(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                                  continuation::ConstVectorRef v, continuation::VectorRef Fmu,
                                  continuation::VectorRef FuMuV) const override;
  /// b̄ for lengths, k̄ for k, k̄b̄ / k̄b̄² for an end force / torque, b̄ / 1 for a held position / angle.
  double secondParameterScale() const override;

  int dimension() const override { return equilibrium_->dimension(); }
  bool residual(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                continuation::VectorRef F) const override {
    return equilibrium_->residual(equilibriumWorkspace(ws), u, lambda, F);
  }
  bool jacobian(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                continuation::MatrixRef Fu, continuation::VectorRef Flambda) const override {
    return equilibrium_->jacobian(equilibriumWorkspace(ws), u, lambda, Fu, Flambda);
  }
  bool jacobianDirectionalDerivative(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                                     continuation::ConstVectorRef du, double dlambda, continuation::MatrixRef dFu,
                                     continuation::VectorRef dFlambda) const override {
    return equilibrium_->jacobianDirectionalDerivative(equilibriumWorkspace(ws), u, lambda, du, dlambda, dFu, dFlambda);
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda, Matrix& H,
                         Matrix& C) const override {
    return equilibrium_->stabilityOperator(equilibriumWorkspace(ws), u, lambda, H, C);
  }
  bool stability(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda, int lowestCount,
                 continuation::StabilityInfo& info) const override {
    return equilibrium_->stability(equilibriumWorkspace(ws), u, lambda, lowestCount, info);
  }
  /// Exact (∂F_u/∂λ)·v in O(n): the dead loads' λ-derivative of K_g (eq 27), −[h'_max(i,j)] v_q.
  bool parameterJacobianApply(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                              continuation::ConstVectorRef v, continuation::VectorRef FuLambdaV) const override;
  bool jacobianApply(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                     continuation::ConstVectorRef x, continuation::VectorRef y) const override {
    return equilibrium_->jacobianApply(equilibriumWorkspace(ws), u, lambda, x, y);
  }
  bool jacobianTransposeApply(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                              continuation::ConstVectorRef w, continuation::VectorRef y) const override {
    return equilibrium_->jacobianTransposeApply(equilibriumWorkspace(ws), u, lambda, w, y);
  }
  /// The chain's O(n) bordered solver, recreated for the current chain whenever μ has changed.
  std::unique_ptr<continuation::BorderedSolver> makeStructuredSolver(continuation::ProblemWorkspace& ws) const override;
  /// Incremented whenever setting μ rebuilds the chain (what the structured solver follows).
  long generation() const { return generation_; }
  continuation::ProblemScales scales() const override { return equilibrium_->scales(); }
  int boundaryCount() const override { return equilibrium_->boundaryCount(); }
  double boundary(continuation::ProblemWorkspace& ws, int k, continuation::ConstVectorRef u,
                  double lambda) const override {
    return equilibrium_->boundary(equilibriumWorkspace(ws), k, u, lambda);
  }
  std::string boundaryName(int k) const override { return equilibrium_->boundaryName(k); }

 private:
  /// The segments with μ applied; false when μ is not finite.
  bool applied(double mu, std::vector<SegmentParameters>& out, EndCondition& end) const;
  bool affects(int segment) const { return parameter_.segment < 0 || parameter_.segment == segment; }

  std::vector<SegmentParameters> segments_;
  EndCondition end_;
  Eigen::Vector3d direction_;
  SecondParameter parameter_;
  EquilibriumOptions options_;
  double mu_ = 0.0;
  long generation_ = 0;
  std::unique_ptr<EquilibriumProblem> equilibrium_;
  // Scratch of the μ derivatives: like the curve problems (fold_curve.h), a two-parameter problem
  // is one computation's object (μ is set on it), so it keeps its scratch itself.
  mutable std::unique_ptr<ChainData> data_;
  mutable Vector dl_, dS_, dC_, dE1_, dE2_, dh_;
};

/// One point of a critical curve.
struct CriticalPoint {
  double mu = 0.0;
  double lambda = 0.0;    ///< the critical load factor
  Vector u;               ///< the state (fold) or the trivial state (branch point)
  Vector mode;            ///< the null vector, unit length in the joint angles
  double kappa = 0.0;     ///< smallest straight-state joint stiffness K_q(0) of the segments
  /// Branch points: λ = λc + aξ + bξ² along the bifurcated branch, ξ the amplitude of the unit
  /// joint-angle mode (bifurcation_coefficients.h). Folds: NaN.
  double koiterA = 0.0, koiterB = 0.0;
  PostBuckling kind = PostBuckling::None;  ///< branch points: koiterKind(); Failed when not computed
  double cusp = 0.0;      ///< folds: the cusp test ψᵀF_uu[v, v] (normalised); NaN for branch points
};

/// A codimension-two point on a critical curve.
struct Codim2Point {
  std::string label;      ///< "K0" zero critical load (κ = 0), "DP" degenerate pitchfork, "CP" cusp, "BD" joint limit
  double mu = 0.0;
  double lambda = 0.0;
  /// along the curve in the scaled variables (curve_zeros.h); "K0": the bracket in μ over its
  /// scale; 0 for "BD" (located by the tracer)
  double accuracy = 0.0;
  bool converged = false;
  std::string note;       ///< "BD": which limit
};

struct CriticalCurve {
  std::string type;       ///< "BP" or "LP"
  SecondParameter parameter;
  std::vector<CriticalPoint> points;  ///< in increasing arclength, both directions joined
  std::vector<Codim2Point> special;
  std::string stopMessage;            ///< why each direction ended
};

struct CriticalCurveOptions {
  double muMin = -1e300, muMax = 1e300;  ///< the range of μ
  continuation::TracerOptions tracer;    ///< step control of the curve (its λ range is μ's)
  bool bothDirections = true;
  bool coefficients = true;              ///< branch points: Koiter coefficients at every point
  /// From this chain dimension N = n + m on (tracer.linearAlgebra Automatic), the curves use the
  /// chain's O(n) structure: the fold curve by the minimally augmented system
  /// (MinimalFoldCurveProblem), the branch-point curve with the structured bordered solver; below
  /// it the dense systems (FoldCurveProblem, the (N+1)² LU). A speed crossover only: the same
  /// curves. tracer.linearAlgebra Dense / Structured force either path. The Koiter coefficients
  /// (coefficients, "DP") stay dense, O(n³) per point. Measured (benchmarks/RESULTS.md): the BP
  /// curve is faster structured from n = 10 (N = 12), the fold curve from about n = 20.
  int structuredFromDimension = 20;
  /// Empty when valid, else what is wrong, the field named by its path after `prefix`.
  std::string validate(const std::string& prefix = "") const;
  bool IsValid(std::string* why) const { return continuation::reportValidity(validate(), why); }
};

/// Branch-point curve of the straight chain's compressive buckling mode `mode` (0: the first)
/// under the clamped/held conditions of the problem's end condition and its load direction,
/// traced in μ from the problem's current μ. Throws std::invalid_argument when the straight
/// chain is not an equilibrium along the load path or has no such mode.
CriticalCurve branchPointCurve(ChainParameterProblem& problem, int mode, const CriticalCurveOptions& options);

/// Fold curve from a fold located on an equilibrium branch of the problem at its current μ.
CriticalCurve foldCurve(ChainParameterProblem& problem, const continuation::SpecialPoint& fold,
                        const CriticalCurveOptions& options);

/// Supercritical when the bifurcated branch of a symmetric pitchfork (|a| ≤ aTolerance) lies on
/// the side of λc where the trivial branch is unstable: the critical eigenvalue of K_q − K_g
/// falls through zero in the direction −sign(ψᵀF_uλ v) (F_u symmetric, ψ ∥ v), so b·ψᵀF_uλ v < 0.
/// Under compression with κ > 0 that is b·λc > 0: |λ| rises along the buckled branch. Subcritical
/// otherwise, and for a ≠ 0 (an asymmetric point is imperfection sensitive).
PostBuckling koiterKind(double a, double b, double transversality, double aTolerance);

}  // namespace buckle::mechanics
