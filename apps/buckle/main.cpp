// buckle: command-line front end of the dual-triangle chain mechanics.
// Subcommands are registered here, each implemented in its own <name>_command.cpp.
#include <CLI/CLI.hpp>
#include <iostream>

#include "command.h"
#include "critical_command.h"
#include "atlas_command.h"
#include "regress_command.h"
#include "run_command.h"
#include "show_command.h"

int main(int argc, char** argv) {
  CLI::App app{"buckle: mechanics of compliant serial manipulators made of dual-triangle segments"};
  app.set_version_flag("--version", std::string("buckle ") + BUCKLE_VERSION);
  app.require_subcommand(1);
  buckle::cli::Outcome outcome;
  buckle::cli::addCriticalCommand(app, outcome);
  buckle::cli::addRunCommand(app, outcome);
  buckle::cli::addAtlasCommand(app, outcome);
  buckle::cli::addRegressCommand(app, outcome);
  buckle::cli::addShowCommand(app, outcome);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help / version (code 0) or the error message
    return code == 0 ? buckle::cli::kSuccess : buckle::cli::kBadInput;
  } catch (const buckle::cli::BadArgument& e) {
    std::cerr << "error: " << e.message << "\n";
    return buckle::cli::kBadInput;
  }
  return outcome.code;
}
