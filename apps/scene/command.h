// `buckle run SCENE [--out DIR]` as a library function (the CLI subcommand is a thin wrapper,
// and the tests call this directly).
#pragma once

#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "scene/progress.h"
#include "scene/shared_work.h"

namespace buckle::scene {

/// Exit codes of the scene commands.
enum ExitCode : int { kSuccess = 0, kIncomplete = 1, kBadInput = 2 };

struct RunCommandOptions {
  std::string scene;        ///< scene file
  std::string out;          ///< output directory; empty: out/<scene stem>
  bool quiet = false;       ///< no progress messages on `log`, no progress line on `err`
  bool force = false;       ///< `out` may replace a regular file or a non-buckle directory (output_target.h)
  /// Seconds for the whole run, overriding the scene's /solver/time_limit (NaN: the scene's).
  double timeLimit = std::numeric_limits<double>::quiet_NaN();
  /// Progress on `err`: a live line (terminal) or plain periodic lines; Off when quiet.
  Progress::Mode progress = Progress::Mode::Lines;
  /// Stop on SIGINT/SIGTERM with partial results (the CLI); off for in-process callers.
  bool handleSignals = false;
  /// The other processes of `mpirun -np N buckle-mpi run` (shared_work.h): the writer checks
  /// `out` and writes; the others compute their share and write nothing (not even an error
  /// message: the writer says it).
  SharedWork shared;
};

/// The problems of a run for a human: the first `keep` as they are, then the rest grouped by
/// their shape (digits ignored), each group once with its count and one example.
std::vector<std::string> summariseProblems(const std::vector<std::string>& problems, size_t keep = 8);

/// Parses the scene and checks `out` (output_target.h) (bad input or a refused or unwritable
/// `out`: message on `err`, nothing written, returns kBadInput), runs
/// what it asks for, writes everything into a staging directory next to `out` and renames it
/// into place. Returns kSuccess, or kIncomplete when a computation could not finish or the time
/// limit stopped it (what was computed is still written), or 128 + the signal number after
/// SIGINT/SIGTERM (with handleSignals; what was computed is still written).
int runSceneCommand(const RunCommandOptions& options, std::ostream& log, std::ostream& err);

/// Default output directory for a scene file: out/<stem>.
std::string defaultOutputDirectory(const std::string& scene);

}  // namespace buckle::scene
