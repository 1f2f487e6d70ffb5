// `buckle critical`: stability of the straight chain and its critical end forces.
#pragma once

#include <CLI/CLI.hpp>

#include "command.h"

namespace buckle::cli {

/// Adds the `critical` subcommand to `app` under `name` (main.cpp's table of subcommands); its status
/// is written to `outcome` when it runs.
void addCriticalCommand(CLI::App& app, Outcome& outcome, const char* name);

}  // namespace buckle::cli
