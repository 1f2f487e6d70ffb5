// gnuplot plots of a run: one data file + one script per plot, rendered to PNG (pngcairo) and
// SVG. Scripts and data stay in <out>/plots so that a figure can be restyled by hand. The plot
// types are drawn in plot_branches.cpp, plot_curves.cpp and plot_shapes.cpp.
#include "scene/plot_internal.h"

namespace buckle::scene {

void plot_detail::Frame::script(std::ostream& os) const {
  os << "set lmargin at screen " << num(left) << "\nset rmargin at screen " << num(right) << "\nset bmargin at screen "
     << num(bottom) << "\nset tmargin at screen " << num(top) << "\nset xrange [" << num(xlo) << ":" << num(xhi)
     << "]\n";
  if (symlog > 0.0) {
    // gnuplot's nonlinear axis: the same asinh mapping as pixel(), so labels placed here stay
    // on their points; tics at 0 and ±10^k from the linear threshold out
    os << "set nonlinear y via asinh(y/" << num(symlog) << ") inverse " << num(symlog) << "*sinh(y)\nset yrange ["
       << num(inverseY(ylo)) << ":" << num(inverseY(yhi)) << "]\nset ytics (";
    const int k0 = int(std::lround(std::log10(symlog)));
    const int k1 = int(std::ceil(std::log10(std::max(std::abs(inverseY(ylo)), std::abs(inverseY(yhi))))));
    const int step = std::max(1, (k1 - k0 + 5) / 6);  // at most about six decades labelled per sign
    os << "\"0\" 0";
    for (int k = k0; k <= k1; k += step)
      for (int sign : {-1, 1}) {
        const double t = sign * std::pow(10.0, k);
        if (!(t >= inverseY(ylo) && t <= inverseY(yhi))) continue;
        // 0.01 … 1000 as numbers, other decades as powers of ten
        const std::string decade = std::abs(k) <= 3 ? num(std::pow(10.0, k)) : "10^{" + std::to_string(k) + "}";
        os << ", \"" << (sign < 0 ? "-" : "") << decade << "\" " << num(t);
      }
    os << ")\n";
  } else if (logY) {
    os << "set logscale y\nset format y '10^{%L}'\nset yrange [" << num(std::pow(10.0, ylo)) << ":"
       << num(std::pow(10.0, yhi)) << "]\n";
  } else {
    os << "set yrange [" << num(ylo) << ":" << num(yhi) << "]\n";
  }
}

using namespace plot_detail;

namespace {

bool executable(const std::string& path) { return ::access(path.c_str(), X_OK) == 0; }

}  // namespace

std::string findGnuplot() {
  if (const char* env = std::getenv("BUCKLE_GNUPLOT")) {
    const std::string p(env);
    return (!p.empty() && executable(p)) ? p : std::string();
  }
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "/usr/bin:/bin");
  std::string d;
  while (std::getline(ss, d, ':')) {
    if (d.empty()) continue;
    const std::string candidate = d + "/gnuplot";
    if (executable(candidate)) return candidate;
  }
  return std::string();
}

PlotReport drawPlots(const Scene& scene, const RunResult& run, const std::string& outDir,
                     const continuation::Interrupt& stop) {
  PlotReport report;
  if (scene.plots.empty()) {
    report.gnuplot = "no plots requested";
    return report;
  }
  const fs::path dir = fs::path(outDir) / "plots";
  fs::create_directories(dir);
  const std::string gnuplot = findGnuplot();
  report.gnuplotFound = !gnuplot.empty();
  report.gnuplot = gnuplot.empty() ? "gnuplot is not installed (no executable `gnuplot` on PATH; on Debian: apt-get "
                                     "install gnuplot-nox); the plot data and scripts are in plots/"
                                   : gnuplot;
  const auto stopReason = [&stop]() { return stop.requested() ? stop.describe() : stopSignalReason(); };
  for (const PlotSpec& spec : scene.plots) {
    if (report.stopped.empty()) report.stopped = stopReason();
    if (!report.stopped.empty()) {
      report.notDrawn.push_back(spec.name);
      continue;
    }
    Script s;
    s.name = spec.name;
    switch (spec.type) {
      case PlotType::Bifurcation:
      case PlotType::Stiffness: branchPlot(scene, run, spec, dir, s); break;
      case PlotType::TorqueAngle: torquePlot(scene, run, spec, dir, s); break;
      case PlotType::SuddenLoad: suddenPlot(scene, run, spec, dir, s); break;
      case PlotType::EnergyCurves: energyPlot(scene, run, spec, dir, s); break;
      case PlotType::CriticalCurves: criticalCurvesPlotBody(scene, run, spec, dir.string(), s.body); break;
      case PlotType::Shapes:
        shapesPlot(scene, run, spec, size_t(&spec - scene.plots.data()), dir, s, report.notes);
        break;
      case PlotType::EquilibriumShapes: equilibriumShapesPlot(scene, run, spec, dir, s); break;
      case PlotType::Workspace: workspacePlot(scene, run, spec, dir, s); break;
      case PlotType::InputMap: inputMapPlot(scene, run, spec, dir, s); break;
    }
    if (spec.type == PlotType::Bifurcation || spec.type == PlotType::Stiffness || spec.type == PlotType::Shapes) {
      size_t stride = 1;  // a streamed large tree's sample of points (runner.h, CaseResult::points)
      for (size_t c : plot_detail::selected(spec)) stride = std::max(stride, run.cases[c].pointStride);
      if (stride > 1)
        report.notes.push_back("plot \"" + spec.name + "\" is drawn from every " + std::to_string(stride) +
                               "th point of each branch (and its ends and changes of stability): every point is in "
                               "branches.csv");
    }
    std::ofstream(dir / (spec.name + "_body.gp")) << s.body.str();
    std::ostringstream gp;
    gp << "# gnuplot " << spec.name << ".gp (run from this directory)\n"
       << "set terminal pngcairo size " << s.width << "," << s.height << " enhanced font 'DejaVu Sans,11'\n"
       << "set output " << quote(spec.name + ".png") << "\nload " << quote(spec.name + "_body.gp") << "\n"
       << "set output\nreset\n"
       << "set terminal svg size " << s.width << "," << s.height << " enhanced font 'DejaVu Sans,11' background 'white'\n"
       << "set output " << quote(spec.name + ".svg") << "\nload " << quote(spec.name + "_body.gp") << "\nset output\n";
    std::ofstream(dir / (spec.name + ".gp")) << gp.str();
    if (gnuplot.empty()) continue;
    const ChildOutcome drawn = runChild(gnuplot, {spec.name + ".gp"}, dir.string(), spec.name + ".log", stopReason);
    if (!drawn.stopped.empty()) {  // no half-drawn image: the script and data stay
      report.stopped = drawn.stopped;
      report.notDrawn.push_back(spec.name);
      std::error_code ec;
      for (const char* image : {".png", ".svg"}) fs::remove(dir / (spec.name + image), ec);
      continue;
    }
    const bool ok = drawn.exitedZero && fs::exists(dir / (spec.name + ".png")) && fs::exists(dir / (spec.name + ".svg"));
    if (ok) {
      report.files.push_back("plots/" + spec.name + ".png");
      report.files.push_back("plots/" + spec.name + ".svg");
      std::error_code ec;
      if (fs::file_size(dir / (spec.name + ".log"), ec) == 0) fs::remove(dir / (spec.name + ".log"), ec);
    } else {
      report.failures.push_back(spec.name + " (see plots/" + spec.name + ".log)");
    }
  }
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) report.written.push_back("plots/" + e.path().filename().string());
  std::sort(report.written.begin(), report.written.end());
  return report;
}

}  // namespace buckle::scene
