// Comparing a fresh measurement with its baseline, one row per checked quantity.
#pragma once

#include <string>
#include <vector>

#include "regress/baseline.h"
#include "regress/measurement.h"

namespace buckle::regress {

enum class Status { Pass, Fail, Info };
const char* toString(Status s);

struct Row {
  std::string name;      ///< baseline name
  std::string quantity;  ///< e.g. "b1 BP#0 lambda", "b0 sample@-1.2 q3", "time"
  std::string baseline, now, drift, tolerance;
  Status status = Status::Pass;
};

/// Time drift fails only beyond `factor` × reference + `slack` (the machine is shared and
/// noisy); factor 0: reported, never a failure.
struct TimingCheck {
  double factor = 3.0;
  double slackSeconds = 0.02;
  /// Time-limited baselines: the run must end within the limit plus this (one step, generous
  /// for sanitizer builds).
  double stopSlackSeconds = 1.0;
};

std::vector<Row> compare(const Baseline& b, const Measurement& m, const TimingCheck& timing);

}  // namespace buckle::regress
