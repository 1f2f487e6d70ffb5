#include "buckle/mechanics/input_plane.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace buckle::mechanics {

namespace cont = buckle::continuation;

std::string PlaneInput::name() const {
  std::string s = controlInputName(input) + (segment >= 0 ? "[" + std::to_string(segment + 1) + "]" : "");
  if (along.size() == 0) return s;
  std::ostringstream os;
  os.precision(6);
  // no commas: the name is a CSV field and a plot label
  if (along.size() <= 6)
    for (Eigen::Index i = 0; i < along.size(); ++i) os << (i ? " " : "") << along[i];
  else
    os << "per-segment rates";
  return s + " + " + (along.size() == 1 ? os.str() : "(" + os.str() + ")") + " " +
         controlInputName(complementaryInput(input));
}

InputPlane::InputPlane(const Chain& chain, const EndCondition& end, const BodyLoads& body, const PlaneInput& first,
                       const PlaneInput& second, EquilibriumOptions options)
    : chain_(chain), end_(end), body_(body), first_(first), second_(second), options_(options) {
  if (end.heldCount() > 0)
    throw std::invalid_argument("input plane: the end must hold no coordinate (the end moves over the workspace; "
                                "give the payload as loads)");
  const int n = chain.size();
  d1_ = ControlDirection::named(n, first.input, first.segment);
  d2_ = ControlDirection::named(n, second.input, second.segment);
  if (first.along.size() > 0) addComplementaryRates(d1_, first.input, first.along);
  if (second.along.size() > 0) addComplementaryRates(d2_, second.input, second.along);
  d1_.origin = controlInputValue(chain, first.input, first.segment);
  d2_.origin = controlInputValue(chain, second.input, second.segment);
  // ℓ₁(r₂) = ℓ₂(r₁) = 0: a small move of one input leaves the other's value (file comment); the
  // functionals are linear, so a move of 10⁻³ of the mean free length tells
  double mean = 0.0;
  for (int i = 0; i < n; ++i)
    mean += 0.5 * (chain.segment(i).parameters().L1_0 + chain.segment(i).parameters().L2_0) / n;
  const double delta = 1e-3 * mean;
  const auto moves = [&](const ControlDirection& d, const PlaneInput& other, double value) {
    const Chain moved = chainWithControls(chain, d, d.origin + delta);
    return std::abs(controlInputValue(moved, other.input, other.segment) - value) > 1e-8 * delta;
  };
  if (moves(d1_, second, d2_.origin) || moves(d2_, first, d1_.origin))
    throw std::invalid_argument("input plane: the inputs " + first.name() + " and " + second.name() +
                                " are not independent (moving one changes the other; use L0 and dL0, L1_0 and L2_0, "
                                "or inputs of different segments)");
}

std::unique_ptr<EquilibriumProblem> InputPlane::along(int axis, double other) const {
  const ControlDirection& moved = axis == 0 ? d2_ : d1_;
  const ControlDirection& path = axis == 0 ? d1_ : d2_;
  return std::make_unique<EquilibriumProblem>(chainWithControls(chain_, moved, other), end_, Eigen::Vector3d::Zero(),
                                              options_, path, body_);
}

Chain InputPlane::chainAt(double u1, double u2) const {
  return chainWithControls(chainWithControls(chain_, d2_, u2), d1_, u1);
}

std::pair<double, double> InputPlane::admissibleRange(int axis) const {
  return mechanics::admissibleRange(chain_, direction(axis));
}

const char* conditionName(InputPlaneCurveProblem::Condition condition) {
  switch (condition) {
    case InputPlaneCurveProblem::Condition::Fold: return "fold";
    case InputPlaneCurveProblem::Condition::Singular: return "singular";
    case InputPlaneCurveProblem::Condition::Limit: return "limit";
  }
  return "";
}

InputPlaneCurveProblem::InputPlaneCurveProblem(const InputPlane& plane, Condition condition, int boundary)
    : plane_(plane), condition_(condition), boundary_(boundary), n_(plane.segments()) {
  const auto p1 = plane.along(0, plane.origin(1));
  const auto p2 = plane.along(1, plane.origin(0));
  if (condition == Condition::Limit && (boundary < 0 || boundary >= p1->boundaryCount()))
    throw std::invalid_argument("input plane curve: boundary " + std::to_string(boundary) + " out of range");
  scale1_ = p1->scales().parameter;
  scale2_ = p2->scales().parameter;
  stiffness_ = p1->scales().stability;
}

std::unique_ptr<cont::ProblemWorkspace> InputPlaneCurveProblem::createWorkspace() const {
  auto w = std::make_unique<Workspace>(plane_.chain());
  w->cached1 = w->cached2 = std::numeric_limits<double>::quiet_NaN();
  w->Fq.resize(n_, n_);
  w->Fq2.resize(n_, n_);
  w->W.resize(n_, 2);
  w->F1.resize(n_);
  w->F2.resize(n_);
  w->x.resize(n_ + 2);
  w->G.resize(n_ + 1);
  return w;
}

const EquilibriumProblem& InputPlaneCurveProblem::alongFirst(cont::ProblemWorkspace& ws, double u2,
                                                             cont::ProblemWorkspace*& eqWs) const {
  Workspace& w = cont::workspaceAs<Workspace>(ws);
  if (!w.along1 || w.cached2 != u2) {
    w.along1 = plane_.along(0, u2);
    w.ws1 = w.along1->createWorkspace();
    w.cached2 = u2;
  }
  eqWs = w.ws1.get();
  return *w.along1;
}

const EquilibriumProblem& InputPlaneCurveProblem::alongSecond(Workspace& w, double u1) const {
  if (!w.along2 || w.cached1 != u1) {
    w.along2 = plane_.along(1, u1);
    w.ws2 = w.along2->createWorkspace();
    w.cached1 = u1;
  }
  return *w.along2;
}

bool InputPlaneCurveProblem::condition(cont::ProblemWorkspace& ws, cont::ConstVectorRef q, double u1, double u2,
                                       double& c) const {
  Workspace& w = cont::workspaceAs<Workspace>(ws);
  try {
    cont::ProblemWorkspace* ws1 = nullptr;
    const EquilibriumProblem& p1 = alongFirst(ws, u2, ws1);
    if (condition_ == Condition::Limit) {
      c = p1.boundary(*ws1, boundary_, q, u1);
      return std::isfinite(c);
    }
    if (!p1.jacobian(*ws1, q, u1, w.Fq, w.F1)) return false;
    if (condition_ == Condition::Fold) {
      // K_q − K_g is symmetric (the end holds nothing, so F_q is the Hessian itself)
      Eigen::SelfAdjointEigenSolver<Matrix> eig(w.Fq, Eigen::EigenvaluesOnly);
      if (eig.info() != Eigen::Success) return false;
      c = eig.eigenvalues()[0] / stiffness_;
      return std::isfinite(c);
    }
    const EquilibriumProblem& p2 = alongSecond(w, u1);
    if (!p2.jacobian(*w.ws2, q, u2, w.Fq2, w.F2)) return false;
    Eigen::PartialPivLU<Matrix> lu(w.Fq);
    Matrix rhs(n_, 2);
    rhs << w.F1, w.F2;
    w.W.noalias() = -lu.solve(rhs);
    if (!w.W.allFinite() || (w.Fq * w.W + rhs).norm() > 1e-8 * (w.Fq.norm() * w.W.norm() + rhs.norm()))
      return false;  // K_q − K_g singular: the equilibrium is at a fold, where J is not defined
    forwardKinematics(plane_.chain(), q, w.data);
    Eigen::Matrix2d J;
    J.row(0) = -w.data.S.transpose() * w.W;  // ∂x/∂q_j = −S_j (chain.h)
    J.row(1) = w.data.C.transpose() * w.W;   // ∂y/∂q_j = C_j
    const double norm2 = J.squaredNorm();
    if (!(norm2 > 0.0)) return false;
    c = J.determinant() / (0.5 * norm2);
    return std::isfinite(c);
  } catch (const std::invalid_argument&) {
    return false;  // a free length ≤ 0 at u
  }
}

bool InputPlaneCurveProblem::residual(cont::ProblemWorkspace& ws, cont::ConstVectorRef U, double u1,
                                      cont::VectorRef G) const {
  const double u2 = U[n_];
  if (!std::isfinite(u2) || !std::isfinite(u1)) return false;
  try {
    cont::ProblemWorkspace* ws1 = nullptr;
    const EquilibriumProblem& p1 = alongFirst(ws, u2, ws1);
    if (!p1.residual(*ws1, U.head(n_), u1, G.head(n_))) return false;
  } catch (const std::invalid_argument&) {
    return false;
  }
  return condition(ws, U.head(n_), u1, u2, G[n_]);
}

bool InputPlaneCurveProblem::jacobian(cont::ProblemWorkspace& ws, cont::ConstVectorRef U, double u1,
                                      cont::MatrixRef GU, cont::VectorRef Gu1) const {
  Workspace& w = cont::workspaceAs<Workspace>(ws);
  const double u2 = U[n_];
  const auto q = U.head(n_);
  try {
    cont::ProblemWorkspace* ws1 = nullptr;
    const EquilibriumProblem& p1 = alongFirst(ws, u2, ws1);
    if (!p1.jacobian(*ws1, q, u1, GU.topLeftCorner(n_, n_), Gu1.head(n_))) return false;
    const EquilibriumProblem& p2 = alongSecond(w, u1);
    if (!p2.jacobian(*w.ws2, q, u2, w.Fq2, w.F2)) return false;
  } catch (const std::invalid_argument&) {
    return false;
  }
  GU.col(n_).head(n_) = w.F2;  // F_u₂: the equilibrium along u₂ has λ = u₂
  // the condition row by central differences in x = (q, u₂, u₁) (file comment)
  w.x << q, u2, u1;
  for (int j = 0; j < n_ + 2; ++j) {
    if (stop_ && stop_->requested()) return false;
    const double unit = j < n_ ? 1.0 : (j == n_ ? scale2_ : scale1_);
    const double h = 1e-6 * std::max(unit, std::abs(w.x[j]));
    double cp = 0.0, cm = 0.0;
    Vector xp = w.x, xm = w.x;
    xp[j] += h;
    xm[j] -= h;
    if (!condition(ws, xp.head(n_), xp[n_ + 1], xp[n_], cp) || !condition(ws, xm.head(n_), xm[n_ + 1], xm[n_], cm))
      return false;
    const double d = (cp - cm) / (xp[j] - xm[j]);
    if (j < n_ + 1)
      GU(n_, j) = d;
    else
      Gu1[n_] = d;
  }
  return true;
}

cont::ProblemScales InputPlaneCurveProblem::scales() const {
  const auto p1 = plane_.along(0, plane_.origin(1));
  const cont::ProblemScales s1 = p1->scales();
  cont::ProblemScales s = cont::ProblemScales::ones(n_ + 1);
  s.unknowns.head(n_) = s1.unknowns.head(n_);
  s.unknowns[n_] = scale2_;
  s.residuals.head(n_) = s1.residuals.head(n_);
  s.residuals[n_] = 1.0;  // c is dimensionless
  s.parameter = scale1_;
  return s;
}

}  // namespace buckle::mechanics
