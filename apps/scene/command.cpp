#include "scene/command.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <optional>
#include <sstream>

#include "scene/escape.h"
#include "scene/output.h"
#include "scene/output_numbers.h"
#include "scene/output_target.h"
#include "scene/runner.h"
#include "scene/scene.h"
#include "scene/signals.h"

namespace buckle::scene {

std::string defaultOutputDirectory(const std::string& scene) {
  return (std::filesystem::path("out") / std::filesystem::path(scene).stem()).string();
}

std::vector<std::string> summariseProblems(const std::vector<std::string>& problems, size_t keep) {
  std::vector<std::string> lines(problems.begin(), problems.begin() + std::min(keep, problems.size()));
  // The same failure at 999 branch points differs only in its numbers: one line per shape.
  std::vector<std::pair<std::string, std::pair<size_t, std::string>>> groups;
  for (size_t i = lines.size(); i < problems.size(); ++i) {
    std::string shape;
    for (char ch : problems[i])
      if (!std::isdigit(static_cast<unsigned char>(ch))) shape += ch;
    auto it = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == shape; });
    if (it == groups.end())
      groups.push_back({shape, {1, problems[i]}});
    else
      ++it->second.first;
  }
  for (const auto& g : groups)
    lines.push_back(g.second.first == 1 ? g.second.second
                                        : std::to_string(g.second.first) + " more like: " + g.second.second);
  return lines;
}

namespace {

/// "341 points on 5 branches; 6 special points (2 BP, 2 LP, 2 BD)".
std::string countsLine(const RunResult& run) {
  size_t points = 0, branches = 0, specials = 0;
  std::vector<std::pair<std::string, int>> byType;
  for (const CaseResult& c : run.cases) {
    points += c.pointCount();
    branches += c.branches.size();
    specials += c.specials.size();
    for (const SpecialPointResult& s : c.specials) {
      const std::string type = mechanics::label(s.type);
      auto it = std::find_if(byType.begin(), byType.end(), [&](const auto& t) { return t.first == type; });
      if (it == byType.end())
        byType.emplace_back(type, 1);
      else
        ++it->second;
    }
  }
  std::ostringstream os;
  os << points << " point" << (points == 1 ? "" : "s") << " on " << branches << " branch" << (branches == 1 ? "" : "es")
     << "; " << specials << " special point" << (specials == 1 ? "" : "s");
  if (!byType.empty()) {
    os << " (";
    for (size_t i = 0; i < byType.size(); ++i) os << (i ? ", " : "") << byType[i].second << " " << byType[i].first;
    os << ")";
  }
  return os.str();
}

/// When drawing the plots must stop: at the run's time limit, counted from `started`, less a
/// tenth of it (at most 0.5 s) for summary.json and report.html written after the plots; on a
/// signal (with the CLI's handlers).
continuation::Interrupt writingStop(double timeLimit, std::chrono::steady_clock::time_point started, bool signals) {
  continuation::Interrupt stop;
  if (timeLimit < 1e9) {
    const double seconds = timeLimit - std::min(0.1 * timeLimit, 0.5);
    stop.setDeadline(started + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                   std::chrono::duration<double>(seconds)),
                     timeLimit);
  }
  if (signals) stop.watch(SignalGuard::flag(), "interrupted by a signal (SIGINT/SIGTERM/SIGHUP)");
  return stop;
}

/// Where the rows of branches.csv are spooled while the tree is traced: the target's parent
/// directory (created), on the output's file system, like the staging directory.
std::string spoolDirectory(const std::string& target) {
  std::filesystem::path t = std::filesystem::absolute(std::filesystem::path(target)).lexically_normal();
  if (t.filename().empty()) t = t.parent_path();
  std::filesystem::create_directories(t.parent_path());
  return t.parent_path().string();
}

// The steering of a run from the command's options: the processes sharing it, the command
// line's time limit (recorded in the scene, so summary.json says it), the signals.
RunControl commandControl(const RunCommandOptions& options, Scene& scene, bool signals) {
  RunControl control;
  control.shared = options.shared;
  if (!std::isnan(options.timeLimit)) scene.solver.timeLimit = options.timeLimit;
  if (signals) control.interrupt.watch(SignalGuard::flag(), "interrupted by a signal (SIGINT/SIGTERM/SIGHUP)");
  return control;
}

// A process of a shared run that does not write (RunCommandOptions::shared): its share of the
// scene's shared work, nothing written, nothing said.
int runSceneShare(const RunCommandOptions& options, Scene& scene) {
  std::optional<SignalGuard> signals;
  if (options.handleSignals) signals.emplace();
  const RunResult run = runScene(scene, commandControl(options, scene, signals.has_value()));
  if (signals && SignalGuard::signal() != 0) return SignalGuard::exitCode();
  return run.complete ? kSuccess : kIncomplete;
}

}  // namespace

int runSceneCommand(const RunCommandOptions& options, std::ostream& log, std::ostream& err) {
  const auto started = std::chrono::steady_clock::now();
  const bool writer = options.shared.writer();
  Scene scene;
  try {
    scene = loadScene(options.scene);
  } catch (const SceneError& e) {
    if (writer) err << "buckle run: bad scene: " << e.what() << "\n";
    return kBadInput;
  }
  if (!writer) {  // the writer checks the rest and says whether the run goes on
    const std::vector<std::string> verdict = options.shared.exchange("start", "");
    return verdict.empty() || verdict[0] != "go" ? kBadInput : runSceneShare(options, scene);
  }
  if (!std::isnan(options.timeLimit) && !(options.timeLimit > 0.0)) {
    err << "buckle run: --time-limit must be a positive number of seconds\n";
    return kBadInput;
  }
  const std::string out = options.out.empty() ? defaultOutputDirectory(options.scene) : options.out;
  std::string target;  // `out` with symbolic links resolved: the directory that is replaced
  try {
    target = checkOutputTarget(out, {options.scene}, options.force);
  } catch (const OutputTargetError& e) {
    err << "buckle run: " << e.what() << "\n";
    return kBadInput;
  }
  if (options.shared.shared()) options.shared.exchange("start", "go");
  std::optional<SignalGuard> signals;
  if (options.handleSignals) signals.emplace();
  // printed once the signal handlers are in place: from here on a signal stops the run cleanly
  if (!options.quiet) {
    const std::string description = escape::commentText(scene.description);  // one line, no control characters
    log << "scene " << options.scene << ": " << scene.cases.size() << " case(s)";
    size_t cut = std::min<size_t>(100, description.size());
    while (cut < description.size() && (static_cast<unsigned char>(description[cut]) & 0xC0) == 0x80) --cut;  // whole characters
    if (!description.empty()) log << " — " << description.substr(0, cut) << (cut < description.size() ? "…" : "");
    log << "\n" << std::flush;
  }
  Progress progress(err, options.quiet ? Progress::Mode::Off : options.progress);
  RunControl control = commandControl(options, scene, signals.has_value());
  control.progress = &progress;
  // branches.csv's rows are written beside the target while the tree is traced (branch_stream.h)
  RunResult run;
  try {
    control.streamTo = spoolDirectory(target);
    run = runScene(scene, control);
  } catch (const std::exception& e) {  // the spool files could not be written
    err << "buckle run: cannot write the output: " << e.what() << "\n";
    return kIncomplete;
  }
  progress.finish();
  if (run.interrupted && signals && SignalGuard::signal() != 0) run.interruption = SignalGuard::description();
  PlotReport plots;
  try {
    StagingDirectory staging(target);
    plots = writeOutputs(scene, run, staging.path(), writingStop(scene.solver.timeLimit, started, signals.has_value()));
    staging.commit();
    for (const std::string& n : plots.notes) err << "buckle run: note: " << n << "\n";
    if (!options.quiet) {
      log << "computed: ";
      for (size_t i = 0; i < run.computed.size(); ++i) log << (i ? "; " : "") << run.computed[i];
      const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      // the computation's time is summary.json's timings_seconds.total, the one report.html shows
      log << "\n" << countsLine(run) << "; computed in " << secondsText(run.totalSeconds) << " s ("
          << secondsText(total) << " s with the outputs written)"
          << (run.interrupted ? " (stopped early: " + run.interruption + ")" : "") << "\n";
      if (!plots.gnuplotFound) log << "plots: " << plots.gnuplot << "\n";
      for (const std::string& f : plots.failures) log << "plot failed: " << f << "\n";
      if (!plots.stopped.empty())
        log << "plots not drawn (" << plots.stopped << "): " << plots.notDrawn.size() << " of " << scene.plots.size()
            << "\n";
      log << "wrote " << out << "\n";
    }
  } catch (const std::exception& e) {
    err << "buckle run: cannot write the output: " << e.what() << "\n";
    return kIncomplete;
  }
  if (!run.complete) {
    err << "buckle run: the computation did not finish (partial results written to " << out << "):\n";
    for (const std::string& p : summariseProblems(run.problems)) err << "  " << p << "\n";
  }
  if (run.complete && !plots.stopped.empty())
    err << "buckle run: " << plots.stopped << " while drawing the plots: " << plots.notDrawn.size()
        << " not drawn (written to " << out << ")\n";
  if (signals && SignalGuard::signal() != 0) return SignalGuard::exitCode();
  return run.complete && plots.stopped.empty() ? kSuccess : kIncomplete;
}

}  // namespace buckle::scene
