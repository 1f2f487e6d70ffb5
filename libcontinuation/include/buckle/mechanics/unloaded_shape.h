// Unloaded shape of the chain from the preloads, and the inverse: preloads for a given shape.
//
// Without end load each segment is independent: its unloaded angle solves M(q) = 0 inside its
// joint limits. The chosen root is the stable one (K_q > 0) nearest to q = 0 — for equal
// preloads and a monotonic segment that is q = 0 itself, and it moves continuously with the
// preloads; other roots are reported.
// Inverse: M(q⁰) = 0 is linear in (L1⁰, L2⁰) (eq 19 in general form):
//   k1 L1'(q⁰) (L1(q⁰) − L1⁰) + k2 L2'(q⁰) (L2(q⁰) − L2⁰) = 0,
// so with L1⁰ + L2⁰ = S fixed the preloads follow in closed form.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "buckle/continuation/options_validity.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/segment.h"

namespace buckle::mechanics {

struct TorqueRoot {
  double q = 0.0;          ///< M(q) = 0
  double stiffness = 0.0;  ///< K_q(q) = −M'(q)
  bool stable = false;     ///< K_q > 0 (K_q zero to rounding: M > 0 below the root and M < 0 above)
};

struct SegmentUnloadedAngle {
  bool found = false;                ///< false: M has no zero inside the joint limits
  TorqueRoot root;                   ///< the chosen root (stable one nearest 0, else root nearest 0)
  std::vector<TorqueRoot> others;    ///< every other root inside the limits, ascending q
};

struct UnloadedShape {
  Eigen::VectorXd q;                          ///< chosen unloaded angles (NaN where none found)
  std::vector<SegmentUnloadedAngle> segments;
  bool allFound = false;
  bool allStable = false;                     ///< every chosen root has K_q > 0
};

struct UnloadedShapeOptions {
  int samples = 2000;         ///< scan resolution of each joint range for sign changes of M
  double tolerance = 1e-14;   ///< root tolerance on q (absolute, radians)
  /// Empty when valid, else what is wrong, the field named by its path after `prefix`.
  std::string validate(const std::string& prefix = "") const;
  bool IsValid(std::string* why) const { return continuation::reportValidity(validate(), why); }
};

/// Roots of M(q) in the joint limits of one segment, and the chosen one.
SegmentUnloadedAngle unloadedAngle(const Segment& segment, const UnloadedShapeOptions& options = {});

/// The torque–angle curve of one segment (eq 1, Fig 2): M(q) = −dE/dq and K_q(q) = d²E/dq² on
/// `points` evenly spaced angles of [from, to] ∩ the joint's range (kept 1e-6 rad inside a
/// geometric limit, where the closing spring's length vanishes), with its unloaded equilibria.
struct TorqueCurve {
  std::vector<double> q, M, Kq;
  std::vector<std::pair<double, bool>> equilibria;  ///< (q, stable) with M(q) = 0, ascending
};
TorqueCurve torqueCurve(const Segment& segment, double from, double to, int points);
/// All segments of a chain.
UnloadedShape unloadedShape(const Chain& chain, const UnloadedShapeOptions& options = {});

struct PreloadResult {
  SegmentParameters parameters;  ///< input parameters with L1_0, L2_0 replaced
  double stiffness = 0.0;        ///< K_q(q⁰) with the new preloads
  bool stable = false;           ///< K_q(q⁰) > 0
};

/// Preloads (L1⁰, L2⁰) making q⁰ an unloaded equilibrium of the segment, with L1⁰ + L2⁰ equal
/// to the given segment's. Throws std::invalid_argument naming the parameter ("q0", "L1_0",
/// "L2_0") when q⁰ is outside the joint limits, not finite, or needs a free length <= 0.
PreloadResult preloadsForAngle(const SegmentParameters& segment, double q0);

/// The same for every segment of a chain; messages are prefixed "segment i: " (1-based).
/// The returned parameters build a Chain whose unloaded shape is q⁰.
std::vector<SegmentParameters> preloadsForShape(const std::vector<SegmentParameters>& segments,
                                                const Eigen::Ref<const Eigen::VectorXd>& q0);

}  // namespace buckle::mechanics
