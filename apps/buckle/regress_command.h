// `buckle regress`: re-run the regression baselines (data/regression) and report drift.
#pragma once

#include <CLI/CLI.hpp>

#include "command.h"

namespace buckle::cli {

/// Adds the `regress` subcommand to `app` under `name` (main.cpp's table of subcommands); its status
/// is written to `outcome` when it runs.
void addRegressCommand(CLI::App& app, Outcome& outcome, const char* name);

}  // namespace buckle::cli
