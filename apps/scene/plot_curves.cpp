// The curves of the analyses without branches: torque–angle (eq 1) and energy curves (eq 6–8).
#include "scene/plot_internal.h"

namespace buckle::scene::plot_detail {

namespace {

// ---- torque–angle ------------------------------------------------------------------------------

void drawTorquePlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  BlockFile data, eq;
  const std::string stem = spec.name;
  std::vector<int> blocks;
  for (size_t c : selected(spec)) {
    blocks.push_back(data.begin());
    const TorqueCurve& t = run.cases[c].torque;
    for (size_t i = 0; i < t.q.size(); ++i) data.point({t.q[i], t.M[i]});
  }
  int stableBlock = eq.begin();
  for (size_t c : selected(spec))
    for (const auto& [q, st] : run.cases[c].torque.equilibria)
      if (st) eq.point({q, 0.0});
  int unstableBlock = eq.begin();
  eq.point({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
  for (size_t c : selected(spec))
    for (const auto& [q, st] : run.cases[c].torque.equilibria)
      if (!st) eq.point({q, 0.0});
  data.write(dir / (stem + ".dat"));
  eq.write(dir / (stem + "_eq.dat"));
  header(s, spec.title.empty() ? "Torque-angle curves M(q) of one segment" : spec.title);
  s.body << "set xlabel 'q (rad)'\nset ylabel " << quote("M(q) = -dE/dq" + scene.units.suffix(Dimension::Moment))
         << "\nset xzeroaxis lt -1\n";
  s.body << "plot \\\n";
  for (size_t c = 0; c < blocks.size(); ++c) {
    std::string title = run.cases[size_t(spec.cases[c])].label;
    s.body << (c ? ", \\\n  " : "  ") << quote(stem + ".dat") << " index " << blocks[c]
           << " using 1:2 with lines lw 2 lc rgb " << quote(color(c)) << " title " << quote(title) << " noenhanced";
  }
  s.body << ", \\\n  " << quote(stem + "_eq.dat") << " index " << stableBlock
         << " using 1:2 with points pt 7 ps 1.4 lc rgb 'red' title 'stable equilibrium'";
  s.body << ", \\\n  " << quote(stem + "_eq.dat") << " index " << unstableBlock
         << " using 1:2 with points pt 6 ps 1.4 lw 2 lc rgb 'black' title 'unstable equilibrium'\n";
  (void)scene;
}

// ---- energy curves -----------------------------------------------------------------------------

void drawEnergyPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  const std::string stem = spec.name;
  const bool torque = scene.analyses.energyCurves.torque;
  const size_t nc = spec.cases.size();
  const int cols = nc <= 1 ? 1 : (nc <= 4 ? 2 : 3);
  const int rows = static_cast<int>((nc + size_t(cols) - 1) / size_t(cols));
  s.width = 700 * cols;
  s.height = 520 * rows;
  s.body << "set encoding utf8\nset grid lc rgb '#dddddd'\nset key below horizontal font ',9' maxcols 3\n";
  s.body << "set multiplot layout " << rows << "," << cols << " title "
         << quote(spec.title.empty() ? std::string("Energy curves E(q_1) with the end held") : spec.title) << "\n";
  for (size_t c : selected(spec)) {
    const CaseResult& cr = run.cases[c];
    BlockFile data;
    // blocks: 0 positive feasible, 1 positive beyond joint limits, 2 negative feasible,
    // 3 negative beyond limits, 4 Me positive, 5 Me negative, 6 stable eq, 7 unstable eq
    for (int b : {1, -1}) {
      const auto& samples = b > 0 ? cr.landscape.positive : cr.landscape.negative;
      for (auto want : {mechanics::LandscapeStatus::Feasible, mechanics::LandscapeStatus::JointLimit}) {
        data.begin();
        data.point({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
        data.breakLine();
        for (const auto& smp : samples) {
          if (smp.status == want && std::isfinite(smp.energy))
            data.point({smp.q1, smp.energy});
          else
            data.breakLine();
        }
      }
    }
    for (int b : {1, -1}) {
      data.begin();
      data.point({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
      data.breakLine();
      const auto& samples = b > 0 ? cr.landscape.positive : cr.landscape.negative;
      for (const auto& smp : samples) {
        if (smp.status == mechanics::LandscapeStatus::Feasible && std::isfinite(smp.endTorque) &&
            std::abs(smp.endTorque) < 1e3)
          data.point({smp.q1, smp.endTorque});
        else
          data.breakLine();
      }
    }
    for (bool stable : {true, false}) {
      data.begin();
      data.point({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
      for (const auto& e : cr.landscape.equilibria)
        if (e.stable == stable) data.point({e.q1, e.energy});
    }
    const std::string file = stem + "_" + std::to_string(c) + ".dat";
    data.write(dir / file);
    std::ostringstream title;
    title << cr.label << "  (x, y) = (" << num(cr.landscape.x) << ", " << num(cr.landscape.y) << ")";
    s.body << "set title " << quote(title.str()) << " noenhanced font ',10'\n";
    s.body << "set xlabel 'q_1 (rad)'\nset ylabel " << quote("E" + scene.units.suffix(Dimension::Moment)) << "\n";
    if (torque) {
      // Me has poles where J is singular (sin q2 = 0, docs/mechanics.md erratum 7): scale the axis on the bulk
      std::vector<double> mags;
      for (const auto* samples : {&cr.landscape.positive, &cr.landscape.negative})
        for (const auto& smp : *samples)
          if (smp.status == mechanics::LandscapeStatus::Feasible && std::isfinite(smp.endTorque))
            mags.push_back(std::abs(smp.endTorque));
      double range = 1.0;
      if (!mags.empty()) {
        std::sort(mags.begin(), mags.end());
        range = std::max(1e-6, 2.0 * mags[size_t(0.8 * double(mags.size() - 1))]);
      }
      s.body << "set y2label " << quote("M_e" + scene.units.suffix(Dimension::Moment)) << "\nset y2tics\nset ytics nomirror\nset y2zeroaxis lt 0\n"
             << "set y2range [" << num(-range) << ":" << num(range) << "]\n";
    }
    s.body << "plot " << quote(file) << " index 0 using 1:2 with lines lw 2 lc rgb 'blue' title 'q_3 > 0', \\\n"
           << "  '' index 1 using 1:2 with lines lw 1 lc rgb 'black' title 'beyond a joint limit', \\\n"
           << "  '' index 2 using 1:2 with lines lw 2 lc rgb '#2ca02c' title 'q_3 < 0', \\\n"
           << "  '' index 3 using 1:2 with lines lw 1 lc rgb 'black' notitle, \\\n";
    if (torque)
      s.body << "  '' index 4 using 1:2 axes x1y2 with lines lw 1 dt 2 lc rgb 'blue' title 'M_e (q_3 > 0)', \\\n"
             << "  '' index 5 using 1:2 axes x1y2 with lines lw 1 dt 2 lc rgb '#2ca02c' title 'M_e (q_3 < 0)', \\\n";
    s.body << "  '' index 6 using 1:2 with points pt 7 ps 1.5 lc rgb 'red' title 'stable equilibrium', \\\n"
           << "  '' index 7 using 1:2 with points pt 7 ps 1.5 lc rgb 'black' title 'unstable equilibrium'\n";
    if (torque) s.body << "unset y2label\nunset y2tics\nset ytics mirror\n";
  }
  s.body << "unset multiplot\n";
}

}  // namespace

void torquePlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  drawTorquePlot(scene, run, spec, dir, s);
}

void energyPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  drawEnergyPlot(scene, run, spec, dir, s);
}

}  // namespace buckle::scene::plot_detail
