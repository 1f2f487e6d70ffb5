#include "buckle/mechanics/imperfection_sensitivity.h"

#include <cmath>

namespace buckle::mechanics {

namespace cont = buckle::continuation;

ImperfectionSensitivity imperfectionSensitivity(const EquilibriumProblem& problem, const cont::SpecialPoint& bp,
                                                const KoiterCoefficients& k, int c) {
  ImperfectionSensitivity s;
  s.coordinate = c;
  if (c < 0 || c > 2) {
    s.error = "imperfection sensitivity: the end coordinate must be 0 (x), 1 (y) or 2 (phi), got " + std::to_string(c);
    return s;
  }
  const EndCondition& end = problem.endCondition();
  const bool held = end.control[size_t(c)] == Control::Held;
  static const char* const loads[] = {"Fx", "Fy", "Me"};
  static const char* const coordinates[] = {"x", "y", "phi"};
  s.name = held ? coordinates[c] : loads[c];
  if (!k.valid) {
    s.error = "imperfection sensitivity: no Koiter coefficients (" + k.error + ")";
    return s;
  }
  // F_ε: the residual is linear in the prescribed values, so F_ε is F_λ of the same chain whose
  // path moves coordinate c alone (exact)
  EquilibriumProblem moved(problem.chain(), end, Eigen::Vector3d::Unit(c));
  const int N = moved.dimension();
  cont::Matrix Fu(N, N);
  cont::Vector Fe(N);
  if (!moved.jacobian(bp.u, bp.lambda, Fu, Fe)) {
    s.error = "imperfection sensitivity: the chain refused the branch point";
    return s;
  }
  s.valid = true;
  s.coupling = k.psi.dot(Fe);
  if (!(std::abs(s.coupling) > 1e-10 * k.psi.norm() * Fe.norm())) {
    s.coupling = 0.0;  // no first-order coupling: the knockdown is of higher order
    return s;
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
  return s;
}

double knockdown(const ImperfectionSensitivity& s, double epsilon) {
  if (!s.valid || s.exponent == 0.0) return 0.0;
  if (s.sign != 0 && epsilon * s.sign <= 0.0) return 0.0;
  return s.prefactor * std::pow(std::abs(epsilon), s.exponent);
}

}  // namespace buckle::mechanics
