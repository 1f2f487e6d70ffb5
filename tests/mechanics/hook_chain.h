// The hook of the self-contact tests: a chain that curls onto itself under an end moment
// (data/scenes/self_contact_hook.json), and its statics by the tests' own geometry.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/self_contact.h"
#include "buckle/mechanics/unloaded_shape.h"
#include "wall_statics.h"

namespace buckle::test {

namespace mech = buckle::mechanics;
using Eigen::Vector2d;
using Eigen::VectorXd;

// A hook: three straight segments, five curled by 0.9 rad, free end under an end moment Me: the
// curl closes until the end's distal corner 8d− meets the straight part (link 3's triangle).
// Lengths scaled by sL, stiffnesses by sK.
struct Hook {
  VectorXd q0 = (VectorXd(8) << 0, 0, 0, 0.9, 0.9, 0.9, 0.9, 0.9).finished();
  mech::Chain chain;
  mech::EquilibriumProblem problem;
  Hook(double sL, double sK)
      : chain(mech::preloadsForShape(
            std::vector<mech::SegmentParameters>(8, mech::SegmentParameters::symmetric(0.3 * sL, sL, sK, 2.25 * sL)), q0)),
        problem(chain, mech::EndCondition::freeEnd(), Eigen::Vector3d(0, 0, 1), options()) {}
  /// One branch from Me = 0 to `to` torque units (k b² of the scaled chain), the scene's steps.
  mech::EquilibriumBranchOptions upTo(double to) const {
    mech::EquilibriumBranchOptions o;
    o.tracer.lambdaMax = to * chain.segment(0).parameters().k1 * chain.segment(0).parameters().b1 *
                         chain.segment(0).parameters().b1;
    o.tracer.step.initialStep = 0.01;
    o.tracer.step.maxStep = 0.02;
    o.tree.branchSwitching = 0;
    return o;
  }
  mech::EquilibriumBranches trace(const mech::EquilibriumBranchOptions& o) {
    return mech::traceEquilibria(problem, q0, 0.0, buckle::continuation::InitialDirection::increasingLambda(), o);
  }
  static mech::EquilibriumOptions options() {
    mech::EquilibriumOptions o;
    o.selfContactAsBoundary = true;
    return o;
  }
};

// The statics of a point holding self contact c under the end moment Me, by the test's own
// geometry: joint j carries Me and, when it moves the vertex's body but not the edge's, the moment
// of μ n_e at the vertex (joints that move both bodies see the pair of forces cancel). μ from the
// joint where its lever is largest; the largest imbalance over every joint, and μ.
inline std::pair<double, double> hookStatics(const mech::Chain& chain, const VectorXd& q, double Me, const mech::SelfContact& c) {
  const int n = chain.size();
  const Vector2d p = vertexAt(chain, q, c.vertex);
  const Vector2d e0 = vertexAt(chain, q, {c.edge.segment, c.edge.corner(0)});
  const Vector2d e1 = vertexAt(chain, q, {c.edge.segment, c.edge.corner(1)});
  const Vector2d third = vertexAt(chain, q, {c.edge.segment, c.edge.corner(2)});
  Vector2d normal(e1.y() - e0.y(), e0.x() - e1.x());
  normal.normalize();
  if (normal.dot(third - e0) > 0.0) normal = -normal;
  const Geometry g = geometry(chain, q);
  const int lo = std::min(c.vertex.lastJoint(), c.edge.lastJoint()), hi = std::max(c.vertex.lastJoint(), c.edge.lastJoint());
  const double sigma = c.vertex.lastJoint() > c.edge.lastJoint() ? 1.0 : -1.0;  // the force on the distal body: ±μ n
  VectorXd lever = VectorXd::Zero(n), dE(n);
  for (int j = 0; j < n; ++j) {
    dE[j] = -chain.segment(j).torque(q[j]);
    if (j > lo && j <= hi) lever[j] = sigma * moment(p, g.P.col(j), normal);
  }
  int k = 0;
  lever.cwiseAbs().maxCoeff(&k);
  const double mu = (dE[k] - Me) / lever[k];
  double imbalance = 0.0;
  for (int j = 0; j < n; ++j) imbalance = std::max(imbalance, std::abs(dE[j] - Me - mu * lever[j]));
  return {imbalance, mu};
}
}  // namespace buckle::test
