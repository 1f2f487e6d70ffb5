#include "buckle/mechanics/imperfection_sensitivity.h"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace buckle::mechanics {

namespace cont = buckle::continuation;

namespace {
/// The law from the coupling e = ψᵀF_ε (file comment of the header) into s (valid k).
void fromCoupling(const KoiterCoefficients& k, const Eigen::VectorXd& Fe, ImperfectionSensitivity& s) {
  s.valid = true;
  s.coupling = k.psi.dot(Fe);
  if (!(std::abs(s.coupling) > 1e-10 * k.psi.norm() * Fe.norm())) {
    s.coupling = 0.0;  // no first-order coupling: the knockdown is of higher order
    return;
  }
  const double ratio = s.coupling / k.transversality;  // e/τ
  if (k.kind == KoiterKind::Asymmetric) {
    s.exponent = 0.5;
    s.prefactor = 2.0 * std::sqrt(std::abs(k.a * ratio));
    s.sign = k.a * ratio < 0.0 ? 1 : -1;  // aK > 0 with K = −εe/τ
  } else if (k.kind == KoiterKind::Subcritical) {
    s.exponent = 2.0 / 3.0;
    s.prefactor = 3.0 * std::cbrt(std::abs(k.b)) * std::pow(std::abs(0.5 * ratio), 2.0 / 3.0);
  }
}

/// The preload asymmetry's direction in a segment's parameters: dL1_0 = ½, dL2_0 = −½ per unit ε.
SegmentParameterDirection preloadDifference() {
  SegmentParameterDirection d;
  d.L1_0 = 0.5;
  d.L2_0 = -0.5;
  return d;
}
}  // namespace

ImperfectionSensitivity imperfectionSensitivity(const EquilibriumProblem& problem, const cont::SpecialPoint& bp,
                                                const KoiterCoefficients& k, int c) {
  ImperfectionSensitivity s;
  s.coordinate = c;
  if (c < 0 || c > 2) {
    s.message = "imperfection sensitivity: the end coordinate must be 0 (x), 1 (y) or 2 (phi), got " + std::to_string(c);
    return s;
  }
  const EndCondition& end = problem.endCondition();
  const bool held = end.control[size_t(c)] == Control::Held;
  static const char* const loads[] = {"Fx", "Fy", "Me"};
  static const char* const coordinates[] = {"x", "y", "phi"};
  s.name = held ? coordinates[c] : loads[c];
  if (!k.valid) {
    s.message = "imperfection sensitivity: no Koiter coefficients (" + k.message + ")";
    return s;
  }
  // F_ε: the residual is linear in the prescribed values, so F_ε is F_λ of the same chain whose
  // path moves coordinate c alone (exact, O(n) through the product F_x e_λ)
  EquilibriumProblem moved(problem.chain(), end, Eigen::Vector3d::Unit(c));
  const int N = moved.dimension();
  cont::Vector lambdaDirection = cont::Vector::Zero(N + 1), Fe(N);
  lambdaDirection[N] = 1.0;
  if (!cont::BoundProblem(moved).jacobianApply(bp.u, bp.lambda, lambdaDirection, Fe)) {
    s.message = "imperfection sensitivity: the chain refused the branch point";
    return s;
  }
  fromCoupling(k, Fe, s);
  return s;
}

ImperfectionSensitivity preloadImperfectionSensitivity(const EquilibriumProblem& problem,
                                                       const cont::SpecialPoint& bp, const KoiterCoefficients& k,
                                                       int segment) {
  ImperfectionSensitivity s;
  s.segment = segment;
  s.name = "dL0";
  const Chain& chain = problem.chain();
  const int n = chain.size();
  if (segment < -1 || segment >= n) {
    s.message = "imperfection sensitivity: the segment must be -1 (all) or 0 ... " + std::to_string(n - 1) + ", got " +
              std::to_string(segment);
    return s;
  }
  if (!k.valid) {
    s.message = "imperfection sensitivity: no Koiter coefficients (" + k.message + ")";
    return s;
  }
  // F_ε = ∂(∂E/∂q)/∂ε on the affected joints (the load terms do not depend on the free lengths)
  cont::Vector Fe = cont::Vector::Zero(problem.dimension());
  const SegmentParameterDirection d = preloadDifference();
  for (int i = (segment < 0 ? 0 : segment); i < (segment < 0 ? n : segment + 1); ++i)
    Fe[i] = chain.segment(i).energyJetParameterDerivative(bp.u[i], d).d1;
  if (!Fe.allFinite()) {
    s.message = "imperfection sensitivity: the chain refused the branch point";
    return s;
  }
  fromCoupling(k, Fe, s);
  return s;
}

int mostSensitivePreloadSegment(const EquilibriumProblem& problem, const cont::SpecialPoint& bp,
                                const KoiterCoefficients& k) {
  if (!k.valid) return -1;
  const SegmentParameterDirection d = preloadDifference();
  int best = -1;
  double largest = -1.0;
  for (int i = 0; i < problem.segments(); ++i) {
    const double e = std::abs(k.psi[i] * problem.chain().segment(i).energyJetParameterDerivative(bp.u[i], d).d1);
    if (e > largest) {
      largest = e;
      best = i;
    }
  }
  return best;
}

Chain preloadAsymmetric(const Chain& chain, int segment, double epsilon) {
  const int n = chain.size();
  if (segment < -1 || segment >= n)
    throw std::invalid_argument("preload asymmetry: the segment must be -1 (all) or 0 ... " + std::to_string(n - 1) +
                                ", got " + std::to_string(segment));
  const SegmentParameterDirection d = preloadDifference();
  std::vector<SegmentParameters> segments;
  for (int i = 0; i < n; ++i) {
    SegmentParameters p = chain.segment(i).parameters();
    if (segment < 0 || segment == i) {
      p.L1_0 += epsilon * d.L1_0;
      p.L2_0 += epsilon * d.L2_0;
    }
    segments.push_back(p);
  }
  return Chain(segments);  // validates the free lengths
}

double knockdown(const ImperfectionSensitivity& s, double epsilon) {
  if (!s.valid || s.exponent == 0.0) return 0.0;
  if (s.sign != 0 && epsilon * s.sign <= 0.0) return 0.0;
  return s.prefactor * std::pow(std::abs(epsilon), s.exponent);
}

}  // namespace buckle::mechanics
