// What the plot files share (plot.cpp: the driver; plot_branches.cpp, plot_curves.cpp,
// plot_shapes.cpp: the plot types): colours, number formats, gnuplot data blocks and scripts, and
// the placement of labels on a frame whose pixel geometry is fixed before gnuplot draws it.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <tuple>
#include <unistd.h>
#include <vector>

#include "buckle/mechanics/contact_geometry.h"

#include "scene/child_process.h"
#include "scene/escape.h"
#include "scene/label_layout.h"
#include "scene/output.h"
#include "scene/plot_range.h"
#include "scene/signals.h"

namespace buckle::scene::plot_detail {

namespace fs = std::filesystem;


inline const char* const kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e",
                               "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
inline std::string color(size_t i) { return kColors[i % (sizeof kColors / sizeof kColors[0])]; }

inline std::string num(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

/// Four significant digits, for titles.
inline std::string short4(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

/// Five significant digits, for titles.
inline std::string short5(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.5g", v);
  return buf;
}

/// gnuplot string literal of any text, a scene's included (escape.h).
inline std::string quote(const std::string& s) { return escape::gnuplotString(s); }

/// Data file with numbered blocks (gnuplot `index`), each made of polylines separated by one
/// blank line.
class BlockFile {
 public:
  int begin() {
    if (blocks_ > 0) os_ << "\n\n";
    // a block that stays empty would merge with the next one and shift every later `index`:
    // each block starts with an undefined point
    os_ << "# block " << blocks_ << "\nNaN NaN\n\n";
    lineOpen_ = false;
    return blocks_++;
  }
  void point(std::initializer_list<double> values) {
    bool first = true;
    for (double v : values) {
      os_ << (first ? "" : " ") << num(v);
      first = false;
    }
    os_ << "\n";
    lineOpen_ = true;
  }
  void text(const std::string& line) { os_ << line << "\n"; }
  void breakLine() {
    if (lineOpen_) os_ << "\n";
    lineOpen_ = false;
  }
  void write(const fs::path& file) const { std::ofstream(file) << os_.str() << "\n"; }
  int blocks() const { return blocks_; }

 private:
  std::ostringstream os_;
  int blocks_ = 0;
  bool lineOpen_ = false;
};

inline std::vector<size_t> selected(const PlotSpec& spec) {
  std::vector<size_t> out;
  for (int c : spec.cases) out.push_back(static_cast<size_t>(c));
  return out;
}

struct Script {
  std::string name;
  int width = 1000, height = 700;
  std::ostringstream body;
};

inline std::string parameterColumnLabel(const Scene& scene, const std::string& column) {
  if (column == "parameter") return columnLabel(scene.cases.front().path.parameter, scene.units);
  return columnLabel(column, scene.units);
}

inline void header(Script& s, const std::string& title) {
  s.body << "set encoding utf8\nset grid lc rgb '#dddddd'\nset key outside right top box opaque samplen 3 font ',9'\n";
  if (!title.empty()) s.body << "set title " << quote(title) << " noenhanced\n";
}

// ---- the plot types -----------------------------------------------------------------------------

void branchPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
void torquePlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
void energyPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
void suddenPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
/// `equilibrium_shapes` (plot_shapes.cpp): every equilibrium of the `equilibria` analysis, one
/// panel each in ascending potential, stable ones marked.
void equilibriumShapesPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
/// `workspace` and `input_map` (plot_workspace.cpp): the workspace analysis's two plots.
void workspacePlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
void inputMapPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
void shapesPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, size_t plotIndex, const fs::path& dir,
                Script& s, std::vector<std::string>& notes);

}  // namespace buckle::scene::plot_detail
