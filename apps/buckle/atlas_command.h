// `buckle atlas`: a two-parameter map of straight-chain stability, first critical force and
// post-buckling character, computed on all cores.
#pragma once

#include <CLI/CLI.hpp>

#include "command.h"

namespace buckle::cli {

/// Adds the `atlas` subcommand to `app` under `name` (main.cpp's table of subcommands); its status
/// is written to `outcome` when it runs.
void addAtlasCommand(CLI::App& app, Outcome& outcome, const char* name);

}  // namespace buckle::cli
