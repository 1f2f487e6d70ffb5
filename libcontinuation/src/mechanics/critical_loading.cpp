#include "buckle/mechanics/critical_loading.h"

#include <stdexcept>

#include "buckle/mechanics/chain_structure.h"

namespace buckle::mechanics {

CriticalLoading criticalLoading(const EndCondition& end, int coordinate, const Eigen::Vector3d& direction) {
  if (coordinate < 0 || coordinate > 2) throw std::invalid_argument("criticalLoading: coordinate outside 0…2");
  CriticalLoading out;
  out.end = end;
  if (end.isHeld(static_cast<EndCoordinate>(coordinate))) {
    out.end.control[size_t(coordinate)] = Control::Load;
    out.direction[coordinate] = 1.0;
    return out;
  }
  out.direction = direction;
  for (int j = 0; j < 3; ++j)
    if (end.isHeld(static_cast<EndCoordinate>(j))) out.direction[j] = 0.0;
  return out;
}

bool clampedPinned3Applies(const Chain& chain, ConstVectorRef q0, const CriticalLoading& loading) {
  if (chain.size() != 3 || q0.size() != 3 || q0.cwiseAbs().maxCoeff() != 0.0) return false;
  const SegmentParameters& first = chain.segment(0).parameters();
  for (int i = 0; i < 3; ++i) {
    const SegmentParameters& s = chain.segment(i).parameters();
    if (!(s.a1 == first.a1 && s.a2 == s.a1 && s.b1 == first.b1 && s.b2 == s.b1 && s.k1 == first.k1 && s.k2 == s.k1 &&
          s.L1_0 == first.L1_0 && s.L2_0 == s.L1_0))
      return false;
  }
  const EndCondition& end = loading.end;
  return end.isHeld(EndCoordinate::Y) && !end.isHeld(EndCoordinate::X) && !end.isHeld(EndCoordinate::Phi) &&
         loading.direction[0] != 0.0 && loading.direction[1] == 0.0 && loading.direction[2] == 0.0;
}

int criticalLoadCount(const Chain& chain, ConstVectorRef q0, const CriticalLoading& loading, double lambda) {
  const int n = chain.size();
  if (q0.size() != n) throw std::invalid_argument("criticalLoadCount: q0 must have one angle per joint");
  ChainData data(chain);
  forwardKinematics(chain, q0, data);
  Matrix J(3, n);
  endJacobian(data, J);
  const std::vector<int> held = loading.end.heldIndices();
  Matrix C(int(held.size()), n);
  for (size_t k = 0; k < held.size(); ++k) C.row(Eigen::Index(k)) = J.row(held[k]);
  ChainStructure ws(n);
  double k = 0.0, b = 0.0;  // the chain's stiffness unit k̄b̄²: the floor of the zero threshold
  for (int i = 0; i < n; ++i) {
    const SegmentParameters& s = chain.segment(i).parameters();
    k += 0.5 * (s.k1 + s.k2) / n;
    b += 0.5 * (s.b1 + s.b2) / n;
  }
  ws.typicalScale = k * b * b;
  auto negative = [&](double factor) {
    assemble(chain, data, q0, Wrench(factor * loading.direction), ws);
    return constrainedInertia(ws, C).negative;
  };
  return std::abs(negative(lambda) - negative(0.0));
}

}  // namespace buckle::mechanics
