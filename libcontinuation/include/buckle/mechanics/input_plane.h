// The plane of two control inputs (issue 29, workspace and stability maps; docs/mechanics.md,
// "Workspace and stability maps"). Two named inputs u = (u₁, u₂) of the chain (control_path.h:
// L1_0, L2_0, L0, dL0, of every segment or of one) move the springs' free lengths,
//     L⁰(u) = L⁰ + (u₁ − u₁⁰) r₁ + (u₂ − u₂⁰) r₂,
// with u⁰ the inputs' values on the chain and the end under a fixed payload (end loads, weight,
// point loads). The inputs must be independent: moving one leaves the other's value unchanged
// (ℓ₁(r₂) = ℓ₂(r₁) = 0 for the inputs' linear functionals ℓ), so both readings are absolute
// (L0 and dL0 of the same segments, L1_0 and L2_0, or inputs of different segments). An input
// may be a direction in control space (PlaneInput::along): r adds rates of its complementary input.
//
// Equilibria F(q; u) = ∂E/∂q − Jᵀ W = 0 (eq 11 with the payload W) form a two-dimensional sheet
// over the plane. Three kinds of curve bound the part of the end's workspace held by a stable
// equilibrium:
//   fold       det(K_q − K_g) = 0: the equilibrium loses stability (a fold of the sheet over the
//              plane; moving the inputs across it makes the chain snap);
//   singular   det ∂p/∂u = 0 for the end position p = (x, y): the map from the inputs to the
//              end's position folds, so the image of the plane turns back there (its envelope);
//   limit      a joint at its stop (q_j = q_max or q_min);
// and the box of the inputs' bounds. Each is traced by continuation of the augmented system
//     F(q; u₁, u₂) = 0,   c(q, u₁, u₂) = 0
// in U = (q, u₂) with λ = u₁ (InputPlaneCurveProblem), c the condition made dimensionless:
//     fold      c = μ_min(K_q − K_g) / κ̄                (the smallest eigenvalue, dense)
//     singular  c = det J / (½‖J‖²_F),  J = ∂p/∂q · W,  (K_q − K_g) W = −[F_u₁ F_u₂]
//     limit     c = the joint-limit gap g_k (rad).
// The F rows and their derivatives are exact (the equilibrium problem's); the c row's gradient
// is by central differences of c (n + 2 evaluations, each a dense O(n³) solve): it only steers
// Newton, while the residual — and so the accuracy reported for every curve point — is exact.
#pragma once

#include <memory>
#include <string>
#include <utility>

#include "buckle/continuation/interrupt.h"
#include "buckle/continuation/problem.h"
#include "buckle/mechanics/body_loads.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/control_path.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

/// One input of the plane: a named input of every segment (−1) or of one (0-based), optionally
/// a direction in control space: moving it by du also moves the complementary input
/// (complementaryInput: L0 ↔ dL0, L1_0 ↔ L2_0) by along·du, as a control path's /path/direction.
/// Its value is still the named input's.
struct PlaneInput {
  PlaneInput() = default;
  PlaneInput(ControlInput input_, int segment_ = -1, Eigen::VectorXd along_ = Eigen::VectorXd())
      : input(input_), segment(segment_), along(std::move(along_)) {}
  ControlInput input = ControlInput::dL0;
  int segment = -1;
  /// Rates of the complementary input per unit of this one: empty (none), one value for every
  /// segment, or one per segment.
  Eigen::VectorXd along;
  /// "dL0", "L0[2]" (1-based segment); with `along`, "dL0 + 0.5 L0" or "dL0 + (0.5 0 1) L0" (up to
  /// six rates, else "(per-segment rates)").
  std::string name() const;
};

class InputPlane {
 public:
  /// The payload `end` must hold no coordinate (the end moves over the workspace). Throws
  /// std::invalid_argument naming the problem: a held end coordinate, a segment out of range,
  /// inputs that are not independent (file comment).
  InputPlane(const Chain& chain, const EndCondition& end, const BodyLoads& body, const PlaneInput& first,
             const PlaneInput& second, EquilibriumOptions options = {});

  const Chain& chain() const { return chain_; }
  int segments() const { return chain_.size(); }
  const PlaneInput& input(int axis) const { return axis == 0 ? first_ : second_; }
  /// u⁰: the inputs' values on the chain.
  double origin(int axis) const { return axis == 0 ? d1_.origin : d2_.origin; }
  const ControlDirection& direction(int axis) const { return axis == 0 ? d1_ : d2_; }
  const EndCondition& end() const { return end_; }

  /// The equilibrium problem whose parameter λ is input `axis` with the other input at `other`
  /// (the chain's free lengths moved by the other input first; O(n), allocates). Throws
  /// std::invalid_argument where a free length is not positive.
  std::unique_ptr<EquilibriumProblem> along(int axis, double other) const;
  /// The chain with its free lengths at u.
  Chain chainAt(double u1, double u2) const;
  /// The admissible range of input `axis` (every free length it moves stays > 0).
  std::pair<double, double> admissibleRange(int axis) const;

 private:
  Chain chain_;
  EndCondition end_;
  BodyLoads body_;
  PlaneInput first_, second_;
  ControlDirection d1_, d2_;
  EquilibriumOptions options_;
};

/// The augmented system of one bounding curve (file comment): U = (q, u₂), λ = u₁.
class InputPlaneCurveProblem final : public continuation::Problem {
 public:
  enum class Condition { Fold, Singular, Limit };
  /// `boundary`: for Limit, which joint-limit boundary of the equilibrium problem (0-based).
  InputPlaneCurveProblem(const InputPlane& plane, Condition condition, int boundary = -1);

  struct Workspace : continuation::ProblemWorkspace {
    double cached2 = 0.0, cached1 = 0.0;
    std::unique_ptr<EquilibriumProblem> along1, along2;  // λ = u₁ at u₂ = cached2; λ = u₂ at u₁ = cached1
    std::unique_ptr<continuation::ProblemWorkspace> ws1, ws2;
    Matrix Fq, Fq2, W;
    Vector F1, F2, x, G;
    ChainData data;
    explicit Workspace(const Chain& chain) : data(chain) {}
  };
  std::unique_ptr<continuation::ProblemWorkspace> createWorkspace() const override;

  int dimension() const override { return n_ + 1; }
  bool residual(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef U, double u1,
                continuation::VectorRef G) const override;
  bool jacobian(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef U, double u1,
                continuation::MatrixRef GU, continuation::VectorRef Gu1) const override;
  bool jacobianWritesAllEntries() const override { return true; }
  continuation::ProblemScales scales() const override;

  /// The condition c at (q, u₁, u₂) (file comment); false where it is not defined (a singular
  /// K_q − K_g for Singular, a free length ≤ 0).
  bool condition(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef q, double u1, double u2,
                 double& c) const;
  /// The equilibrium problem along u₁ at u₂ and its workspace (cached in `ws`).
  const EquilibriumProblem& alongFirst(continuation::ProblemWorkspace& ws, double u2,
                                       continuation::ProblemWorkspace*& eqWs) const;

  Condition kind() const { return condition_; }
  /// A time limit or signal to honour inside one Jacobian (n + 2 dense solves: minutes for a long
  /// chain): once it is requested the Jacobian fails, and the tracer stops on its own check.
  void watch(const continuation::Interrupt* stop) { stop_ = stop; }
  int boundaryIndex() const { return boundary_; }

 private:
  const EquilibriumProblem& alongSecond(Workspace& w, double u1) const;

  const InputPlane& plane_;
  Condition condition_;
  int boundary_;
  int n_;
  double scale1_, scale2_, stiffness_;
  const continuation::Interrupt* stop_ = nullptr;
};

/// "fold", "singular", "limit".
const char* conditionName(InputPlaneCurveProblem::Condition condition);

}  // namespace buckle::mechanics
