// The tracer settings a chain's analyses start from: scenes and Python scenes read them here,
// and a scene's /solver block changes only what it names.
#pragma once

#include "buckle/continuation/tracer_options.h"

namespace buckle::mechanics {

/// The core's defaults (continuation::TracerOptions) with steps sized for the chain's scaled
/// variables, in which a joint angle of one radian and the load k̄b̄ are O(1) (initial 0.02,
/// between 1e-7 and 0.05), and up to 10 000 points per branch: a path to several times the first
/// critical load, also for a long chain's children that lock and release its joints a hundred
/// times and more before they close into a loop (the default scene with 100 segments: 6626).
inline continuation::TracerOptions chainTracerOptions() {
  continuation::TracerOptions o;
  o.step.initialStep = 0.02;
  o.step.minStep = 1e-7;
  o.step.maxStep = 0.05;
  o.maxPoints = 10000;
  return o;
}

}  // namespace buckle::mechanics
