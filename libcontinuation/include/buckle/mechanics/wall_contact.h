// Contact of the chain's moving vertices with the base wall x = 0 as a unilateral constraint
// (docs/mechanics.md, "Contact with the base wall"). Conventions: conventions.h.
//
// The moving bodies are the segments' triangles except segment 1's proximal one (clamped). Their
// vertices, named per segment i (0-based):
//   corner 0        the joint i (the apex shared by the segment's two triangles; i ≥ 1),
//   corners 1, 2    the proximal triangle's base corners at +a_1, −a_1 across the link (i ≥ 1),
//   corners 3, 4    the distal triangle's base corners at +a_2, −a_2.
// A vertex v on the link of absolute angle θ_L is moved by the joints 0 … last(v) (last = i − 1
// for corners 0–2, i for corners 3–4); a rotation about joint j (at P_j) moves it by
// dv = R90 (v − P_j) dq_j, so
//   ∂x_v/∂q_j = −(y_v − y_Pj),        ∂²x_v/∂q_j∂q_k = −(x_v − x_P,max(j,k))     (j, k ≤ last)
// and zero for a joint beyond last. The second derivative depends on max(j, k) only: the same
// generator form as K_g (eq 27), so a contact keeps the O(n) chain structure.
//
// A vertex held on the wall is the constraint x_v(q) = 0 with its force μ (friction-free, along +x
// on the chain) an unknown. With the sign of the held end coordinates (equilibrium_problem.h):
//   q rows:     ∂E/∂q − Jᵀ F − Σ_v μ_v ∇x_v = 0
//   wall rows:  −x_v(q) = 0
// and the Hessian of the total potential gains −Σ μ_v ∂²x_v, i.e. the generator h of
// K_q − K_g = κ δ − h_max (chain_structure.h) gains −μ_v (x_v − x_Pm) for m ≤ last(v). The contact
// holds while μ_v ≥ 0 (the wall pushes); it releases where μ_v returns to zero.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "buckle/mechanics/chain.h"

namespace buckle::mechanics {

/// One vertex of the moving triangles (file comment).
struct WallVertex {
  int segment = -1;  ///< 0-based
  int corner = 3;    ///< 0 joint, 1/2 proximal ±a, 3/4 distal ±a
  bool operator==(const WallVertex& o) const { return segment == o.segment && corner == o.corner; }
  bool operator!=(const WallVertex& o) const { return !(*this == o); }
  bool operator<(const WallVertex& o) const {
    return segment != o.segment ? segment < o.segment : corner < o.corner;
  }
  /// Whether the triangle holding it is the segment's distal one (corners 3, 4).
  bool distal() const { return corner >= 3; }
  /// The last joint (0-based) that moves it.
  int lastJoint() const { return distal() ? segment : segment - 1; }
  /// "3j", "3p+", "3p-", "3d+", "3d-" (1-based segment): the `wall` column's spelling.
  std::string label() const;
};

/// Throws std::invalid_argument naming the vertex when it is not a moving vertex of the chain.
void checkWallVertex(const WallVertex& v, int segments);

/// Corner `corner` (0–4, as WallVertex) of segment p's triangles, from its joint's position and
/// the absolute angles of the links before and after the joint (the same sums as the shape plots).
Eigen::Vector2d segmentVertex(const SegmentParameters& p, const Eigen::Vector2d& joint, double before, double after,
                              int corner);
/// The same from the links' directions (cos, sin) of those angles: a chain's every vertex with
/// one sine and cosine per joint, not four per vertex.
Eigen::Vector2d segmentVertex(const SegmentParameters& p, const Eigen::Vector2d& joint, const Eigen::Vector2d& before,
                              const Eigen::Vector2d& after, int corner);

/// The vertex's position at q, from the joint positions P = jointPositions(chain, q). O(1).
Eigen::Vector2d wallVertexPoint(const Chain& chain, ConstVectorRef q, const Eigen::Matrix2Xd& P, const WallVertex& v);

/// ∂x_v/∂q into gradient (size n, zero beyond last) and the generator g_m = x_v − x_Pm of
/// −∂²x_v (zero beyond last) into generator (file comment). O(n).
void wallVertexDerivatives(const Eigen::Matrix2Xd& P, const Eigen::Vector2d& point, const WallVertex& v,
                           VectorRef gradient, VectorRef generator);

/// Every moving vertex of the chain, each once (a proximal corner that is the previous
/// segment's distal one is named by the latter, as nearestWallVertex): base to end, corners in
/// increasing order.
std::vector<WallVertex> movingVertices(const Chain& chain);
/// x of every vertex of movingVertices(chain) at q, in that order, into xs (resized). O(n), one
/// sine and cosine per joint.
void movingVertexAbscissae(const Chain& chain, ConstVectorRef q, std::vector<double>& xs);

/// The moving vertex nearest to the wall, i.e. of smallest x, leaving out `exclude` (the vertices
/// already held on it). distance +inf when none is left. A link's two triangles share their base
/// (ℓ_m = b_m2 + b_(m+1)1): where the half-heights are equal (a_(i+1)1 = a_i2) the proximal
/// corners of segment i + 1 are the distal corners of segment i and only the latter are named.
struct WallApproach {
  double distance = 0.0;
  WallVertex vertex;
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
};
WallApproach nearestWallVertex(const Chain& chain, ConstVectorRef q, const std::vector<WallVertex>& exclude = {});

}  // namespace buckle::mechanics
