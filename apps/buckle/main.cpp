// buckle: command-line front end of the dual-triangle chain mechanics.
// Subcommands are registered here, each implemented in its own <name>_command.cpp.
#include <CLI/CLI.hpp>
#include <iostream>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "command.h"
#include "critical_command.h"
#include "atlas_command.h"
#include "regress_command.h"
#include "run_command.h"
#include "show_command.h"

int main(int argc, char** argv) {
#if defined(__GLIBC__)
  // Outside the tracer's preallocated hot loop, a tree allocates and frees large blocks again and
  // again (dense location systems, branch reports, the outputs' strings of megabytes). With glibc's adaptive defaults the freed heap top is
  // returned to the kernel (brk trims, TLB flushes) and faulted back in, blocks above 128 kB are
  // mapped and unmapped each time: ~10 % of a 50-segment tree's CPU went to page faults
  // (benchmarks/RESULTS.md, issue 13). Keep up to 64 MB of freed heap; map only blocks of 32 MB
  // and more.
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
  mallopt(M_TOP_PAD, 16 << 20);
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
#endif
  CLI::App app{"buckle: mechanics of compliant serial manipulators made of dual-triangle segments"};
  app.set_version_flag("--version", std::string("buckle ") + BUCKLE_VERSION);
  app.require_subcommand(1);
  buckle::cli::Outcome outcome;
  buckle::cli::addCriticalCommand(app, outcome);
  buckle::cli::addRunCommand(app, outcome);
  buckle::cli::addAtlasCommand(app, outcome);
  buckle::cli::addRegressCommand(app, outcome);
  buckle::cli::addShowCommand(app, outcome);
  // CLI11 would only say "A subcommand is required" for a mistyped one: name it
  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
      known = known || sub->get_name() == argv[1];
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::cerr << "error: unknown subcommand \"" << argv[1] << "\" (one of: " << names << "; see buckle --help)\n";
      return buckle::cli::kBadInput;
    }
  }
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
