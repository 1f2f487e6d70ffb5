#include "scene/command.h"

#include <filesystem>
#include <iomanip>

#include "scene/output.h"
#include "scene/runner.h"
#include "scene/scene.h"

namespace buckle::scene {

std::string defaultOutputDirectory(const std::string& scene) {
  return (std::filesystem::path("out") / std::filesystem::path(scene).stem()).string();
}

int runSceneCommand(const RunCommandOptions& options, std::ostream& log, std::ostream& err) {
  Scene scene;
  try {
    scene = loadScene(options.scene);
  } catch (const SceneError& e) {
    err << "buckle run: bad scene: " << e.what() << "\n";
    return kBadInput;
  }
  const std::string out = options.out.empty() ? defaultOutputDirectory(options.scene) : options.out;
  if (!options.quiet) {
    log << "scene " << options.scene << ": " << scene.cases.size() << " case(s)";
    if (!scene.description.empty()) log << " — " << scene.description.substr(0, 100) << (scene.description.size() > 100 ? "…" : "");
    log << "\n";
  }
  const RunResult run = runScene(scene);
  try {
    StagingDirectory staging(out);
    const PlotReport plots = writeOutputs(scene, run, staging.path());
    staging.commit();
    for (const std::string& n : plots.notes) err << "buckle run: note: " << n << "\n";
    if (!options.quiet) {
      size_t points = 0, specials = 0;
      for (const CaseResult& c : run.cases) {
        points += c.points.size();
        specials += c.specials.size();
      }
      log << "computed: ";
      for (size_t i = 0; i < run.computed.size(); ++i) log << (i ? "; " : "") << run.computed[i];
      log << "\n" << points << " branch points, " << specials << " special points in " << std::fixed
          << std::setprecision(2) << run.totalSeconds << " s\n";
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
    for (const std::string& p : run.problems) err << "  " << p << "\n";
    return kIncomplete;
  }
  return kSuccess;
}

}  // namespace buckle::scene
