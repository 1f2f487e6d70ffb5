#include "buckle/mechanics/end_condition.h"

#include <stdexcept>
#include <string>

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

EndCondition LoadPath::problemEnd() const {
  EndCondition e = start;
  e.value -= startValue * direction;
  return e;
}

EndCondition LoadPath::at(double lambda) const {
  EndCondition e = start;
  e.value += (lambda - startValue) * direction;
  return e;
}

LoadPath LoadPath::throughReaction(int c) const {
  if (c < 0 || c > 2 || start.control[size_t(c)] != Control::Held)
    throw std::invalid_argument("LoadPath::throughReaction: coordinate " + std::to_string(c) +
                                " is not a held end coordinate");
  LoadPath r;
  r.start = start;
  r.start.control[size_t(c)] = Control::Load;
  r.start.value[c] = 0.0;
  r.direction = Eigen::Vector3d::Unit(c);
  r.startValue = 0.0;
  return r;
}

}  // namespace buckle::mechanics
