// Running gnuplot (or any helper program) without a shell and within the run's limits: no
// command line is ever parsed, so no path or name can be taken for shell syntax, and the child
// is stopped as soon as the run must stop (time limit, signal) instead of being waited for.
// std::system would also ignore SIGINT in the caller while the child runs, discarding a Ctrl-C
// that the output writers hold back (output.h, StagingDirectory).
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace buckle::scene {

struct ChildOutcome {
  bool exitedZero = false;  ///< ran to its end with status 0
  std::string stopped;      ///< non-empty: killed because stop() said so (its reason)
  std::string error;        ///< non-empty: could not be started (why)
};

/// Runs `program` with `arguments` in directory `dir`, stdin from /dev/null, stdout and stderr
/// into the file `log` (relative to `dir`), with the signal mask of a fresh process. Every few
/// milliseconds until the child ends asks `stop()`; a non-empty answer ends the child (SIGTERM,
/// SIGKILL half a second later) and is returned as `stopped`.
ChildOutcome runChild(const std::string& program, const std::vector<std::string>& arguments, const std::string& dir,
                      const std::string& log, const std::function<std::string()>& stop);

}  // namespace buckle::scene
