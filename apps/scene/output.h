// Writing a run's results: branches.csv, special_points.json, summary.json and the plots, into
// a temporary directory next to the target that is renamed into place at the end, so a reader
// never sees a half-written output directory.
#pragma once

#include <csignal>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/branch_rows.h"
#include "scene/column_values.h"
#include "scene/columns.h"
#include "scene/runner.h"
#include "scene/scene.h"

namespace buckle::scene {

/// A directory created next to `target` (same parent, hidden name), renamed onto `target` by
/// commit(); removed by the destructor unless committed. While it exists SIGINT, SIGTERM and
/// SIGHUP are held back (blocked in the calling thread, then delivered when it is gone): a signal that
/// would end the program (a second Ctrl-C, signals.h) then ends it after the output is complete
/// or removed, never with a half-written temporary directory left behind.
class StagingDirectory {
 public:
  explicit StagingDirectory(const std::string& target);
  ~StagingDirectory();
  StagingDirectory(const StagingDirectory&) = delete;
  StagingDirectory& operator=(const StagingDirectory&) = delete;
  const std::string& path() const { return path_; }
  /// Replaces `target` (if it exists) by the staged directory.
  void commit();

 private:
  std::string target_, path_;
  bool committed_ = false;
  sigset_t previousMask_;
};

struct PlotReport {
  bool gnuplotFound = false;
  std::string gnuplot;                 ///< program used, or why none
  std::vector<std::string> files;      ///< written image files, relative to the output dir
  /// Every file in plots/ (images, scripts, data, logs), relative to the output dir: summary.json
  /// `plots.written`, which tells a later run what it may replace (output_target.h).
  std::vector<std::string> written;
  std::vector<std::string> failures;   ///< plots gnuplot failed to draw
  /// Non-empty when drawing stopped early (the time limit of the run, a signal): why; the plots
  /// not drawn are in `notDrawn` (only the one being drawn then has its data and script).
  std::string stopped;
  std::vector<std::string> notDrawn;
  /// What a plot could not show as asked (a shape requested where no stable point was traced):
  /// summary.json `notes`, and printed by `buckle run`.
  std::vector<std::string> notes;
};

/// The document written as special_points.json (docs/outputs.md): special points, critical loads
/// and the other per-analysis results the scene asked for.
nlohmann::json specialPointsJson(const Scene& scene, const RunResult& run);
/// The document written as summary.json (docs/outputs.md), with `plots` describing what was drawn.
nlohmann::json summaryJson(const Scene& scene, const RunResult& run, const PlotReport& plots);

/// critical_curves.csv of the two_parameter analysis (two_parameter.cpp, docs/outputs.md).
void writeCriticalCurvesCsv(const RunResult& run, const std::string& dir);
/// Every case's critical curves with their codimension-two points, for special_points.json.
nlohmann::json criticalCurvesJson(const RunResult& run);
/// The gnuplot body of a critical_curves plot: λ against μ, supercritical parts solid,
/// subcritical dashed, fold curves dotted, codimension-two points marked; data files in `dir`.
void criticalCurvesPlotBody(const Scene& scene, const RunResult& run, const PlotSpec& spec, const std::string& dir,
                            std::ostream& body);
/// Writes every output file of the run into `dir` (which exists), report.html included;
/// returns the plot report.
/// `stop` ends the drawing of plots early (the run's time limit, a signal; output.h PlotReport).
PlotReport writeOutputs(const Scene& scene, const RunResult& run, const std::string& dir,
                        const continuation::Interrupt& stop = continuation::Interrupt());

/// Draws the scene's plots with gnuplot into dir/plots (scripts and data files kept beside the
/// images so a plot can be re-rendered by hand). Without gnuplot only the data and scripts are
/// written and the report says so. gnuplot runs without a shell (child_process.h); once `stop`
/// is requested or a stop signal is held back (signals.h) the plot being drawn is ended and the
/// rest are not drawn (PlotReport::stopped).
PlotReport drawPlots(const Scene& scene, const RunResult& run, const std::string& dir,
                     const continuation::Interrupt& stop = continuation::Interrupt());

/// The gnuplot executable: $BUCKLE_GNUPLOT if set (empty: none), else `gnuplot` on PATH.
/// Returns an empty string when there is none.
std::string findGnuplot();

}  // namespace buckle::scene
