// Contact of the chain with itself as a unilateral constraint: a vertex of one link's body held
// on an edge of another link's triangle (docs/mechanics.md, "Contact of the chain with itself").
// Conventions: conventions.h; the vertices are wall_contact.h's WallVertex (any corner of any
// triangle, the clamped one's included).
//
// The gap of vertex v against edge e = (e0, e1) of a triangle, n_e the edge's outward unit normal:
//     g(q) = n_e · (p_v − p_e0)        (> 0 apart, = 0 touching).
// g is invariant under a rigid motion of both bodies, so a joint that moves both (j ≤ lo, lo the
// last joint that moves the more proximal of the two bodies) does not change it. With hi the last
// joint of the more distal body, σ = +1 when the vertex's body is the distal one (the joints
// lo < j ≤ hi move the vertex) and −1 when the edge's is (they move the edge: in its frame the
// vertex turns the other way about the same joints), and c_m = −n_e · (p_v − P_m) on lo < m ≤ hi:
//     ∂g/∂q_j = σ n_e · R90 (p_v − P_j)                                    (lo < j ≤ hi)
//     σ = +1:  ∂²g/∂q_j∂q_k = c_max(j,k) on the block (lo, hi]², zero elsewhere
//     σ = −1:  ∂²g/∂q_j∂q_k = −c_min(j,k) on the block
// (the wall is σ = +1 with lo = −1 and n_e = (1, 0): wall_contact.h). Both are the generator form
// of K_g (eq 27) plus a symmetric rank-2 term: with G(γ)_jk = γ_max(j,k),
//     −∂²g = G(γ) − (c wᵀ + w cᵀ),   σ = +1: γ = −c, w = −1 on j ≤ lo;   σ = −1: γ = c, w = +1 on j ≤ hi,
// since c_min = c_j + c_k − c_max. The rank-2 term couples the two bodies' joints outside the
// generator form: the O(n) solves and counts border it (selfCouplingColumns).
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/wall_contact.h"

namespace buckle::mechanics {

/// An edge of a segment's triangle: the proximal (distal = false: corners 0, 1, 2) or the distal
/// one (corners 0, 3, 4) of `segment` (0-based); edge 0 its base (between its ±a corners), 1 from
/// the apex (the joint) to its +a corner, 2 from the apex to its −a corner.
struct TriangleEdge {
  int segment = -1;
  bool distal = true;
  int edge = 0;
  bool operator==(const TriangleEdge& o) const { return segment == o.segment && distal == o.distal && edge == o.edge; }
  bool operator<(const TriangleEdge& o) const {
    if (segment != o.segment) return segment < o.segment;
    return distal != o.distal ? distal < o.distal : edge < o.edge;
  }
  /// The last joint that moves the triangle (−1: the clamped one).
  int lastJoint() const { return distal ? segment : segment - 1; }
  /// The link (contact_geometry.h) whose body the triangle belongs to.
  int link() const { return distal ? segment + 1 : segment; }
  /// The edge's two corners (e0, e1) and the triangle's third one, as WallVertex corners.
  int corner(int k) const;
  /// "3d[j,+]", "3p[+,-]" (1-based segment; j the apex, + and − the ±a corners).
  std::string label() const;
};

/// Vertex `vertex` held on edge `edge` (self contact).
struct SelfContact {
  WallVertex vertex;
  TriangleEdge edge;
  bool operator==(const SelfContact& o) const { return vertex == o.vertex && edge == o.edge; }
  bool operator!=(const SelfContact& o) const { return !(*this == o); }
  bool operator<(const SelfContact& o) const { return vertex != o.vertex ? vertex < o.vertex : edge < o.edge; }
  /// "7d+ on 3d[j,+]": the `self` column's spelling.
  std::string label() const;
};

/// Throws std::invalid_argument naming the contact when the vertex or the edge is not one of the
/// chain's, or when their bodies are not two links or more apart (a joint's own contact is its limit).
void checkSelfContact(const SelfContact& c, int segments);

/// The gap of a self contact at q and where the vertex is along the edge.
struct SelfContactGap {
  double gap = 0.0;    ///< g = n_e · (p_v − p_e0)
  double along = 0.0;  ///< t of the vertex's projection p_e0 + t (p_e1 − p_e0): in [0, 1] on the edge
  double edgeLength = 0.0;
  Eigen::Vector2d normal = Eigen::Vector2d::Zero();  ///< n_e, outward
  Eigen::Vector2d vertex = Eigen::Vector2d::Zero();  ///< p_v
};
/// O(n) with the joint positions P = jointPositions(chain, q).
SelfContactGap selfContactGap(const Chain& chain, ConstVectorRef q, const Eigen::Matrix2Xd& P, const SelfContact& c);

/// ∇g into gradient and −∂²g = G(generator) − (coupling weightsᵀ + weights couplingᵀ) (file
/// comment; every vector of size n, zero where the formula has no entry). O(n).
void selfContactDerivatives(const Eigen::Matrix2Xd& P, const SelfContact& c, const SelfContactGap& g, VectorRef gradient,
                            VectorRef generator, VectorRef coupling, VectorRef weights);

/// The rank-2 part −μ(c wᵀ + w cᵀ) of a held self contact's −μ∂²g (c = coupling, w = weights) as
/// R E Rᵀ with E = diag(−s, s), s = sign μ (+1 at μ = 0): with β = √(‖w‖/‖c‖) balancing the two
/// (c is a length, w a number: no cancellation whichever is the larger) and ρ = √(|μ|/2),
///     R = ρ [β c + w/β, β c − w/β],
/// since c wᵀ + w cᵀ = ½(a aᵀ − b bᵀ) for a = βc + w/β, b = βc − w/β. Bordered by R with the block
/// −E, whose entries are ±1 at any μ (no 1/μ at release), the term keeps the chain structure's
/// O(n) form (chain_structure.h, setCoupling). R is n×2; returns s.
double selfCouplingColumns(ConstVectorRef coupling, ConstVectorRef weights, double mu, MatrixRef R);

/// The vertex–edge pair by which links linkA and linkB (contact_geometry.h numbering, at least two
/// apart) touch at q: among every vertex of one link's triangles against every edge of the
/// other's, the one whose vertex lies nearest to the edge's line with its projection on the edge
/// (0 ≤ t ≤ 1), by |g|; but where a vertex lies inside a triangle of the other link (beyond
/// rounding: a step of the dynamics or a landing's solve ended there), the deepest one on the
/// edge it is nearest to. The vertices `held` on the same pair of links and their edges' ends are
/// left out: the pair's second contact. Throws std::invalid_argument for links that cannot touch.
SelfContact touchingPair(const Chain& chain, ConstVectorRef q, int linkA, int linkB,
                         const std::vector<SelfContact>& held = {});

/// The pairs of links (contact_geometry.h numbering, lower first, sorted) that the contacts `held`
/// hold together: the edge's link with each link of the vertex (a joint is on two).
std::vector<std::pair<int, int>> heldLinkPairs(const std::vector<SelfContact>& held);

/// The clearance of the pairs of links that hold contacts in `held`: each vertex of either link's
/// triangles, but those held on the pair and their edges' ends, against the other link's
/// triangles (its distance outside, minus its distance to the nearest edge inside); the smallest,
/// the pair it was found on in linkA, linkB when given (+inf without contacts). O(contacts).
double heldPairsClearance(const Chain& chain, ConstVectorRef q, const Eigen::Matrix2Xd& P,
                          const std::vector<SelfContact>& held, int* linkA = nullptr, int* linkB = nullptr);

/// The contact of the same vertex on the edge that shares `c`'s base corner (t = 1): the same
/// side's edge of the link's other triangle (the link's outline is a diamond, convex at its ±a
/// corners, when the two triangles' half-heights are equal). False for a base edge, a link with
/// one triangle there or unequal half-heights (the outline has a step there). (At the apex, t = 0,
/// the edge meets the next link's at a joint, where the outline has a notch or a ridge: a vertex
/// there touches two links at a point of both, which the model does not hold.)
bool cornerNeighbour(const Chain& chain, const SelfContact& c, SelfContact& next);

/// Whether `c` is half of a vertex held at its edge's base corner: its corner neighbour is held
/// too. The two gaps then pin the vertex to the corner (g = 0 along both edges' normals), and the
/// force may point anywhere in the corner's normal cone (both forces ≥ 0).
bool heldAtCorner(const Chain& chain, const SelfContact& c, const std::vector<SelfContact>& held);

/// d_self (contact_geometry.h) over the pairs of links that hold none of `held` between them, and
/// heldPairsClearance over those that do: the clearance boundary of a chain holding those self
/// contacts. The pair it was found on in linkA, linkB when given. O(n log n) unless the chain
/// folds onto itself.
double selfClearanceApart(const Chain& chain, ConstVectorRef q, const std::vector<SelfContact>& held,
                          int* linkA = nullptr, int* linkB = nullptr);

}  // namespace buckle::mechanics
