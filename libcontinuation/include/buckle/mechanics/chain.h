// An n-segment planar chain: a read-only model (Chain) beside a preallocated workspace
// (ChainData), and the kinematic / energetic algorithms as free functions on Eigen types
// (Pinocchio style). Every function here is O(n). Conventions: conventions.h.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "buckle/mechanics/segment.h"

namespace buckle::mechanics {

using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;
using ConstVectorRef = Eigen::Ref<const Eigen::VectorXd>;
using VectorRef = Eigen::Ref<Eigen::VectorXd>;
using MatrixRef = Eigen::Ref<Eigen::MatrixXd>;
using Pose = Eigen::Vector3d;    ///< (x, y, φ)
using Wrench = Eigen::Vector3d;  ///< (Fx, Fy, Me)

class Chain {
 public:
  /// n = segments.size() >= 1; throws std::invalid_argument naming a bad parameter
  /// ("segment 3: k1 must be > 0 ...").
  explicit Chain(const std::vector<SegmentParameters>& segments);
  /// n identical segments.
  static Chain uniform(int n, const SegmentParameters& p);

  int size() const { return static_cast<int>(segments_.size()); }
  const Segment& segment(int i) const { return segments_[static_cast<size_t>(i)]; }
  /// Link lengths ℓ_0 … ℓ_n: base → joint 1, joint i → joint i+1, joint n → end (eq 5).
  const Vector& linkLengths() const { return links_; }
  /// Lower / upper joint limits (geometric ∩ user), size n.
  const Vector& lowerLimits() const { return qMin_; }
  const Vector& upperLimits() const { return qMax_; }
  /// Total length of the straight chain.
  double length() const { return links_.sum(); }

 private:
  std::vector<Segment> segments_;
  Vector links_, qMin_, qMax_;
};

/// Workspace filled by forwardKinematics(); sized once for a chain.
struct ChainData {
  explicit ChainData(const Chain& chain);
  Vector theta;  ///< absolute link angles θ_m = q_1 + … + q_m
  /// Tail sums S_j = Σ_{m≥j} ℓ_m sin θ_m = −∂x/∂q_j and C_j = Σ_{m≥j} ℓ_m cos θ_m = ∂y/∂q_j.
  Vector S, C;
  Pose pose = Pose::Zero();
};

/// θ, the tail sums and the end pose (eq 5 generalised). O(n).
void forwardKinematics(const Chain& chain, ConstVectorRef q, ChainData& data);
/// The same from the joints' half-angle sines and cosines sinHalf[i] = sin(q_i/2), cosHalf[i] =
/// cos(q_i/2), which the springs need anyway (Segment::energyJet(q, sinHalf, cosHalf)): the link
/// directions (cos θ_m, sin θ_m) follow by rotating the previous one by q_m, cos q = (c − s)(c + s),
/// sin q = 2sc, instead of one sincos per link. Each rotation adds a few ulp; every 16th link takes
/// its direction from sincos(θ_m) itself, so the error stays within 16 rotations' rounding, the size
/// of the rounding of the prefix sum θ_m itself. θ, the tail sums and the pose are summed in the
/// same order as above.
void forwardKinematics(const Chain& chain, ConstVectorRef q, const double* sinHalf, const double* cosHalf,
                       ChainData& data);
Pose endPose(const Chain& chain, ConstVectorRef q);
/// The chain's centre line at q: column 0 the base (0, 0), column i the joint i (i = 1 … n),
/// column n + 1 the end; 2×(n + 2). O(n). For drawing and reporting shapes. Throws
/// std::invalid_argument when q does not have one angle per segment.
Eigen::Matrix2Xd jointPositions(const Chain& chain, ConstVectorRef q);

/// Jacobian of (x, y, φ) with respect to q, 3×n (eq 11): rows (−S_j, C_j, 1).
void endJacobian(const ChainData& data, MatrixRef J);
/// True when the end moves along coordinate c (0 x, 1 y, 2 φ) to first order at q: row c of
/// the end Jacobian is not zero relative to its own unit (the chain's length for x and y, 1 for
/// φ). False, e.g., for x on the straight chain: displacement control of c starts at a singular
/// point there.
bool endMovesAlong(const Chain& chain, ConstVectorRef q, int c);

/// h_m = −Fx·C_m − Fy·S_m: K_g(i, j) = h_max(i,j) (eq 27). The torque Me does not enter.
void loadHessianGenerator(const ChainData& data, const Wrench& F, VectorRef h);
/// out = K x for the matrix K(i, j) = h_max(i,j) (the K_g structure, eq 27) in O(n):
/// out_i = h_i Σ_{j≤i} x_j + Σ_{j>i} h_j x_j (out may not alias x).
void maxIndexProduct(ConstVectorRef h, ConstVectorRef x, VectorRef out);
/// Dense K_g(F) = Fx ∂²x/∂q² + Fy ∂²y/∂q² (eq 26–27).
void loadMatrix(const ChainData& data, const Wrench& F, MatrixRef Kg);

/// Elastic energy E(q) (eq 7).
double energy(const Chain& chain, ConstVectorRef q);
/// ∂E/∂q = −M (size n).
void energyGradient(const Chain& chain, ConstVectorRef q, VectorRef g);
/// Joint torques M = −∂E/∂q (eq 10/19).
void jointTorques(const Chain& chain, ConstVectorRef q, VectorRef M);
/// Diagonal of K_q = ∂²E/∂q² (size n).
void jointStiffness(const Chain& chain, ConstVectorRef q, VectorRef kq);
/// Diagonal of ∂³E/∂q³ (size n), for exact second derivatives of the equilibrium equations.
void jointStiffnessDerivative(const Chain& chain, ConstVectorRef q, VectorRef dkq);

/// Π = E − F·p.
double totalPotential(const Chain& chain, ConstVectorRef q, const Wrench& F);
/// ∂Π/∂q = ∂E/∂q − Jᵀ F.
void totalPotentialGradient(const Chain& chain, ConstVectorRef q, const Wrench& F, VectorRef grad);
/// Dense Hessian of Π: K_q − K_g(F).
void totalPotentialHessian(const Chain& chain, ConstVectorRef q, const Wrench& F, MatrixRef H);

}  // namespace buckle::mechanics
