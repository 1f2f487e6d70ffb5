// `buckle show DIR`: the results of a `buckle run` as tables on the terminal, read back from
// its output directory (special_points.json, summary.json), for when there are no plots.
#pragma once

#include <CLI/CLI.hpp>

#include "command.h"

namespace buckle::cli {

/// Adds the `show` subcommand to `app` under `name` (main.cpp's table of subcommands); its status
/// is written to `outcome` when it runs.
void addShowCommand(CLI::App& app, Outcome& outcome, const char* name);

}  // namespace buckle::cli
