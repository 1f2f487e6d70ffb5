// Control inputs as the path parameter (issue 29): the springs' free lengths L1⁰, L2⁰ of the
// segments — the control inputs of the paper ("two control inputs influencing on the spring
// lengths") — move with the path parameter λ while the end loads stay at a payload or the end
// stays held:
//   L⁰_{i,s}(λ) = L⁰_{i,s} + (λ − origin)·rates(i, s)      (s = 0: L1⁰, s = 1: L2⁰)
// with L⁰_{i,s} the chain's own free lengths. Named directions (every segment, or one):
//   L1_0, L2_0          rates (1, 0), (0, 1)
//   L0  = (L1⁰ + L2⁰)/2 rates (1, 1)       (the common mode; the difference kept)
//   dL0 = L1⁰ − L2⁰     rates (½, −½)      (the differential; the mean kept)
// so that along a named direction λ − origin is the change of that input, and with origin the
// input's value on the chain λ is the input itself (of the segment, or their mean over all).
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>

#include "buckle/mechanics/chain.h"

namespace buckle::mechanics {

enum class ControlInput { L1_0, L2_0, L0, dL0 };

struct ControlDirection {
  /// n×2: dL1⁰/dλ, dL2⁰/dλ of every segment. Empty (0 rows): no control path.
  Eigen::MatrixX2d rates;
  /// λ at which the free lengths are the chain's own.
  double origin = 0.0;

  bool active() const { return rates.rows() > 0; }

  /// The named input of segment `segment` (0-based), or of every segment (−1), origin 0.
  /// Throws std::invalid_argument for a segment out of range or n < 1.
  static ControlDirection named(int n, ControlInput input, int segment = -1);
};

/// The input that with `input` sets both free lengths: L1_0 ↔ L2_0, L0 ↔ dL0.
ControlInput complementaryInput(ControlInput input);

/// Adds to `d` the rates of `input`'s complementary input per unit of d's parameter (a
/// direction in control space): `rates` one value for every segment, or one per segment.
/// Throws std::invalid_argument for another length or a rate that is not finite.
void addComplementaryRates(ControlDirection& d, ControlInput input, const Eigen::VectorXd& rates);

/// "L1_0", "L2_0", "L0", "dL0".
std::string controlInputName(ControlInput input);
/// Parses controlInputName(); false for any other text.
bool parseControlInput(const std::string& name, ControlInput& input);
/// The input's value on the chain: that of segment `segment` (0-based), or the mean over the
/// segments (−1).
double controlInputValue(const Chain& chain, ControlInput input, int segment = -1);

/// The λ for which every free length the direction moves stays positive:
/// L⁰ + (λ − origin)·rate > 0 (±inf where the direction moves none the other way).
std::pair<double, double> admissibleRange(const Chain& chain, const ControlDirection& control);

/// The chain's segments with the free lengths at λ (the others unchanged). Throws
/// std::invalid_argument naming the segment when a free length is not positive there.
Chain chainWithControls(const Chain& chain, const ControlDirection& control, double lambda);

}  // namespace buckle::mechanics
