// Special points in the field's words (mechanics/classification.h): the shape named at a
// branch point of multiplicity > 1 does not depend on the arbitrary basis of its kernel.
#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <cmath>

#include "buckle/mechanics/classification.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

TEST_CASE("a multiple branch point names the same mode whatever basis its kernel comes in", "[classification]") {
  // The hysteresis scene's point: three identical joints at the fold of their torque-angle curve,
  // free end, end torque as parameter. ker [F_u F_λ] = {(v, 0)}: the traced branch along
  // (1, 1, 1, 0), the bifurcating directions its complement (1, 1, 1)⊥ in the joint angles.
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.2));
  const EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 0, 1));
  cont::SpecialPoint bp;
  bp.type = cont::SpecialPointType::BranchPoint;
  bp.multiplicity = 3;
  bp.u = Eigen::VectorXd::Constant(3, 0.7259372972113);
  bp.lambda = -0.1436326148038883;
  const Eigen::Vector4d t(1.0 / std::sqrt(3.0), 1.0 / std::sqrt(3.0), 1.0 / std::sqrt(3.0), 0.0);
  for (double angle : {0.0, 0.3, 1.1, 2.0, 2.9, 4.4}) {
    // An orthonormal basis of the complement of t in the v-space, rotated by `angle`.
    const Eigen::Vector4d a = Eigen::Vector4d(1, -1, 0, 0).normalized(), b = Eigen::Vector4d(1, 1, -2, 0).normalized();
    bp.nullVectors.resize(4, 3);
    bp.nullVectors.col(0) = t;
    bp.nullVectors.col(1) = std::cos(angle) * a + std::sin(angle) * b;
    bp.nullVectors.col(2) = -std::sin(angle) * a + std::cos(angle) * b;
    const Classification c = classify(problem, bp);
    // The projection of joint 1's rotation: (2, −1, −1)/3, the U pattern (+, −, −) of Table I.
    CHECK(c.shape == "U");
    CHECK(c.phenomenon == Phenomenon::Buckling);
  }
  // A simple branch point names its one bifurcating direction as given.
  bp.multiplicity = 1;
  bp.nullVectors.resize(4, 2);
  bp.nullVectors.col(0) = t;
  bp.nullVectors.col(1) = Eigen::Vector4d(-1, 1, -1, 0).normalized();
  CHECK(classify(problem, bp).shape == "Z");
}
