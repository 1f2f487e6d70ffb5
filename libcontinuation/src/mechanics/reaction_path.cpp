#include "buckle/mechanics/reaction_path.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "buckle/mechanics/critical_loading.h"
#include "buckle/mechanics/linear_buckling.h"

namespace buckle::mechanics {

ReactionLimit reactionLimit(const Chain& chain, ConstVectorRef q0, const EndCondition& end, int coordinate,
                            int modes) {
  static const char* loads[3] = {"Fx", "Fy", "Me"};
  if (coordinate < 0 || coordinate > 2 || !end.isHeld(static_cast<EndCoordinate>(coordinate)))
    throw std::invalid_argument("reactionLimit: the coordinate must be one the end condition holds");
  if (modes < 1) throw std::invalid_argument("reactionLimit: modes must be >= 1");
  const CriticalLoading released = criticalLoading(end, coordinate, Eigen::Vector3d::Zero());
  LinearBucklingOptions opt;
  opt.direction = released.direction;
  opt.count = modes;
  const LinearBucklingResult lb = linearBuckling(chain, q0, released.end, opt);
  ReactionLimit out;
  if (lb.degenerate)
    throw std::invalid_argument(std::string("every critical reaction ") + loads[coordinate] +
                                " is 0 (K_q vanishes on the constraints): no load limit can be derived from them");
  for (const BucklingMode& m : lb.modes) {
    if (!(std::isfinite(m.lambda) && m.lambda != 0.0)) continue;
    if (out.modesFound == 0) out.firstCritical = m.lambda;
    out.governing = m.lambda;
    if (++out.modesFound == modes) break;
  }
  if (out.modesFound == 0)
    throw std::invalid_argument(std::string("the reaction ") + loads[coordinate] +
                                " has no finite critical value: the straight start never buckles under it");
  out.limit = kReactionLimitMargin * std::abs(out.governing);
  return out;
}

}  // namespace buckle::mechanics
