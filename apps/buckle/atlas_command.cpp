#include "atlas_command.h"
#include "buckle/continuation/available_cores.h"

#include <algorithm>
#include <chrono>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <vector>

#include "atlas_mpi.h"
#include "buckle/continuation/interrupt.h"
#include "scene/atlas.h"
#include "scene/output.h"
#include "scene/output_target.h"
#include "scene/signals.h"

namespace buckle::cli {

namespace {

struct AtlasArgs {
  scene::AtlasOptions atlas;
  std::vector<double> xRange{0.05, 1.0, 20}, yRange{1.0, 3.0, 21};
  std::string out = "out/atlas";
  double timeLimit = std::numeric_limits<double>::infinity();
  bool quiet = false;
  bool force = false;
};

scene::AtlasAxis axis(const std::string& name, const std::vector<double>& r, const std::string& opt) {
  if (r.size() != 3 || !(r[2] >= 1.0) || r[2] != static_cast<double>(static_cast<int>(r[2])))
    throw BadArgument{opt + " takes FROM TO COUNT with an integer COUNT >= 1"};
  return scene::AtlasAxis{name, r[0], r[1], static_cast<int>(r[2])};
}

// The cells as one rank sends them to rank 0: '0' and the packed cells, or '1' and the message
// of an error that stopped the rank (rank 0 then writes nothing and names it).
std::string rankReport(const std::vector<scene::AtlasCell>& cells, const scene::AtlasShare& share,
                       const std::string& fatal) {
  return fatal.empty() ? "0" + scene::packAtlasCells(cells, share) : "1" + fatal;
}

void runAtlas(const AtlasArgs& args, Outcome& outcome) {
  std::optional<MpiWorld> world;  // MPI only when started by mpirun; one process otherwise
  try {
    world.emplace();
  } catch (const std::runtime_error& e) {
    throw BadArgument{e.what()};
  }
  // Every rank reads the arguments alike; rank 0 alone checks --out (it writes there), says what
  // is wrong and carries the exit status. The other ranks always leave with 0 once rank 0 knows
  // their part: mpirun ends the whole job as soon as one rank exits non-zero, which could cut
  // rank 0 short before its message or output.
  scene::AtlasOptions o = args.atlas;
  std::string target;  // args.out with symbolic links resolved: the directory that is replaced
  std::string bad;
  try {
    o.x = axis(args.atlas.x.name, args.xRange, "--x-range");
    o.y = axis(args.atlas.y.name, args.yRange, "--y-range");
    scene::validateAtlas(o);
    if (!(args.timeLimit > 0.0)) throw BadArgument{"--time-limit must be a number of seconds > 0"};
    if (world->root()) target = scene::checkOutputTarget(args.out, {}, args.force);
  } catch (const BadArgument& e) {
    bad = e.message;
  } catch (const std::invalid_argument& e) {
    bad = e.what();
  } catch (const scene::OutputTargetError& e) {
    bad = e.what();
  }
  if (world->broadcast(bad.empty() ? 0 : 1) != 0) {
    if (world->root()) throw BadArgument{bad};
    return;
  }
  // Threads per rank: the ranks on one machine share its cores.
  const int threads = o.threads > 0 ? o.threads
                                    : std::max(1, buckle::continuation::availableCores() / world->ranksOnThisNode());
  // No progress bar under mpirun: a rank sees only its share, and mpirun hands the ranks a
  // terminal even when its own output goes to a file.
  const bool tty = !world->distributed() && ::isatty(STDOUT_FILENO) == 1 && !args.quiet;
  const auto t0 = std::chrono::steady_clock::now();
  auto progress = [tty](int done, int total) {
    if (!tty) return;
    const int width = 40, filled = width * done / total;
    std::cout << "\r[" << std::string(size_t(filled), '#') << std::string(size_t(width - filled), ' ') << "] " << done
              << "/" << total << std::flush;
    if (done == total) std::cout << "\n";
  };
  scene::SignalGuard signals;
  continuation::Interrupt interrupt = continuation::Interrupt::after(args.timeLimit);
  interrupt.watch(scene::SignalGuard::flag(), "interrupted by a signal (SIGINT/SIGTERM)");
  std::vector<scene::AtlasCell> cells = scene::atlasGrid(o);
  const scene::AtlasShare share{world->rank(), world->size()};
  std::string fatal;
  try {
    const size_t computed = scene::computeCells(cells, share, threads, interrupt, progress);
    if (tty && computed < share.size(cells.size())) std::cout << "\n";  // end the stopped bar's line
  } catch (const std::exception& e) {
    fatal = e.what();
  }
  const int signalStatus = signals.signal() != 0 ? signals.exitCode() : kSuccess;
  if (world->distributed()) {
    std::vector<std::string> reports;
    try {
      reports = world->gather(rankReport(cells, share, fatal));
    } catch (const std::runtime_error& e) {
      fatal = e.what();  // every rank alike
    }
    if (!world->root()) return;  // rank 0 reports for every rank (see above)
    std::string failures;
    for (size_t r = 1; r < reports.size(); ++r) {
      if (reports[r].rfind("1", 0) == 0) {
        failures += "\n  rank " + std::to_string(r) + ": " + reports[r].substr(1);
        continue;
      }
      try {
        scene::unpackAtlasCells(reports[r].substr(1), cells);
      } catch (const std::runtime_error& e) {
        failures += "\n  rank " + std::to_string(r) + ": " + e.what();
      }
    }
    if (!fatal.empty()) failures = "\n  rank 0: " + fatal + failures;
    fatal = failures;
  }
  if (!fatal.empty()) {
    // distributed: one "\n  rank R: ..." line per rank that failed
    std::cerr << "buckle atlas: stopped by an error, nothing written:" << (world->distributed() ? "" : " ") << fatal
              << "\n";
    outcome.code = kComputationFailure;
    return;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  int failed = 0, notComputed = 0;
  std::string stopped;  // why some cells were not computed
  for (const auto& c : cells) {
    if (c.postBuckling == "failed") ++failed;
    if (c.postBuckling == "not computed") {
      ++notComputed;
      if (stopped.empty()) stopped = c.error;
    }
  }
  try {
    scene::StagingDirectory staging(target);
    std::string note;
    const std::vector<std::string> files = scene::writeAtlas(o, cells, staging.path(), note);
    nlohmann::json summary;
    summary["generator"] = scene::kAtlasGenerator;  // the marker that lets a later --out replace it
    summary["schema"] = scene::kOutputSchema;
    summary["x"] = {{"name", o.x.name}, {"from", o.x.from}, {"to", o.x.to}, {"count", o.x.count}};
    summary["y"] = {{"name", o.y.name}, {"from", o.y.from}, {"to", o.y.to}, {"count", o.y.count}};
    summary["fixed"] = {{"a", o.a}, {"L0", o.L0}, {"n", o.n}, {"b", 1.0}, {"k", 1.0}};
    summary["end"] = "clamped-pinned: y held at 0, end rotation free, Fx compression";
    summary["cells"] = cells.size();
    summary["failed_cells"] = failed;
    summary["not_computed_cells"] = notComputed;
    if (notComputed > 0) summary["stopped"] = stopped;
    summary["mpi_ranks"] = world->size();
    summary["threads"] = threads;  // per rank
    summary["seconds"] = seconds;
    summary["plots"] = {{"gnuplot", note}, {"files", files}};
    std::ofstream file(std::string(staging.path()) + "/summary.json");
    file << summary.dump(2) << "\n";
    file.close();
    if (!file) throw std::runtime_error("cannot write summary.json in " + staging.path());
    staging.commit();
  } catch (const std::exception& e) {
    std::cerr << "buckle atlas: cannot write the output: " << e.what() << "\n";
    outcome.code = kComputationFailure;
    return;
  }
  if (!args.quiet) {
    std::cout << cells.size() << " cells in " << seconds << " s";
    if (world->distributed()) std::cout << " on " << world->size() << " MPI ranks x " << threads << " threads";
    std::cout << "; wrote " << args.out << "/atlas.csv and plots\n";
  }
  if (failed > 0) {
    std::cerr << "buckle atlas: " << failed << " cell(s) could not be computed (post_buckling = failed in atlas.csv)\n";
    outcome.code = kComputationFailure;
  }
  if (notComputed > 0) {
    std::cerr << "buckle atlas: " << notComputed << " cell(s) not computed, " << stopped
              << " (post_buckling = not computed in atlas.csv)\n";
    outcome.code = kComputationFailure;
  }
  if (signalStatus != kSuccess) outcome.code = signalStatus;
}

}  // namespace

void addAtlasCommand(CLI::App& app, Outcome& outcome, const char* name) {
  auto args = std::make_shared<AtlasArgs>();
  CLI::App* cmd = app.add_subcommand(
      name, "Two-parameter map (a/b, L0/b, n) of straight-chain stability, first critical force, post-buckling");
  cmd->footer(
      "Clamped-pinned chain (y held, rotation free) of n identical symmetric segments, b = k = 1, under "
      "compression Fx. For every cell: stability of the straight chain, first critical force (linear "
      "buckling), and whether the branch born there is stable (supercritical) or not (subcritical), by "
      "continuation and branch switching. Writes DIR/atlas.csv, DIR/summary.json and heat maps "
      "DIR/plots/atlas_critical.png|svg, atlas_post_buckling.png|svg. Under mpirun every rank computes a share of "
      "the cells and rank 0 writes the same files. Exit status: 0, 1 some cell failed or not computed, 2 bad input.");
  cmd->add_option("--x", args->atlas.x.name, "Horizontal parameter: a, L0 or n")->capture_default_str();
  cmd->add_option("--x-range", args->xRange, "FROM TO COUNT of the horizontal parameter")->expected(3)->capture_default_str();
  cmd->add_option("--y", args->atlas.y.name, "Vertical parameter: a, L0 or n")->capture_default_str();
  cmd->add_option("--y-range", args->yRange, "FROM TO COUNT of the vertical parameter")->expected(3)->capture_default_str();
  cmd->add_option("--a", args->atlas.a, "a/b when it is not an axis")->capture_default_str();
  cmd->add_option("--L0", args->atlas.L0, "L0/b when it is not an axis")->capture_default_str();
  cmd->add_option("--segments,-n", args->atlas.n, "Segment count when n is not an axis")->capture_default_str();
  cmd->add_option("--threads,-j", args->atlas.threads,
                  "Worker threads (0: all cores; under mpirun, per rank: the cores shared among the ranks on a machine)")
      ->capture_default_str();
  cmd->add_option("--time-limit", args->timeLimit,
                  "Seconds; past them no new cell is started, the cells computed are written and the rest marked "
                  "\"not computed\" (exit 1). SIGINT/SIGTERM do the same")
      ->capture_default_str();
  cmd->add_option("--out,-o", args->out,
                  "Output directory, written beside it and renamed at the end. Refused (exit 2, before computing) "
                  "when it is /, the current directory or one containing it, an existing file, or an existing "
                  "non-empty directory that is not a previous buckle output")
      ->capture_default_str();
  cmd->add_flag("--force", args->force,
                "Let --out replace an existing file or a directory that is not a buckle output, with everything "
                "in it (never /, the current directory or one containing it)");
  cmd->add_flag("--quiet,-q", args->quiet, "No progress bar or messages");
  cmd->callback([args, &outcome]() { runAtlas(*args, outcome); });
}

}  // namespace buckle::cli
