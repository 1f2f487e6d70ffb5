// What a long `buckle run` is doing, on stderr: a live line on a terminal (rewritten in place),
// plain periodic lines otherwise (logs, CI), nothing with --quiet. Runs shorter than about a
// second print nothing. Fed by the runner's stage changes and the tracer's per-step callback.
#pragma once

#include <chrono>
#include <ostream>
#include <string>

namespace buckle::scene {

class Progress {
 public:
  enum class Mode { Off, Live, Lines };
  /// `liveAfter`: seconds of silence before the first report; `lineInterval`: seconds between
  /// two plain lines (Lines mode).
  Progress(std::ostream& out, Mode mode, double liveAfter = 1.0, double lineInterval = 5.0);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// A new stage of case `caseIndex` (0-based) of `caseCount`.
  void stage(const std::string& name, const std::string& caseLabel, int caseIndex, int caseCount);
  /// The branch being traced (`branch`: 1-based count in this case, the earlier ones finished)
  /// has `points` points and is at parameter `parameter`; `specials` special points so far;
  /// `queued` branch points found but not yet switched at (the tree's size ahead; < 0: none).
  void step(int branch, int points, double parameter, int specials, int queued = -1);
  /// A warning, printed at once as its own line (in every mode but Off).
  void warn(const std::string& what);
  /// Anything else worth a line now and then (a jump being integrated, a located point).
  void note(const std::string& what);
  /// Clears the live line (before the final summary is printed).
  void finish();

  double elapsed() const;

 private:
  void report();

  std::ostream& out_;
  Mode mode_;
  double liveAfter_, lineInterval_;
  std::chrono::steady_clock::time_point start_, last_;
  bool printedLive_ = false, anyPrinted_ = false;
  std::string stage_, case_, detail_;
  int caseIndex_ = 0, caseCount_ = 1;
};

}  // namespace buckle::scene
