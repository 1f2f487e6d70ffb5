#include "buckle/mechanics/energy_landscape.h"

#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "buckle/mechanics/shape_name.h"
#include "buckle/mechanics/validation.h"

namespace buckle::mechanics {

namespace {

double wrapAngle(double a) {
  a = std::remainder(a, 2.0 * M_PI);  // [−π, π]
  if (a <= -M_PI) a += 2.0 * M_PI;
  return a;
}

// Everything needed along the branch at a point q (3 joints).
struct BranchDerivatives {
  bool tangentValid = false;
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double dE = std::numeric_limits<double>::quiet_NaN();
  double d2E = std::numeric_limits<double>::quiet_NaN();
  double Me = std::numeric_limits<double>::quiet_NaN();
  double V = 0.0;  ///< the body loads' potential (eq B1)
  Eigen::Vector3d grad = Eigen::Vector3d::Zero();  ///< ∇(E + V)
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
};

BranchDerivatives branchDerivatives(const Chain& chain, const Eigen::Vector3d& q, BodyLoadTerms* body) {
  BranchDerivatives d;
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, 3);
  endJacobian(data, J);
  d.J = J;
  Vector g(3), kq(3), tau = Vector::Zero(3), gamma = Vector::Zero(3);
  energyGradient(chain, q, g);
  jointStiffness(chain, q, kq);
  if (body && body->active()) {
    body->update(data);
    body->torques(0.0, tau);
    body->generator(0.0, gamma);
    d.V = body->potential(data, 0.0);
    g -= tau;  // ∇V = −τ (eq B2)
  }
  d.grad = g;
  // Tangent of the IK curve: J_p t = 0 with t1 = 1.
  Eigen::Matrix2d A;
  A << J(0, 1), J(0, 2), J(1, 1), J(1, 2);
  const double scale = A.cwiseAbs().maxCoeff();
  if (std::abs(A.determinant()) > 1e-12 * scale * scale) {
    const Eigen::Vector2d t23 = A.lu().solve(Eigen::Vector2d(-J(0, 0), -J(1, 0)));
    d.t = Eigen::Vector3d(1.0, t23[0], t23[1]);
    d.tangentValid = true;
    d.dE = g.dot(d.t);
    // Curvature of the curve: J_p q'' = −(tᵀ ∇²x t, tᵀ ∇²y t), q1'' = 0, with
    // ∂²x/∂q_i∂q_j = −C_max(i,j), ∂²y/∂q_i∂q_j = −S_max(i,j).
    double txx = 0.0, tyy = 0.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int m = std::max(i, j);
        txx += -data.C[m] * d.t[i] * d.t[j];
        tyy += -data.S[m] * d.t[i] * d.t[j];
      }
    const Eigen::Vector2d s23 = A.lu().solve(Eigen::Vector2d(-txx, -tyy));
    double quad = 0.0;
    for (int i = 0; i < 3; ++i) {
      quad += kq[i] * d.t[i] * d.t[i];
      for (int j = 0; j < 3; ++j) quad += gamma[std::max(i, j)] * d.t[i] * d.t[j];  // ∇²V (eq B3)
    }
    d.d2E = quad + g[1] * s23[0] + g[2] * s23[1];
  }
  // Me from ∇E = Jᵀ F (eq 12), where the 3×3 J is regular (sin q2 ≠ 0, docs/mechanics.md erratum 7).
  const Eigen::Matrix3d J3 = J;
  const Eigen::PartialPivLU<Eigen::Matrix3d> lu(J3.transpose());
  if (lu.rcond() > 1e-13) d.Me = lu.solve(d.grad)[2];
  return d;
}

}  // namespace

bool landscapeInverseKinematics(const Chain& chain, double x, double y, double q1, int branch, Eigen::Vector3d& q) {
  if (chain.size() != 3) throw std::invalid_argument("energy landscape: the chain must have 3 segments (n = 3)");
  const Vector& l = chain.linkLengths();
  const double dx = x - l[0] - l[1] * std::cos(q1), dy = y - l[1] * std::sin(q1);
  double C3 = (dx * dx + dy * dy - l[2] * l[2] - l[3] * l[3]) / (2.0 * l[2] * l[3]);
  if (!std::isfinite(C3) || std::abs(C3) > 1.0 + 1e-12) return false;
  C3 = std::max(-1.0, std::min(1.0, C3));
  const double S3 = (branch >= 0 ? 1.0 : -1.0) * std::sqrt(std::max(0.0, 1.0 - C3 * C3));
  const double q3 = std::atan2(S3, C3);
  const double q2 = wrapAngle(std::atan2(dy, dx) - std::atan2(l[3] * S3, l[2] + l[3] * C3) - q1);
  q = Eigen::Vector3d(q1, q2, q3);
  return true;
}

LandscapeSample landscapeSample(const Chain& chain, double x, double y, double q1, int branch, BodyLoadTerms* body) {
  LandscapeSample s;
  s.q1 = q1;
  Eigen::Vector3d q;
  if (!landscapeInverseKinematics(chain, x, y, q1, branch, q)) return s;
  s.q = q;
  s.energy = energy(chain, q);
  s.status = LandscapeStatus::Feasible;
  for (int i = 0; i < 3; ++i)
    if (q[i] < chain.lowerLimits()[i] || q[i] > chain.upperLimits()[i]) {
      s.status = LandscapeStatus::JointLimit;
      s.violatedJoint = i + 1;
      break;
    }
  const BranchDerivatives d = branchDerivatives(chain, q, body);
  s.energy += d.V;
  s.dEdq1 = d.dE;
  s.d2Edq1 = d.d2E;
  s.endTorque = d.Me;
  return s;
}

namespace {

LandscapeEquilibrium makeEquilibrium(const Chain& chain, const LandscapeSample& s, int branch, BodyLoadTerms* body) {
  LandscapeEquilibrium e;
  e.branch = branch;
  e.q1 = s.q1;
  e.q = s.q;
  e.energy = s.energy;
  e.d2Edq1 = s.d2Edq1;
  e.stable = s.d2Edq1 > 0.0;
  const BranchDerivatives d = branchDerivatives(chain, s.q, body);
  // ∇E = J_pᵀ F_p with Me = 0 (least squares; exact at an equilibrium).
  const Eigen::Matrix<double, 3, 2> Jpt = d.J.topRows(2).transpose();
  const Eigen::Vector2d Fp = Jpt.colPivHouseholderQr().solve(d.grad);
  e.F = Wrench(Fp[0], Fp[1], 0.0);
  e.residual = (d.grad - Jpt * Fp).lpNorm<Eigen::Infinity>();
  e.shape = shapeName(s.q);
  return e;
}

void locateEquilibria(const Chain& chain, double x, double y, const std::vector<LandscapeSample>& samples, int branch,
                      BodyLoadTerms* body, std::vector<LandscapeEquilibrium>& out) {
  auto usable = [](const LandscapeSample& s) {
    return s.status == LandscapeStatus::Feasible && std::isfinite(s.dEdq1);
  };
  for (size_t i = 0; i + 1 < samples.size(); ++i) {
    const LandscapeSample &a = samples[i], &b = samples[i + 1];
    if (!usable(a) || !usable(b)) continue;
    if (std::abs(wrapAngle(b.q[1] - a.q[1])) > 0.5 || std::abs(b.q[2] - a.q[2]) > 0.5) continue;  // not one piece
    if (a.dEdq1 == 0.0) {
      out.push_back(makeEquilibrium(chain, a, branch, body));
      continue;
    }
    if (b.dEdq1 == 0.0 || (a.dEdq1 < 0) == (b.dEdq1 < 0)) continue;
    // Safeguarded Newton (derivative d²E/dq1²) inside the bracket.
    double lo = a.q1, hi = b.q1, glo = a.dEdq1;
    LandscapeSample cur = landscapeSample(chain, x, y, 0.5 * (lo + hi), branch, body);
    bool ok = usable(cur);
    for (int it = 0; ok && it < 200; ++it) {
      const double g = cur.dEdq1;
      if (g == 0.0) break;
      if ((g < 0) == (glo < 0)) {
        lo = cur.q1;
        glo = g;
      } else {
        hi = cur.q1;
      }
      double next = (std::isfinite(cur.d2Edq1) && cur.d2Edq1 != 0.0) ? cur.q1 - g / cur.d2Edq1 : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      const double step = std::abs(next - cur.q1);
      cur = landscapeSample(chain, x, y, next, branch, body);
      ok = usable(cur);
      if (step <= 1e-15 * std::max(1.0, std::abs(next)) || hi - lo <= 1e-15) break;
    }
    if (ok) out.push_back(makeEquilibrium(chain, cur, branch, body));
  }
}

}  // namespace

std::string LandscapeOptions::validate(const std::string& prefix) const {
  namespace cont = continuation;
  auto bound = [](double q) { return std::isnan(q) || std::isfinite(q); };
  return cont::firstProblem(
      {cont::require(samples >= 2, prefix, "samples", "must be at least 2"),
       cont::require(bound(q1Min) && bound(q1Max), prefix, "q1Min", "and q1Max must be finite (NaN: the joint's limit)"),
       cont::require(std::isnan(q1Min) || std::isnan(q1Max) || q1Min < q1Max, prefix, "q1Min",
                     "must be smaller than q1Max")});
}

EnergyLandscape energyLandscape(const Chain& chain, double x, double y, const LandscapeOptions& options) {
  if (chain.size() != 3) throw std::invalid_argument("energy landscape: the chain must have 3 segments (n = 3)");
  requireFinite("x", x);
  requireFinite("y", y);
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("LandscapeOptions: " + why);
  EnergyLandscape L;
  L.x = x;
  L.y = y;
  const double lo = std::isnan(options.q1Min) ? chain.lowerLimits()[0] : options.q1Min;
  const double hi = std::isnan(options.q1Max) ? chain.upperLimits()[0] : options.q1Max;
  requireFinite("q1Min", lo);
  requireFinite("q1Max", hi);
  if (!(lo < hi)) throw std::invalid_argument("q1Min must be < q1Max");
  BodyLoadTerms terms(chain, options.body.atParameter(0.0));  // throws as BodyLoads::check
  BodyLoadTerms* body = terms.active() ? &terms : nullptr;
  for (int i = 0; i < options.samples; ++i) {
    const double q1 = lo + (hi - lo) * i / (options.samples - 1);
    L.positive.push_back(landscapeSample(chain, x, y, q1, +1, body));
    L.negative.push_back(landscapeSample(chain, x, y, q1, -1, body));
  }
  locateEquilibria(chain, x, y, L.positive, +1, body, L.equilibria);
  locateEquilibria(chain, x, y, L.negative, -1, body, L.equilibria);
  std::sort(L.equilibria.begin(), L.equilibria.end(),
            [](const LandscapeEquilibrium& a, const LandscapeEquilibrium& b) { return a.q1 < b.q1; });
  return L;
}

}  // namespace buckle::mechanics
