#include "regress_command.h"

#include <iostream>
#include <memory>
#include <string>

#include "regress/command.h"

namespace buckle::cli {

void addRegressCommand(CLI::App& app, Outcome& outcome, const char* name) {
  auto options = std::make_shared<regress::RegressOptions>();
  CLI::App* cmd = app.add_subcommand(
      name, "Re-run the regression baselines (docs/regression.md) and report drift in values and time");
  cmd->footer(
      "Each baseline names a scene or a benchmark problem; it is re-run in memory (nothing is written) and its "
      "special points (type, load, shape), branch samples and median time are compared with the baseline.\n"
      "--update rewrites the baselines from a fresh run (review with `git diff data/regression`); it is never "
      "done implicitly.\n"
      "Exit status: 0 all within tolerance, 1 drift beyond tolerance (or time beyond the factor), 2 bad input "
      "(the message names the baseline file and the JSON path of the bad value).");
  cmd->add_option("--baselines", options->baselines, "Directory of baseline files <name>.json")
      ->capture_default_str();
  cmd->add_option("--scenes", options->scenes, "Directory of the scene files (default: <baselines>/../scenes)");
  cmd->add_option("--only", options->only, "Only these baselines (by name; repeatable)");
  cmd->add_option("--time-tolerance", options->timeTolerance,
                  "Time fails beyond this factor of the reference (plus 20 ms); 0: time is reported only")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--repetitions", options->repetitions, "Timed runs per baseline (default: the baseline's own)")
      ->check(CLI::Range(1, 100));
  cmd->add_flag("--ci", options->ci, "Skip the baselines marked \"ci\": false (heavy scenes)");
  cmd->add_option("--json", options->json, "Also write the table as JSON to this file");
  cmd->add_flag("--update", options->update,
                "Rewrite the baselines from a fresh run (every scene and benchmark problem, or --only those)");
  cmd->add_flag("--keep-timing", options->keepTiming, "With --update: keep the existing reference timings");
  cmd->callback([options, &outcome]() {
    const int code = regress::runRegressCommand(*options, std::cout, std::cerr);
    outcome.code = code == regress::kAllPass ? kSuccess : code == regress::kBadInput ? kBadInput : kComputationFailure;
  });
}

}  // namespace buckle::cli
