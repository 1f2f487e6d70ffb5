// The two-parameter problem of critical_curves.h: the chain's equilibrium with a segment or end
// parameter μ as the second parameter (SecondParameter, ChainParameterProblem: F_μ and
// (∂F_u/∂μ)·v exactly, the structured solver kept in step with μ). The critical curves traced
// on it are in critical_curves.cpp.
#include "buckle/mechanics/critical_curves.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "buckle/mechanics/chain_structure.h"

namespace buckle::mechanics {

namespace cont = buckle::continuation;
using Kind = SecondParameter::Kind;

namespace {
const char* kindName(Kind kind, int component) {
  switch (kind) {
    case Kind::A: return "a";
    case Kind::B: return "b";
    case Kind::K: return "k";
    case Kind::L0: return "L0";
    case Kind::PreloadDifference: return "dL0";
    case Kind::End: return component == 0 ? "x" : component == 1 ? "y" : "phi";
  }
  return "?";
}

// dp/dμ of one affected segment.
SegmentParameterDirection segmentDirection(Kind kind) {
  SegmentParameterDirection d;
  switch (kind) {
    case Kind::A: d.a1 = d.a2 = 1.0; break;
    case Kind::B: d.b1 = d.b2 = 1.0; break;
    case Kind::K: d.k1 = d.k2 = 1.0; break;
    case Kind::L0: d.L1_0 = d.L2_0 = 1.0; break;
    case Kind::PreloadDifference: d.L1_0 = 0.5; d.L2_0 = -0.5; break;
    case Kind::End: break;
  }
  return d;
}

// The chain's structured solver, recreated for the current chain after μ has changed (setting μ
// rebuilds the EquilibriumProblem the chain solver is bound to).
class ChainParameterSolver final : public cont::BorderedSolver {
 public:
  ChainParameterSolver(const ChainParameterProblem& problem, cont::ProblemWorkspace& ws) : problem_(problem), ws_(ws) {}

  cont::Factorization factor(cont::ConstVectorRef u, double lambda, cont::ConstVectorRef c) override {
    return sync() ? inner_->factor(u, lambda, c) : cont::Factorization::Refused;
  }
  bool solve(cont::ConstVectorRef b, cont::VectorRef x) override { return inner_ && inner_->solve(b, x); }
  int determinantSign() const override { return inner_ ? inner_->determinantSign() : 0; }
  double logAbsDeterminant() const override {
    return inner_ ? inner_->logAbsDeterminant() : -std::numeric_limits<double>::infinity();
  }
  int maxGeneralBorder() const override { return ChainStructure::kMaxBorder - problem_.equilibrium().heldCount(); }
  cont::Factorization factorGeneral(cont::ConstVectorRef u, double lambda, cont::ConstMatrixRef B,
                                    cont::ConstMatrixRef C, cont::ConstMatrixRef D, bool transposed) override {
    return sync() ? inner_->factorGeneral(u, lambda, B, C, D, transposed) : cont::Factorization::Refused;
  }

 private:
  bool sync() {
    if (!inner_ || generation_ != problem_.generation()) {
      inner_ = problem_.equilibrium().makeStructuredSolver(problem_.equilibriumWorkspace(ws_));
      generation_ = problem_.generation();
    }
    return inner_ != nullptr;
  }

  const ChainParameterProblem& problem_;
  cont::ProblemWorkspace& ws_;
  std::unique_ptr<cont::BorderedSolver> inner_;
  long generation_ = -1;
};
}  // namespace

std::string SecondParameter::name() const {
  std::string s = kindName(kind, component);
  if (kind != Kind::End && segment >= 0) s += "[" + std::to_string(segment + 1) + "]";
  return s;
}

SecondParameter SecondParameter::parse(const std::string& kind, int segment) {
  SecondParameter p;
  p.segment = segment;
  if (kind == "a") p.kind = Kind::A;
  else if (kind == "b") p.kind = Kind::B;
  else if (kind == "k") p.kind = Kind::K;
  else if (kind == "L0") p.kind = Kind::L0;
  else if (kind == "dL0") p.kind = Kind::PreloadDifference;
  else if (kind == "x" || kind == "y" || kind == "phi") {
    p.kind = Kind::End;
    p.component = kind == "x" ? 0 : kind == "y" ? 1 : 2;
    if (segment >= 0) throw std::invalid_argument("second parameter \"" + kind + "\" is an end coordinate: no segment");
  } else {
    throw std::invalid_argument("second parameter \"" + kind +
                                "\" is not one of a, b, k, L0, dL0 (segment parameters), x, y, phi (end values)");
  }
  return p;
}

ChainParameterProblem::ChainParameterProblem(std::vector<SegmentParameters> segments, const EndCondition& end,
                                             const Eigen::Vector3d& direction, const SecondParameter& parameter,
                                             EquilibriumOptions options)
    : segments_(std::move(segments)), end_(end), direction_(direction), parameter_(parameter), options_(options) {
  const int n = int(segments_.size());
  if (n < 1) throw std::invalid_argument("second parameter: the chain has no segments");
  if (parameter_.segment < -1 || parameter_.segment >= n)
    throw std::invalid_argument("second parameter: segment " + std::to_string(parameter_.segment + 1) +
                                " outside 1.." + std::to_string(n));
  if (parameter_.component < 0 || parameter_.component > 2)
    throw std::invalid_argument("second parameter: end component must be 0 (x), 1 (y) or 2 (phi)");
  const SegmentParameters& s = segments_[size_t(std::max(parameter_.segment, 0))];
  switch (parameter_.kind) {
    case Kind::A: mu_ = s.a1; break;
    case Kind::B: mu_ = s.b1; break;
    case Kind::K: mu_ = s.k1; break;
    case Kind::L0: mu_ = 0.5 * (s.L1_0 + s.L2_0); break;
    case Kind::PreloadDifference: mu_ = s.L1_0 - s.L2_0; break;
    case Kind::End: mu_ = end_.value[parameter_.component]; break;
  }
  std::vector<SegmentParameters> segs;
  EndCondition e;
  applied(mu_, segs, e);
  segments_ = segs;
  end_ = e;
  equilibrium_ = std::make_unique<EquilibriumProblem>(Chain(segments_), end_, direction_, options_);
  data_ = std::make_unique<ChainData>(equilibrium_->chain());
  dl_.resize(n + 1);
  dS_.resize(n);
  dC_.resize(n);
  dE1_.resize(n);
  dE2_.resize(n);
  dh_.resize(n);
}

bool ChainParameterProblem::applied(double mu, std::vector<SegmentParameters>& out, EndCondition& end) const {
  if (!std::isfinite(mu)) return false;
  out = segments_;
  end = end_;
  if (parameter_.kind == Kind::End) {
    end.value[parameter_.component] = mu;
    return true;
  }
  for (int i = 0; i < int(out.size()); ++i) {
    if (!affects(i)) continue;
    SegmentParameters& p = out[size_t(i)];
    switch (parameter_.kind) {
      case Kind::A: p.a1 = p.a2 = mu; break;
      case Kind::B: p.b1 = p.b2 = mu; break;
      case Kind::K: p.k1 = p.k2 = mu; break;
      case Kind::L0: {
        const double d = p.L1_0 - p.L2_0;
        p.L1_0 = mu + 0.5 * d;
        p.L2_0 = mu - 0.5 * d;
        break;
      }
      case Kind::PreloadDifference: {
        const double m = 0.5 * (p.L1_0 + p.L2_0);
        p.L1_0 = m + 0.5 * mu;
        p.L2_0 = m - 0.5 * mu;
        break;
      }
      case Kind::End: break;
    }
  }
  return true;
}

bool ChainParameterProblem::setSecondParameter(double mu) {
  if (mu == mu_) return true;
  std::vector<SegmentParameters> segs;
  EndCondition end;
  if (!applied(mu, segs, end)) return false;
  try {
    auto eq = std::make_unique<EquilibriumProblem>(Chain(segs), end, direction_, options_);
    equilibrium_ = std::move(eq);
  } catch (const std::invalid_argument&) {
    return false;  // a parameter outside a segment's domain (e.g. a < 0, empty joint range)
  }
  data_ = std::make_unique<ChainData>(equilibrium_->chain());
  mu_ = mu;
  ++generation_;
  return true;
}

std::unique_ptr<cont::BorderedSolver> ChainParameterProblem::makeStructuredSolver(cont::ProblemWorkspace& ws) const {
  return std::make_unique<ChainParameterSolver>(*this, ws);
}

cont::ProblemWorkspace& ChainParameterProblem::equilibriumWorkspace(cont::ProblemWorkspace& ws) const {
  Workspace& w = cont::workspaceAs<Workspace>(ws);
  if (!w.equilibrium || w.generation != generation_) {
    w.equilibrium = equilibrium_->createWorkspace();
    w.generation = generation_;
  }
  return *w.equilibrium;
}

bool ChainParameterProblem::parameterJacobianApply(cont::ProblemWorkspace&, cont::ConstVectorRef u, double lambda,
                                                   cont::ConstVectorRef v, cont::VectorRef FuLambdaV) const {
  const Chain& chain = equilibrium_->chain();
  const int n = chain.size();
  const int N = equilibrium_->dimension();
  if (u.size() != N || v.size() != N || !u.allFinite() || !std::isfinite(lambda)) return false;
  forwardKinematics(chain, u.head(n), *data_);
  // F_u = [[K_q − [h_max(i,j)], −J_hᵀ], [−J_h, 0]], h = −Fx C − Fy S (eq 27): only the dead
  // loads depend on λ (∂W/∂λ = direction on the loaded coordinates; the reactions are unknowns).
  const Eigen::Vector3d& dir = equilibrium_->direction();
  double dFx = 0.0, dFy = 0.0;
  for (int c : equilibrium_->endCondition().loadedIndices()) {
    if (c == 0) dFx = dir[0];
    if (c == 1) dFy = dir[1];
  }
  dh_ = -dFx * data_->C - dFy * data_->S;
  maxIndexProduct(dh_, v.head(n), FuLambdaV.head(n));
  FuLambdaV.head(n) = -FuLambdaV.head(n);
  FuLambdaV.tail(N - n).setZero();
  return true;
}

double ChainParameterProblem::secondParameterScale() const {
  const double length = equilibrium_->lengthUnit(), stiffness = equilibrium_->stiffnessUnit();
  switch (parameter_.kind) {
    case Kind::K: return stiffness;
    case Kind::End: {
      const int c = parameter_.component;
      if (end_.control[size_t(c)] == Control::Held) return c == 2 ? 1.0 : length;
      return c == 2 ? stiffness * length * length : stiffness * length;
    }
    default: return length;
  }
}

bool ChainParameterProblem::secondParameterDerivatives(cont::ProblemWorkspace&, cont::ConstVectorRef u, double lambda,
                                                       cont::ConstVectorRef v, cont::VectorRef Fmu,
                                                       cont::VectorRef FuMuV) const {
  const Chain& chain = equilibrium_->chain();
  const int n = chain.size();
  const int N = equilibrium_->dimension();
  if (u.size() != N || v.size() != N) return false;
  const auto q = u.head(n);
  for (int i = 0; i < N; ++i)
    if (!std::isfinite(u[i])) return false;
  forwardKinematics(chain, q, *data_);
  const ChainData& d = *data_;
  const Wrench W = equilibrium_->wrench(u, lambda);
  const std::vector<int> held = end_.heldIndices();
  const int m = int(held.size());

  // ∂/∂μ of the end value (End kind) and of the segments' energies
  Wrench dValue = Wrench::Zero();
  Wrench dW = Wrench::Zero();  // ∂/∂μ of the loads (the multipliers are unknowns, not μ-dependent)
  if (parameter_.kind == Kind::End) {
    dValue[parameter_.component] = 1.0;
    if (end_.control[size_t(parameter_.component)] == Control::Load) dW[parameter_.component] = 1.0;
  }
  const SegmentParameterDirection dir = segmentDirection(parameter_.kind);
  for (int i = 0; i < n; ++i) {
    if (parameter_.kind == Kind::End || !affects(i)) {
      dE1_[i] = dE2_[i] = 0.0;
      continue;
    }
    const Jet3 e = chain.segment(i).energyJetParameterDerivative(q[i], dir);
    dE1_[i] = e.d1;
    dE2_[i] = e.d2;
  }
  // link lengths ℓ0 = b1(1), ℓi = b2(i) + b1(i+1), ℓn = b2(n) (chain.h) and their tail sums
  dl_.setZero();
  if (parameter_.kind == Kind::B)
    for (int i = 0; i < n; ++i)
      if (affects(i)) {
        dl_[i] += 1.0;      // b1 of segment i sits in link i
        dl_[i + 1] += 1.0;  // b2 in link i + 1
      }
  double s = 0.0, c = 0.0;
  for (int j = n - 1; j >= 0; --j) {
    s += dl_[j + 1] * std::sin(d.theta[j]);
    c += dl_[j + 1] * std::cos(d.theta[j]);
    dS_[j] = s;
    dC_[j] = c;
  }
  const Pose dPose(dl_[0] + dC_[0], dS_[0], 0.0);

  // F = ∂E/∂q − JᵀW (J rows −S, C, 1) and value − pose on the held rows
  for (int i = 0; i < n; ++i)
    Fmu[i] = dE1_[i] - (-dS_[i] * W[0] + dC_[i] * W[1]) - (-d.S[i] * dW[0] + d.C[i] * dW[1] + dW[2]);
  for (int k = 0; k < m; ++k) Fmu[n + k] = dValue[held[size_t(k)]] - dPose[held[size_t(k)]];

  // F_u = [[diag K_q − [h_max(i,j)], −J_hᵀ], [−J_h, 0]] with h = −Fx C − Fy S (eq 27)
  dh_ = -dW[0] * d.C - W[0] * dC_ - dW[1] * d.S - W[1] * dS_;
  const auto vq = v.head(n);
  maxIndexProduct(dh_, vq, FuMuV.head(n));
  for (int i = 0; i < n; ++i) FuMuV[i] = dE2_[i] * vq[i] - FuMuV[i];
  for (int k = 0; k < m; ++k) {
    const int h = held[size_t(k)];
    double row = 0.0;
    for (int i = 0; i < n; ++i) {
      const double dJ = h == 0 ? -dS_[i] : h == 1 ? dC_[i] : 0.0;
      FuMuV[i] -= dJ * v[n + k];
      row += dJ * vq[i];
    }
    FuMuV[n + k] = -row;
  }
  return true;
}

}  // namespace buckle::mechanics
