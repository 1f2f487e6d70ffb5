// The eigenvalues found lately, by index: warm starts of the certified searches (eigenvalue_memory.h).
#include "buckle/mechanics/eigenvalue_memory.h"

#include <cmath>
#include <limits>

namespace buckle::mechanics {

void EigenvalueMemory::remember(int first, ConstVectorRef values) {
  for (Eigen::Index j = 0; j < values.size(); ++j) {
    const double v = values[j];
    if (!std::isfinite(v)) continue;
    const int index = first + int(j);
    int at = 0;
    while (at < size_ && entries_[size_t(at)].index != index) ++at;
    if (at == size_) {
      if (size_ == kSize) at = 0;  // forget the oldest
      else ++size_;
    }
    for (int k = at; k + 1 < size_; ++k) entries_[size_t(k)] = entries_[size_t(k) + 1];
    entries_[size_t(size_) - 1] = Entry{index, v};
  }
}

bool EigenvalueMemory::guesses(int first, VectorRef out) const {
  if (size_ == 0) return false;
  for (Eigen::Index j = 0; j < out.size(); ++j) {
    const int index = first + int(j);
    // the nearest remembered indices below and above (or equal)
    const Entry* below = nullptr;
    const Entry* above = nullptr;
    const Entry* exact = nullptr;
    for (int k = 0; k < size_; ++k) {
      const Entry& e = entries_[size_t(k)];
      if (e.index == index) exact = &e;  // the latest (entries are unique by index)
      else if (e.index < index && (!below || e.index > below->index)) below = &e;
      else if (e.index > index && (!above || e.index < above->index)) above = &e;
    }
    double g = std::numeric_limits<double>::quiet_NaN();
    if (exact) {
      g = exact->value;
    } else if (below && above) {
      const double t = double(index - below->index) / double(above->index - below->index);
      g = below->value + t * (above->value - below->value);
    } else {
      // past the remembered indices: the spacing of the two nearest, or the value's magnitude
      const Entry* near = below ? below : above;
      const Entry* next = nullptr;  // the next one further in, on the same side
      for (int k = 0; k < size_; ++k) {
        const Entry& e = entries_[size_t(k)];
        if (below ? e.index < near->index && (!next || e.index > next->index)
                  : e.index > near->index && (!next || e.index < next->index))
          next = &e;
      }
      const double spacing = next ? std::abs(near->value - next->value) / double(std::abs(near->index - next->index))
                                  : std::abs(near->value);
      g = near->value + double(index - near->index) * spacing;
    }
    out[j] = g;
  }
  return true;
}

}  // namespace buckle::mechanics
