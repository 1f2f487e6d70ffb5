// The case's weight and point loads (/gravity, /point_loads) as the library's body loads
// (mechanics/body_loads.h) along the case's path.
#include "scene/case_runner.h"

namespace buckle::scene {

namespace mech = buckle::mechanics;

mech::InertiaData CaseRunner::caseInertia(double massPerLength) const {
  return mech::withPayload(out_.chain, mech::InertiaData::uniformRods(out_.chain, massPerLength), spec_.body.payload);
}

mech::BodyLoads CaseRunner::bodyLoads() const {
  const BodySpec& b = spec_.body;
  mech::BodyLoads loads;
  if (!b.any()) return loads;
  const int n = out_.chain.size();
  // g(λ) = g⁰ + λ g': on a gravity path λ is the magnitude itself
  const Eigen::Vector2d g0 = spec_.path.gravity ? Eigen::Vector2d::Zero() : Eigen::Vector2d(b.gravity * b.direction);
  const Eigen::Vector2d rate = spec_.path.gravity ? b.direction : Eigen::Vector2d::Zero();
  if (b.haveGravity && b.massPerLength > 0.0)
    loads = mech::BodyLoads::weight(out_.chain, mech::InertiaData::uniformRods(out_.chain, b.massPerLength), g0, rate);
  if (b.payload > 0.0) loads.points.push_back({n + 1, b.payload * g0, b.payload * rate});
  const double s0 = out_.startValue;
  for (const PointLoadSpec& p : b.points) loads.points.push_back({p.joint, p.force - s0 * p.rate, p.rate});
  return loads;
}

}  // namespace buckle::scene
