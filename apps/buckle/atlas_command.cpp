#include "atlas_command.h"

#include <chrono>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

#include "scene/atlas.h"
#include "scene/output.h"
#include "scene/output_target.h"

namespace buckle::cli {

namespace {

struct AtlasArgs {
  scene::AtlasOptions atlas;
  std::vector<double> xRange{0.05, 1.0, 20}, yRange{1.0, 3.0, 21};
  std::string out = "out/atlas";
  bool quiet = false;
  bool force = false;
};

scene::AtlasAxis axis(const std::string& name, const std::vector<double>& r, const std::string& opt) {
  if (r.size() != 3 || !(r[2] >= 1.0) || r[2] != static_cast<double>(static_cast<int>(r[2])))
    throw BadArgument{opt + " takes FROM TO COUNT with an integer COUNT >= 1"};
  return scene::AtlasAxis{name, r[0], r[1], static_cast<int>(r[2])};
}

void runAtlas(const AtlasArgs& args, Outcome& outcome) {
  scene::AtlasOptions o = args.atlas;
  o.x = axis(args.atlas.x.name, args.xRange, "--x-range");
  o.y = axis(args.atlas.y.name, args.yRange, "--y-range");
  try {
    scene::validateAtlas(o);
  } catch (const std::invalid_argument& e) {
    throw BadArgument{e.what()};
  }
  std::string target;  // args.out with symbolic links resolved: the directory that is replaced
  try {
    target = scene::checkOutputTarget(args.out, {}, args.force);
  } catch (const scene::OutputTargetError& e) {
    throw BadArgument{e.what()};
  }
  const bool tty = ::isatty(STDOUT_FILENO) == 1 && !args.quiet;
  const auto t0 = std::chrono::steady_clock::now();
  auto progress = [tty](int done, int total) {
    if (!tty) return;
    const int width = 40, filled = width * done / total;
    std::cout << "\r[" << std::string(size_t(filled), '#') << std::string(size_t(width - filled), ' ') << "] " << done
              << "/" << total << std::flush;
    if (done == total) std::cout << "\n";
  };
  const std::vector<scene::AtlasCell> cells = scene::computeAtlas(o, progress);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  int failed = 0;
  for (const auto& c : cells)
    if (c.postBuckling == "failed") ++failed;
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
    summary["threads"] = o.threads > 0 ? unsigned(o.threads) : std::max(1u, std::thread::hardware_concurrency());
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
  if (!args.quiet)
    std::cout << cells.size() << " cells in " << seconds << " s; wrote " << args.out << "/atlas.csv and plots\n";
  if (failed > 0) {
    std::cerr << "buckle atlas: " << failed << " cell(s) could not be computed (post_buckling = failed in atlas.csv)\n";
    outcome.code = kComputationFailure;
  }
}

}  // namespace

void addAtlasCommand(CLI::App& app, Outcome& outcome) {
  auto args = std::make_shared<AtlasArgs>();
  CLI::App* cmd = app.add_subcommand(
      "atlas", "Two-parameter map (a/b, L0/b, n) of straight-chain stability, first critical force, post-buckling");
  cmd->footer(
      "Clamped-pinned chain (y held, rotation free) of n identical symmetric segments, b = k = 1, under "
      "compression Fx. For every cell: stability of the straight chain, first critical force (linear "
      "buckling), and whether the branch born there is stable (supercritical) or not (subcritical), by "
      "continuation and branch switching. Writes DIR/atlas.csv, DIR/summary.json and heat maps "
      "DIR/plots/atlas_critical.png|svg, atlas_post_buckling.png|svg. Exit status: 0, 1 some cell failed, 2 bad input.");
  cmd->add_option("--x", args->atlas.x.name, "Horizontal parameter: a, L0 or n")->capture_default_str();
  cmd->add_option("--x-range", args->xRange, "FROM TO COUNT of the horizontal parameter")->expected(3)->capture_default_str();
  cmd->add_option("--y", args->atlas.y.name, "Vertical parameter: a, L0 or n")->capture_default_str();
  cmd->add_option("--y-range", args->yRange, "FROM TO COUNT of the vertical parameter")->expected(3)->capture_default_str();
  cmd->add_option("--a", args->atlas.a, "a/b when it is not an axis")->capture_default_str();
  cmd->add_option("--L0", args->atlas.L0, "L0/b when it is not an axis")->capture_default_str();
  cmd->add_option("--segments,-n", args->atlas.n, "Segment count when n is not an axis")->capture_default_str();
  cmd->add_option("--threads,-j", args->atlas.threads, "Worker threads (0: all cores)")->capture_default_str();
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
