// Warm starts of the certified eigenvalue searches (chain_structure.h, eigenvaluesFrom) along a
// branch: the eigenvalues found lately, by their index.
//
// The continuation asks for the eigenvalues next to zero (indices ν − 1, ν: the certified
// counting, spectral_monitor.h) at every point, and the locator for the crossing one at its
// samples. Where branch points crowd (a long straight chain: 199 of them on the default path at
// n = 200), ν changes from one point to the next, so the values of the previous call have other
// indices, and without a guess each value costs a bisection from ±‖H‖_F down to 1e-13 of it
// (about 50 O(n) factorizations). The values of neighbouring indices are near the wanted ones
// (they straddle the same zero), so a guess from them isolates each value in a few counts.
// A guess only saves work: the counts either side certify every value (eigenvalue_search.h).
#pragma once

#include <array>

#include "buckle/mechanics/chain.h"

namespace buckle::mechanics {

class EigenvalueMemory {
 public:
  static constexpr int kSize = 16;  ///< values remembered (the oldest forgotten first)

  /// Remember values[j] as eigenvalue first + j (the latest value of an index replaces the older).
  void remember(int first, ConstVectorRef values);
  /// Guesses for the eigenvalues first … first + out.size() − 1, ascending: a remembered index's
  /// value; between remembered indices the linear interpolation; past them the nearest value
  /// moved by the spacing of the two nearest (or by its own magnitude when only one is known).
  /// False (out unchanged) when nothing is remembered.
  bool guesses(int first, VectorRef out) const;
  void clear() { size_ = 0; }

 private:
  struct Entry {
    int index = 0;
    double value = 0.0;
  };
  std::array<Entry, kSize> entries_{};  // the latest last
  int size_ = 0;
};

}  // namespace buckle::mechanics
