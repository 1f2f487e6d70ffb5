#include "scene/command.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <optional>
#include <sstream>

#include "scene/output.h"
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
    points += c.points.size();
    branches += c.branches.size();
    specials += c.specials.size();
    for (const SpecialRecord& s : c.specials) {
      auto it = std::find_if(byType.begin(), byType.end(), [&](const auto& t) { return t.first == s.type; });
      if (it == byType.end())
        byType.emplace_back(s.type, 1);
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

}  // namespace

int runSceneCommand(const RunCommandOptions& options, std::ostream& log, std::ostream& err) {
  const auto started = std::chrono::steady_clock::now();
  Scene scene;
  try {
    scene = loadScene(options.scene);
  } catch (const SceneError& e) {
    err << "buckle run: bad scene: " << e.what() << "\n";
    return kBadInput;
  }
  if (!std::isnan(options.timeLimit) && !(options.timeLimit > 0.0)) {
    err << "buckle run: --time-limit must be a positive number of seconds\n";
    return kBadInput;
  }
  const std::string out = options.out.empty() ? defaultOutputDirectory(options.scene) : options.out;
  if (!options.quiet) {
    log << "scene " << options.scene << ": " << scene.cases.size() << " case(s)";
    if (!scene.description.empty()) log << " — " << scene.description.substr(0, 100) << (scene.description.size() > 100 ? "…" : "");
    log << "\n" << std::flush;
  }
  std::optional<SignalGuard> signals;
  if (options.handleSignals) signals.emplace();
  Progress progress(err, options.quiet ? Progress::Mode::Off : options.progress);
  RunControl control;
  control.progress = &progress;
  if (!std::isnan(options.timeLimit)) {
    scene.solver.timeLimit = options.timeLimit;  // recorded as such in summary.json
  }
  if (signals) control.interrupt.watch(SignalGuard::flag(), "interrupted by a signal (SIGINT/SIGTERM)");
  RunResult run = runScene(scene, control);
  progress.finish();
  try {
    StagingDirectory staging(out);
    const PlotReport plots = writeOutputs(scene, run, staging.path());
    staging.commit();
    if (!options.quiet) {
      log << "computed: ";
      for (size_t i = 0; i < run.computed.size(); ++i) log << (i ? "; " : "") << run.computed[i];
      const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      log << "\n" << countsLine(run) << " in " << std::fixed << std::setprecision(2) << total << " s"
          << (run.interrupted ? " (stopped early: " + run.interruption + ")" : "") << "\n";
      log.unsetf(std::ios::floatfield);
      if (!plots.gnuplotFound) log << "plots: " << plots.gnuplot << "\n";
      for (const std::string& f : plots.failures) log << "plot failed: " << f << "\n";
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
  if (signals && SignalGuard::signal() != 0) return SignalGuard::exitCode();
  return run.complete ? kSuccess : kIncomplete;
}

}  // namespace buckle::scene
