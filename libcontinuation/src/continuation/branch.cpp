#include "buckle/continuation/branch.h"

namespace buckle::continuation {

Vector ContinuationPoint::state() const {
  Vector x(u.size() + 1);
  x << u, lambda;
  return x;
}

const char *label(SpecialPointType type) {
  switch (type) {
    case SpecialPointType::Fold: return "LP";
    case SpecialPointType::BranchPoint: return "BP";
    case SpecialPointType::Boundary: return "BD";
    case SpecialPointType::Endpoint: return "EP";
    case SpecialPointType::EigenvalueTouch: return "ET";
  }
  return "??";
}

const char *toString(StopReason reason) {
  switch (reason) {
    case StopReason::NotStarted: return "not started";
    case StopReason::InvalidOptions: return "invalid options";
    case StopReason::StartFailed: return "start failed";
    case StopReason::MaxPoints: return "maximum number of points";
    case StopReason::LambdaRange: return "parameter range end";
    case StopReason::MaxArclength: return "maximum arclength";
    case StopReason::Box: return "box";
    case StopReason::Boundary: return "boundary";
    case StopReason::StepSizeTooSmall: return "step size below minimum";
    case StopReason::SwitchFailed: return "branch switching failed";
    case StopReason::Interrupted: return "interrupted";
    case StopReason::Joined: return "joined a traced branch";
    case StopReason::ClosedLoop: return "closed loop";
    case StopReason::EventNotContinued: return "event not continued";
    case StopReason::Paused: return "paused at a branch point";
  }
  return "unknown";
}

std::vector<const SpecialPoint *> Branch::specialPointsOfType(SpecialPointType type) const {
  std::vector<const SpecialPoint *> result;
  for (const SpecialPoint &point : specialPoints)
    if (point.type == type) result.push_back(&point);
  return result;
}

}  // namespace buckle::continuation
