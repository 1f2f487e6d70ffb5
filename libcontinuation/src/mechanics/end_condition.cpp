#include "buckle/mechanics/end_condition.h"

namespace buckle::mechanics {

EndCondition EndCondition::freeEnd(const Eigen::Vector3d& wrench) {
  EndCondition e;
  e.value = wrench;
  return e;
}

EndCondition EndCondition::clampedPinned(double Fx, double y) {
  EndCondition e;
  e.control = {Control::Load, Control::Held, Control::Load};
  e.value = Eigen::Vector3d(Fx, y, 0.0);
  return e;
}

EndCondition EndCondition::heldPosition(double x, double y) {
  EndCondition e;
  e.control = {Control::Held, Control::Held, Control::Load};
  e.value = Eigen::Vector3d(x, y, 0.0);
  return e;
}

std::vector<int> EndCondition::heldIndices() const {
  std::vector<int> idx;
  for (int c = 0; c < 3; ++c)
    if (control[size_t(c)] == Control::Held) idx.push_back(c);
  return idx;
}

std::vector<int> EndCondition::loadedIndices() const {
  std::vector<int> idx;
  for (int c = 0; c < 3; ++c)
    if (control[size_t(c)] == Control::Load) idx.push_back(c);
  return idx;
}

}  // namespace buckle::mechanics
