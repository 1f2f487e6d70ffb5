// A regression baseline (data/regression/<name>.json, format in docs/regression.md): what one
// scene or benchmark problem is expected to compute — special points, branch samples, each with
// its tolerance — and how long it took on the machine that wrote it.
#pragma once

#include <string>
#include <vector>

#include "regress/measurement.h"

namespace buckle::regress {

/// A value passes when |now − baseline| ≤ absolute + relative·|baseline|.
struct Tolerance {
  double absolute = 0.0;
  double relative = 0.0;
  double allowed(double baseline) const;
};

/// How --update sets each entry's tolerance (kept from the existing file, so hand-tuning a
/// baseline's policy survives updates).
struct TolerancePolicy {
  // Located points reproduce to ~1e-15 under changed step sizes; 1e-10 leaves room for a
  // different linear algebra in the core without hiding a real change.
  double lambdaRelative = 1e-10;  ///< located special points: λ relative
  double lambdaAbsolute = 1e-12;  ///< ... and absolute floor
  double accuracyFactor = 2.0;    ///< absolute ≥ factor × the point's own location accuracy
  double sampleAbsolute = 1e-10;  ///< branch samples: absolute floor
  double sampleRelative = 1e-10;
  double sampleErrorFactor = 2.0; ///< absolute ≥ factor × the interpolation error estimate
};

struct SpecialEntry {
  int branch = 0;
  std::string type;
  int order = 0;  ///< k-th point of this type on this branch
  double lambda = 0.0;
  std::string shape;
  /// The branch point's post-buckling name; empty (and absent from the file) elsewhere, and in
  /// baselines written before it was recorded (then not compared).
  std::string postBuckling;
  Tolerance tolerance;
};

struct SampleEntry {
  int branch = 0;
  double lambda = 0.0;
  int crossing = 0;
  std::vector<int> coordinates;  ///< joint indices (0-based; "q1" in the file is 0)
  std::vector<double> values;
  Tolerance tolerance;
};

struct CaseEntry {
  std::string label;
  int branches = 0;
  std::vector<SpecialEntry> specials;
  std::vector<SampleEntry> samples;
};

struct Baseline {
  std::string file;  ///< where it was read from (messages)
  std::string name;
  Source source;
  bool ci = true;        ///< run by `buckle regress --ci` (the ctest entry)
  int repetitions = 3;   ///< timed runs; the median is compared
  double referenceSeconds = 0.0;
  std::string machine;
  TolerancePolicy policy;
  std::vector<CaseEntry> cases;
};

/// Reads and validates a baseline; JsonInputError (scene/json_reader.h) names the file and the
/// JSON path of anything wrong.
Baseline loadBaseline(const std::string& file);

/// The file text: fixed key order, round-trip (shortest exact) numbers, 2-space indent, so the
/// same values always give the same bytes and `git diff` shows only what changed.
std::string formatBaseline(const Baseline& b);

/// A baseline from a fresh measurement. `settings` supplies the name, source, ci, repetitions
/// and tolerance policy (its cases and timing are replaced).
Baseline makeBaseline(const Baseline& settings, const Measurement& m, const std::string& machine);

/// The special points of a case grouped by (branch, type) and numbered in order, as matched.
std::vector<SpecialEntry> numberSpecials(const MeasuredCase& c, const TolerancePolicy& policy);

/// Joint angles recorded at each sample: the first and the last.
std::vector<int> sampleCoordinates(int joints);

/// "<cpu model>, <n> threads": where the reference timing was taken.
std::string machineDescription();

/// Writes `text` to a temporary file beside `file` and renames it into place: readers see the
/// old or the new file, never a half-written one. Throws std::runtime_error on failure.
void writeFileAtomically(const std::string& file, const std::string& text);

}  // namespace buckle::regress
