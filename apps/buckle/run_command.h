// `buckle run SCENE [--out DIR]`: compute what a scene file asks for (docs/scenes.md).
#pragma once

#include <CLI/CLI.hpp>

#include "command.h"

namespace buckle::cli {

/// Adds the `run` subcommand to `app` under `name` (main.cpp's table of subcommands); its status
/// is written to `outcome` when it runs.
void addRunCommand(CLI::App& app, Outcome& outcome, const char* name);

}  // namespace buckle::cli
