#include "run_command.h"
#include "buckle/continuation/available_cores.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <unistd.h>

#include "atlas_mpi.h"
#include "scene/command.h"

namespace buckle::cli {

namespace {

// scene::SharedWork::exchange over MPI: an all-gather of tagged bytes; a rank whose tag differs
// is at another exchange (or finished) and sent nothing for this one.
std::vector<std::string> taggedExchange(const MpiWorld& world, const std::string& tag, const std::string& mine) {
  const std::string head = tag + '\n';
  std::vector<std::string> parts = world.allgather(head + mine);
  for (std::string& p : parts) p = p.compare(0, head.size(), head) == 0 ? p.substr(head.size()) : std::string();
  return parts;
}

// Waits until every rank has finished its run; the exchanges of ranks still running meanwhile
// get nothing from this one (they compute its share themselves). Every rank leaves in the same
// round, so no collective call is left unmatched.
void finishShared(const MpiWorld& world) {
  const std::string done = "done\n";
  for (;;) {
    const std::vector<std::string> all = world.allgather(done);
    if (std::all_of(all.begin(), all.end(), [&](const std::string& s) { return s == done; })) return;
  }
}

}  // namespace

void addRunCommand(CLI::App& app, Outcome& outcome, const char* name) {
  auto options = std::make_shared<scene::RunCommandOptions>();
  CLI::App* run = app.add_subcommand(
      name, "Run a scene file (docs/scenes.md): branches, special points, stiffness, curves and plots");
  run->footer(
      "Computes only what the scene asks for and writes DIR/branches.csv, DIR/special_points.json, "
      "DIR/summary.json, DIR/plots/*.png|svg (gnuplot) and DIR/report.html (one self-contained page: diagram, "
      "special points, chain shapes; open it in a browser).\n"
      "Exit status: 0 success, 1 a computation could not finish or the time limit stopped it (what was computed "
      "is written), 2 bad input (the message names the file and the JSON path of the bad value; nothing is "
      "written), 130 / 143 stopped by SIGINT / SIGTERM (what was computed is written; a second signal ends the "
      "program, once the output directory is complete or removed).\n"
      "Progress goes to stderr: a live line on a terminal, a plain line every few seconds otherwise; --quiet "
      "silences it.\n"
      "Under mpirun (`mpirun -np N buckle-mpi run SCENE`): rank 0 runs the scene and writes it; the rows of a "
      "workspace map are shared among the ranks (the same output as one process, byte for byte but the timings).");
  run->add_option("scene", options->scene, "Scene file (JSON, schema: docs/scenes.md), e.g. data/scenes/default.json")
      ->required();
  run->add_option("--out,-o", options->out,
                  "Output directory (default: out/<scene name>). Written to a temporary directory beside it and "
                  "renamed at the end, so it is never half-written. Refused (exit 2, before computing) when it is "
                  "/, the current directory or one containing it, the scene file, an existing file, or an existing "
                  "non-empty directory that is not a previous buckle output");
  run->add_flag("--force", options->force,
                "Let --out replace an existing file or a directory that is not a buckle output, with everything "
                "in it (never /, the current directory or one containing it, or the scene file)");
  run->add_flag("--quiet,-q", options->quiet, "No progress messages (errors are still printed)");
  run->add_option("--time-limit", options->timeLimit,
                  "Seconds for the whole run (overrides the scene's /solver/time_limit); when it is reached the "
                  "run stops within a step, writes what it computed (summary.json: \"complete\": false) and exits 1")
      // NaN is the options' "not given": refuse it here, the rest is checked in runSceneCommand
      ->check(CLI::Validator(
          [](std::string& s) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(s.c_str(), &end);
            return end != s.c_str() && std::isnan(v) ? "must be a positive number of seconds, got " + s : "";
          },
          "SECONDS"));
  run->callback([options, run, &outcome]() {
    // an empty --out is a mistake, not the default directory
    if (run->count("--out") > 0 && options->out.empty())
      throw BadArgument{"--out is empty: give the output directory (or leave --out out for out/<scene>)"};
    std::optional<MpiWorld> world;  // MPI only when started by mpirun (buckle-mpi); one process otherwise
    try {
      world.emplace();
    } catch (const std::runtime_error& e) {
      throw BadArgument{e.what()};
    }
    scene::RunCommandOptions o = *options;
    o.handleSignals = true;
    // no live line under mpirun: it hands the ranks a terminal even when its own output is a file
    o.progress = ::isatty(STDERR_FILENO) == 1 && !world->distributed() ? scene::Progress::Mode::Live
                                                                        : scene::Progress::Mode::Lines;
    if (world->distributed() && world->size() > 1) {
      o.shared.part = world->rank();
      o.shared.parts = world->size();
      o.shared.threads = std::max(1, buckle::continuation::availableCores() / world->ranksOnThisNode());
      o.shared.exchange = [&w = *world](const std::string& tag, const std::string& mine) {
        return taggedExchange(w, tag, mine);
      };
      o.quiet = o.quiet || !world->root();
    }
    int code = scene::runSceneCommand(o, std::cout, std::cerr);
    if (o.shared.shared()) {
      finishShared(*world);
      // rank 0 carries the exit status: mpirun ends the job when any rank exits non-zero
      if (!world->root()) code = scene::kSuccess;
    }
    // 128 + signal after SIGINT/SIGTERM (partial results written), as a shell reports it
    outcome.code = code == scene::kSuccess    ? kSuccess
                   : code == scene::kBadInput ? kBadInput
                   : code > 128               ? code
                                              : kComputationFailure;
  });
}

}  // namespace buckle::cli
