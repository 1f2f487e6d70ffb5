// `buckle run SCENE [--out DIR]` as a library function (the CLI subcommand is a thin wrapper,
// and the tests call this directly).
#pragma once

#include <ostream>
#include <string>

namespace buckle::scene {

/// Exit codes of the scene commands.
enum ExitCode : int { kSuccess = 0, kIncomplete = 1, kBadInput = 2 };

struct RunCommandOptions {
  std::string scene;        ///< scene file
  std::string out;          ///< output directory; empty: out/<scene stem>
  bool quiet = false;       ///< no progress messages on `log`
  bool force = false;       ///< `out` may replace a regular file or a non-buckle directory (output_target.h)
};

/// Parses the scene and checks `out` (output_target.h) (bad input or a refused or unwritable
/// `out`: message on `err`, nothing written, returns kBadInput), runs
/// what it asks for, writes everything into a staging directory next to `out` and renames it
/// into place. Returns kSuccess, or kIncomplete when a computation could not finish (what was
/// computed is still written).
int runSceneCommand(const RunCommandOptions& options, std::ostream& log, std::ostream& err);

/// Default output directory for a scene file: out/<stem>.
std::string defaultOutputDirectory(const std::string& scene);

}  // namespace buckle::scene
