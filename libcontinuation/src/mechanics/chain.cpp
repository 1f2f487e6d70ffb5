#include "buckle/mechanics/chain.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace buckle::mechanics {

Chain::Chain(const std::vector<SegmentParameters>& segments) {
  if (segments.empty()) throw std::invalid_argument("n (segment count) must be >= 1 (got 0)");
  segments_.reserve(segments.size());
  for (size_t i = 0; i < segments.size(); ++i) {
    try {
      segments_.emplace_back(segments[i]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("segment " + std::to_string(i + 1) + ": " + e.what());
    }
  }
  const int n = size();
  links_.resize(n + 1);
  qMin_.resize(n);
  qMax_.resize(n);
  // Each segment's distal triangle is rigidly joined to the next one's proximal triangle.
  links_[0] = segments[0].b1;
  for (int i = 0; i + 1 < n; ++i) links_[i + 1] = segments[size_t(i)].b2 + segments[size_t(i) + 1].b1;
  links_[n] = segments[size_t(n) - 1].b2;
  for (int i = 0; i < n; ++i) {
    qMin_[i] = segments_[size_t(i)].lowerLimit();
    qMax_[i] = segments_[size_t(i)].upperLimit();
  }
}

Chain Chain::uniform(int n, const SegmentParameters& p) {
  if (n < 1) throw std::invalid_argument("n (segment count) must be >= 1 (got " + std::to_string(n) + ")");
  return Chain(std::vector<SegmentParameters>(size_t(n), p));
}

ChainData::ChainData(const Chain& chain)
    : theta(Vector::Zero(chain.size())), S(Vector::Zero(chain.size())), C(Vector::Zero(chain.size())) {}

namespace {
// Compensated (Neumaier) running sums for the link angles and the tail sums: a long chain's end
// position sums thousands of terms of the chain's length, and their plain rounding (≈ √n·ε·L)
// is the floor of the held coordinates' residuals, which the corrector's tolerance must clear.
struct RunningSum {
  double sum = 0.0, correction = 0.0;
  void add(double x) {
    const double t = sum + x;
    correction += std::abs(sum) >= std::abs(x) ? (sum - t) + x : (x - t) + sum;
    sum = t;
  }
  double value() const { return sum + correction; }
};

// The link directions stand in S[m] = sin θ_m, C[m] = cos θ_m; the tail sums replace them in place,
// from the end, and the pose follows (forwardKinematics' one summation order).
void tailSumsInPlace(const Vector& l, ChainData& data) {
  const Eigen::Index n = data.S.size();
  RunningSum s, c;
  for (Eigen::Index m = n - 1; m >= 0; --m) {
    s.add(l[m + 1] * data.S[m]);
    c.add(l[m + 1] * data.C[m]);
    data.S[m] = s.value();
    data.C[m] = c.value();
  }
  data.pose = Pose(l[0] + c.value(), s.value(), data.theta[n - 1]);
}
constexpr int kReanchor = 16;  // links per exact sincos in the half-angle recurrence
}  // namespace

void forwardKinematics(const Chain& chain, ConstVectorRef q, ChainData& data) {
  const int n = chain.size();
  RunningSum theta;
  for (int m = 0; m < n; ++m) {
    theta.add(q[m]);
    const double t = theta.value();
    data.theta[m] = t;
    data.S[m] = std::sin(t);  // one sincos call at -O2
    data.C[m] = std::cos(t);
  }
  tailSumsInPlace(chain.linkLengths(), data);
}

void forwardKinematics(const Chain& chain, ConstVectorRef q, const double* sinHalf, const double* cosHalf,
                       ChainData& data) {
  const int n = chain.size();
  RunningSum theta;
  double ct = 1.0, st = 0.0;
  for (int m = 0; m < n; ++m) {
    theta.add(q[m]);
    const double t = theta.value();
    data.theta[m] = t;
    if (m % kReanchor == kReanchor - 1) {
      ct = std::cos(t);
      st = std::sin(t);
    } else {
      const double sh = sinHalf[m], ch = cosHalf[m];
      const double cq = (ch - sh) * (ch + sh), sq = 2.0 * sh * ch;
      const double c = ct * cq - st * sq;
      st = st * cq + ct * sq;
      ct = c;
    }
    data.S[m] = st;
    data.C[m] = ct;
  }
  tailSumsInPlace(chain.linkLengths(), data);
}

Pose endPose(const Chain& chain, ConstVectorRef q) {
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  return data.pose;
}

bool endMovesAlong(const Chain& chain, ConstVectorRef q, int c) {
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, chain.size());
  endJacobian(data, J);
  const double unit = c < 2 ? chain.length() : 1.0;
  return J.row(c).norm() > 1e-9 * unit;
}

Eigen::Matrix2Xd jointPositions(const Chain& chain, ConstVectorRef q) {
  const int n = chain.size();
  if (q.size() != n)
    throw std::invalid_argument("joint angles: " + std::to_string(q.size()) + " values for a chain of " +
                                std::to_string(n) + " segments");
  Eigen::Matrix2Xd P(2, n + 2);
  P.col(0).setZero();
  P.col(1) << chain.linkLengths()[0], 0.0;
  double theta = 0.0;
  for (int i = 0; i < n; ++i) {
    theta += q[i];
    P.col(i + 2) = P.col(i + 1) + chain.linkLengths()[i + 1] * Eigen::Vector2d(std::cos(theta), std::sin(theta));
  }
  return P;
}

void endJacobian(const ChainData& data, MatrixRef J) {
  // A plain loop: three strided row assignments cost ≈ 50 instructions per call at n = 3.
  const Eigen::Index n = data.S.size();
  for (Eigen::Index j = 0; j < n; ++j) {
    J(0, j) = -data.S[j];
    J(1, j) = data.C[j];
    J(2, j) = 1.0;
  }
}

void loadHessianGenerator(const ChainData& data, const Wrench& F, VectorRef h) {
  // ∂²x/∂q_i∂q_j = −C_max(i,j), ∂²y/∂q_i∂q_j = −S_max(i,j)  (eq 27)
  h = -F[0] * data.C - F[1] * data.S;
}

void maxIndexProduct(ConstVectorRef h, ConstVectorRef x, VectorRef out) {
  const Eigen::Index n = h.size();
  double prefix = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    prefix += x[i];
    out[i] = h[i] * prefix;
  }
  double suffix = 0.0;
  for (Eigen::Index i = n - 1; i >= 0; --i) {
    out[i] += suffix;
    suffix += h[i] * x[i];
  }
}

void loadMatrix(const ChainData& data, const Wrench& F, MatrixRef Kg) {
  const Eigen::Index n = data.S.size();
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Index m = std::max(i, j);
      Kg(i, j) = -F[0] * data.C[m] - F[1] * data.S[m];
    }
}

double energy(const Chain& chain, ConstVectorRef q) {
  double e = 0.0;
  for (int i = 0; i < chain.size(); ++i) e += chain.segment(i).energy(q[i]);
  return e;
}

void energyGradient(const Chain& chain, ConstVectorRef q, VectorRef g) {
  for (int i = 0; i < chain.size(); ++i) g[i] = chain.segment(i).energyJet(q[i]).d1;
}

void jointTorques(const Chain& chain, ConstVectorRef q, VectorRef M) {
  for (int i = 0; i < chain.size(); ++i) M[i] = chain.segment(i).torque(q[i]);
}

void jointStiffness(const Chain& chain, ConstVectorRef q, VectorRef kq) {
  for (int i = 0; i < chain.size(); ++i) kq[i] = chain.segment(i).energyJet(q[i]).d2;
}

void jointStiffnessDerivative(const Chain& chain, ConstVectorRef q, VectorRef dkq) {
  for (int i = 0; i < chain.size(); ++i) dkq[i] = chain.segment(i).energyJet(q[i]).d3;
}

double totalPotential(const Chain& chain, ConstVectorRef q, const Wrench& F) {
  return energy(chain, q) - F.dot(endPose(chain, q));
}

void totalPotentialGradient(const Chain& chain, ConstVectorRef q, const Wrench& F, VectorRef grad) {
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  energyGradient(chain, q, grad);
  // Jᵀ F with J rows (−S, C, 1)
  grad.array() -= -F[0] * data.S.array() + F[1] * data.C.array() + F[2];
}

void totalPotentialHessian(const Chain& chain, ConstVectorRef q, const Wrench& F, MatrixRef H) {
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  loadMatrix(data, F, H);
  H = -H;
  for (int i = 0; i < chain.size(); ++i) H(i, i) += chain.segment(i).energyJet(q[i]).d2;
}

}  // namespace buckle::mechanics
