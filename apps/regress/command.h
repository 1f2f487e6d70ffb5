// `buckle regress` as a library function (the CLI subcommand is a thin wrapper).
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace buckle::regress {

/// Exit codes: every value within tolerance; some drift (or time beyond the factor); bad input.
enum ExitCode : int { kAllPass = 0, kDrift = 1, kBadInput = 2 };

struct RegressOptions {
  std::string baselines = "data/regression";  ///< directory of <name>.json baselines
  std::string scenes;                  ///< scene files; empty: <baselines>/../scenes
  std::vector<std::string> only;       ///< baseline names to run (empty: all)
  double timeTolerance = 3.0;          ///< time fails beyond this factor; 0: report only
  int repetitions = 0;                 ///< timed runs per baseline; 0: the baseline's own
  bool ci = false;                     ///< skip baselines marked "ci": false
  std::string json;                    ///< also write the rows here
  bool update = false;                 ///< rewrite the baselines from a fresh run
  bool keepTiming = false;             ///< with update: keep the reference timings
};

/// Re-runs every selected baseline and prints the drift table on `out`; with `update`,
/// rewrites the baselines instead (every scene in the scenes directory and every benchmark
/// problem, or --only those). Errors go to `err`.
int runRegressCommand(const RegressOptions& options, std::ostream& out, std::ostream& err);

}  // namespace buckle::regress
