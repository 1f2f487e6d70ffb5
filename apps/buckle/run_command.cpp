#include "run_command.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>
#include <unistd.h>

#include "scene/command.h"

namespace buckle::cli {

void addRunCommand(CLI::App& app, Outcome& outcome) {
  auto options = std::make_shared<scene::RunCommandOptions>();
  CLI::App* run = app.add_subcommand(
      "run", "Run a scene file (docs/scenes.md): branches, special points, stiffness, curves and plots");
  run->footer(
      "Computes only what the scene asks for and writes DIR/branches.csv, DIR/special_points.json, "
      "DIR/summary.json, DIR/plots/*.png|svg (gnuplot) and DIR/report.html (one self-contained page: diagram, "
      "special points, chain shapes; open it in a browser).\n"
      "Exit status: 0 success, 1 a computation could not finish or the time limit stopped it (what was computed "
      "is written), 2 bad input (the message names the file and the JSON path of the bad value; nothing is "
      "written), 130 / 143 stopped by SIGINT / SIGTERM (what was computed is written; a second signal ends the "
      "program, once the output directory is complete or removed).\n"
      "Progress goes to stderr: a live line on a terminal, a plain line every few seconds otherwise; --quiet "
      "silences it.");
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
    options->handleSignals = true;
    options->progress = ::isatty(STDERR_FILENO) == 1 ? scene::Progress::Mode::Live : scene::Progress::Mode::Lines;
    const int code = scene::runSceneCommand(*options, std::cout, std::cerr);
    // 128 + signal after SIGINT/SIGTERM (partial results written), as a shell reports it
    outcome.code = code == scene::kSuccess    ? kSuccess
                   : code == scene::kBadInput ? kBadInput
                   : code > 128               ? code
                                              : kComputationFailure;
  });
}

}  // namespace buckle::cli
