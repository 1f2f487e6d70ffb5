// gnuplot plots of a run: one data file + one script per plot, rendered to PNG (pngcairo) and
// SVG. Scripts and data stay in <out>/plots so that a figure can be restyled by hand.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "scene/output.h"

namespace buckle::scene {

namespace fs = std::filesystem;

namespace {

const char* const kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e",
                               "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
std::string color(size_t i) { return kColors[i % (sizeof kColors / sizeof kColors[0])]; }

std::string num(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

/// gnuplot string literal (single quotes, doubled inside).
std::string quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') out += "''";
    else out += c;
  }
  return out + "'";
}

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

std::vector<size_t> selected(const PlotSpec& spec) {
  std::vector<size_t> out;
  for (int c : spec.cases) out.push_back(static_cast<size_t>(c));
  return out;
}

struct Script {
  std::string name;
  int width = 1000, height = 700;
  std::ostringstream body;
};

std::string parameterColumnLabel(const Scene& scene, const std::string& column) {
  if (column == "parameter") return columnLabel(scene.cases.front().path.parameter);
  return columnLabel(column);
}

void header(Script& s, const std::string& title) {
  s.body << "set encoding utf8\nset grid lc rgb '#dddddd'\nset key outside right top box opaque samplen 3 font ',9'\n";
  if (!title.empty()) s.body << "set title " << quote(title) << " noenhanced\n";
}

// ---- bifurcation / stiffness (columns of branches.csv) ----------------------------------------

void branchPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  BlockFile data, sp;
  struct Series {
    int block;
    size_t caseIdx, yIdx;
    bool stable;
  };
  std::vector<Series> series;
  const bool multiCase = spec.cases.size() > 1;
  for (size_t c : selected(spec)) {
    const CaseResult& cr = run.cases[c];
    for (size_t j = 0; j < spec.y.size(); ++j) {
      for (bool stable : {true, false}) {
        const int block = data.begin();
        series.push_back({block, c, j, stable});
        // polylines of consecutive points with the wanted stability; a run keeps the first point
        // of the next run so that stable and unstable parts join
        for (size_t i = 0; i < cr.points.size(); ++i) {
          const PointRecord& p = cr.points[i];
          const bool sameBranchNext = i + 1 < cr.points.size() && cr.points[i + 1].branch == p.branch;
          const double x = columnValue(spec.x, p, cr.pose0), y = columnValue(spec.y[j], p, cr.pose0);
          if (p.stable == stable && std::isfinite(x) && std::isfinite(y)) {
            data.point({x, y});
            if (sameBranchNext && cr.points[i + 1].stable != stable) {
              const PointRecord& q = cr.points[i + 1];
              data.point({columnValue(spec.x, q, cr.pose0), columnValue(spec.y[j], q, cr.pose0)});
            }
          }
          if (p.stable != stable || !sameBranchNext || !std::isfinite(x) || !std::isfinite(y)) data.breakLine();
        }
      }
    }
  }
  // special points: x y label
  bool anySpecial = false;
  sp.begin();
  for (size_t c : selected(spec)) {
    const CaseResult& cr = run.cases[c];
    for (const SpecialRecord& r : cr.specials) {
      for (size_t j = 0; j < spec.y.size(); ++j) {
        const double x = columnValue(spec.x, r, cr.pose0), y = columnValue(spec.y[j], r, cr.pose0);
        if (!std::isfinite(x) || !std::isfinite(y)) continue;
        std::string label = r.type;
        if (r.type == "BP" && !r.shape.empty() && r.shape != "other") label += " " + r.shape;
        std::ostringstream line;
        line << num(x) << " " << num(y) << " \"" << label << "\"";
        sp.text(line.str());
        anySpecial = true;
      }
    }
  }
  // jumps: arrows from the fold to the landing point
  BlockFile jumps;
  jumps.begin();
  bool anyJump = false;
  for (size_t c : selected(spec)) {
    const CaseResult& cr = run.cases[c];
    for (const SpecialRecord& r : cr.specials) {
      if (!r.jumpSuccess || r.jumpQ.size() == 0) continue;
      SpecialRecord to = r;
      to.q = r.jumpQ;
      to.F = r.jumpF;
      to.pose = r.jumpPose;
      for (size_t j = 0; j < spec.y.size(); ++j) {
        const double x0 = columnValue(spec.x, r, cr.pose0), y0 = columnValue(spec.y[j], r, cr.pose0);
        const double x1 = columnValue(spec.x, to, cr.pose0), y1 = columnValue(spec.y[j], to, cr.pose0);
        if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) continue;
        jumps.point({x0, y0, x1 - x0, y1 - y0});
        anyJump = true;
      }
    }
  }
  const std::string stem = spec.name;
  data.write(dir / (stem + ".dat"));
  if (anySpecial) sp.write(dir / (stem + "_special.dat"));
  if (anyJump) jumps.write(dir / (stem + "_jumps.dat"));

  header(s, spec.title.empty() ? (spec.type == PlotType::Stiffness ? "Loaded stiffness along the branches"
                                                                   : "Bifurcation diagram: stable solid, unstable dashed")
                               : spec.title);
  s.body << "set xlabel " << quote(parameterColumnLabel(scene, spec.x)) << "\n";
  std::string ylabel;
  for (size_t j = 0; j < spec.y.size(); ++j) ylabel += (j ? ", " : "") + columnLabel(spec.y[j]);
  if (spec.y.size() > 1) {
    bool same = true;
    for (const std::string& y : spec.y) same = same && (y[0] == spec.y[0][0]);
    if (same && spec.y[0][0] == 'K') ylabel = "stiffness (units of k)";
    if (same && spec.y[0][0] == 'q') ylabel = "joint angles (rad)";
  }
  s.body << "set ylabel " << quote(ylabel) << "\n";
  if (spec.type == PlotType::Stiffness) s.body << "set yrange [*:*]\n";
  s.body << "plot \\\n";
  bool first = true;
  for (const Series& se : series) {
    const size_t colorIndex = multiCase ? se.caseIdx * spec.y.size() + se.yIdx : se.yIdx;
    std::string title;
    if (multiCase) title = run.cases[se.caseIdx].label;
    if (spec.y.size() > 1) title += (title.empty() ? "" : " ") + spec.y[se.yIdx];
    if (title.empty()) title = se.stable ? "stable" : "unstable";
    else if (!se.stable) title = "";
    s.body << (first ? "  " : ", \\\n  ") << quote(stem + ".dat") << " index " << se.block
           << " using 1:2 with lines lw 2 lc rgb " << quote(color(colorIndex)) << " dt " << (se.stable ? 1 : 2)
           << (title.empty() ? std::string(" notitle") : " title " + quote(title) + " noenhanced");
    first = false;
  }
  if (anyJump)
    s.body << ", \\\n  " << quote(stem + "_jumps.dat")
           << " using 1:2:3:4 with vectors head filled size screen 0.015,20 lw 1.5 lc rgb '#ff7f0e' title 'jump'";
  if (anySpecial) {
    s.body << ", \\\n  " << quote(stem + "_special.dat")
           << " using 1:2 with points pt 7 ps 1.3 lc rgb 'black' title 'special points'";
    s.body << ", \\\n  " << quote(stem + "_special.dat")
           << " using 1:2:3 with labels offset char 1.2,0.9 font ',9' tc rgb 'black' notitle";
  }
  s.body << "\n";
}

// ---- torque–angle ------------------------------------------------------------------------------

void torquePlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
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
  s.body << "set xlabel 'q (rad)'\nset ylabel 'M(q) = -dE/dq (units of k b^2)'\nset xzeroaxis lt -1\n";
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

void energyPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
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
    s.body << "set xlabel 'q_1 (rad)'\nset ylabel 'E (units of k b^2)'\n";
    if (torque) {
      // Me has poles where J is singular (sin q2 = 0, ERRATA 7): scale the axis on the bulk
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
      s.body << "set y2label 'M_e (units of k b^2)'\nset y2tics\nset ytics nomirror\nset y2zeroaxis lt 0\n"
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

// ---- chain shapes ------------------------------------------------------------------------------

// Outline of one chain at joint angles q: triangles (closed polygons), springs (zigzags),
// joint-limit arcs; appended to the given block files.
void drawChain(const mechanics::Chain& chain, const Eigen::VectorXd& q, BlockFile& triangles, BlockFile& springs,
               BlockFile& limits, BlockFile& joints, BlockFile& nearLimit) {
  const int n = chain.size();
  double theta = 0.0;
  Eigen::Vector2d joint(chain.linkLengths()[0], 0.0);
  auto dir = [](double t) { return Eigen::Vector2d(std::cos(t), std::sin(t)); };
  auto nrm = [](double t) { return Eigen::Vector2d(-std::sin(t), std::cos(t)); };
  for (int i = 0; i < n; ++i) {
    const mechanics::SegmentParameters& p = chain.segment(i).parameters();
    const double before = theta, after = theta + q[i];
    // proximal triangle: apex at the joint, base b1 behind it, half-height a1
    const Eigen::Vector2d A1 = joint - p.b1 * dir(before) + p.a1 * nrm(before);
    const Eigen::Vector2d B1 = joint - p.b1 * dir(before) - p.a1 * nrm(before);
    const Eigen::Vector2d A2 = joint + p.b2 * dir(after) + p.a2 * nrm(after);
    const Eigen::Vector2d B2 = joint + p.b2 * dir(after) - p.a2 * nrm(after);
    for (const auto& tri : {std::array<Eigen::Vector2d, 3>{joint, A1, B1}, std::array<Eigen::Vector2d, 3>{joint, A2, B2}}) {
      for (const auto& v : tri) triangles.point({v.x(), v.y()});
      triangles.point({tri[0].x(), tri[0].y()});
      triangles.breakLine();
    }
    // springs: zigzag between the +n vertices (spring 1) and the −n vertices (spring 2)
    for (const auto& [P, Q] : {std::pair{A1, A2}, std::pair{B1, B2}}) {
      const Eigen::Vector2d d = Q - P;
      const double len = d.norm();
      const Eigen::Vector2d t = len > 0 ? Eigen::Vector2d(d / len) : Eigen::Vector2d(1, 0);
      const Eigen::Vector2d m(-t.y(), t.x());
      const int zig = 10;
      springs.point({P.x(), P.y()});
      for (int k = 1; k < zig; ++k) {
        const double f = double(k) / zig;
        const double w = (k % 2 ? 1.0 : -1.0) * 0.08 * std::max(p.b1, p.b2);
        const Eigen::Vector2d v = P + f * d + w * m;
        springs.point({v.x(), v.y()});
      }
      springs.point({Q.x(), Q.y()});
      springs.breakLine();
    }
    // joint-limit arc: admissible directions of the distal link, radius 0.6 b
    const double r = 0.6 * std::min(p.b1, p.b2);
    const double lo = chain.lowerLimits()[i], hi = chain.upperLimits()[i];
    for (int k = 0; k <= 40; ++k) {
      const double a = before + lo + (hi - lo) * k / 40.0;
      limits.point({joint.x() + r * std::cos(a), joint.y() + r * std::sin(a)});
    }
    limits.breakLine();
    for (double a : {before + lo, before + hi}) {
      limits.point({joint.x(), joint.y()});
      limits.point({joint.x() + 1.3 * r * std::cos(a), joint.y() + 1.3 * r * std::sin(a)});
      limits.breakLine();
    }
    joints.point({joint.x(), joint.y()});
    const double margin = std::min(hi - q[i], q[i] - lo) / (hi - lo);
    if (margin < 0.05) nearLimit.point({joint.x(), joint.y()});
    theta = after;
    joint += chain.linkLengths()[i + 1] * dir(theta);
  }
}

void shapesPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  const std::string stem = spec.name;
  const size_t nc = spec.cases.size(), na = spec.at.size();
  s.width = std::min<int>(3200, int(520 * na));
  s.height = std::min<int>(2400, int(330 * nc) + 60);
  s.body << "set encoding utf8\nset size ratio -1\nunset key\nset grid lc rgb '#eeeeee'\n";
  s.body << "set multiplot layout " << nc << "," << na << " title "
         << quote(spec.title.empty() ? std::string("Chain shapes to scale (units of b); grey arcs: joint limits, "
                                                   "red: joint within 5% of a limit")
                                     : spec.title)
         << " font ',11'\n";

  // one scale for every panel: the bounding box of all chains drawn
  Eigen::AlignedBox2d box;
  box.extend(Eigen::Vector2d(0.0, 0.0));
  for (size_t c : selected(spec)) {
    const CaseResult& cr = run.cases[c];
    box.extend(Eigen::Vector2d(cr.chain.length(), 0.0));
    for (const PointRecord& p : cr.points) {
      mechanics::ChainData data(cr.chain);
      mechanics::forwardKinematics(cr.chain, p.q, data);
      Eigen::Vector2d joint(cr.chain.linkLengths()[0], 0.0);
      box.extend(joint);
      for (int i = 0; i < cr.chain.size(); ++i) {
        joint += cr.chain.linkLengths()[i + 1] * Eigen::Vector2d(std::cos(data.theta[i]), std::sin(data.theta[i]));
        box.extend(joint);
      }
    }
  }
  const double pad = 1.2;
  const double x0 = box.min().x() - pad, x1 = box.max().x() + pad, y0 = box.min().y() - pad, y1 = box.max().y() + pad;
  for (size_t c : selected(spec)) {
    const CaseResult& cr = run.cases[c];
    std::vector<const PointRecord*> chosen;
    for (double at : spec.at) {
      // the stable point nearest to the requested level; among equals, the most deflected
      const PointRecord* best = nullptr;
      double bestD = std::numeric_limits<double>::infinity();
      for (const PointRecord& p : cr.points) {
        if (!p.stable) continue;
        const double d = std::abs(p.parameter - at) - 1e-9 * p.q.cwiseAbs().sum();
        if (d < bestD) {
          bestD = d;
          best = &p;
        }
      }
      chosen.push_back(best);
    }
    for (size_t k = 0; k < na; ++k) {
      const PointRecord* p = chosen[k];
      BlockFile tri, spr, lim, jnt, near;
      for (BlockFile* f : {&tri, &spr, &lim, &jnt, &near}) {
        f->begin();
        f->point({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
        f->breakLine();
      }
      std::ostringstream title;
      if (p) {
        drawChain(cr.chain, p->q, tri, spr, lim, jnt, near);
        title << (nc > 1 ? cr.label + ": " : std::string()) << scene.cases[c].path.parameter << " = "
              << num(std::round(p->parameter * 1e4) / 1e4);
        if (p->haveStiffness && std::isfinite(p->K(0, 0)))
          title << ",  K_{xx} = " << num(std::round(p->K(0, 0) * 1e4) / 1e4) << ", K_{yy} = "
                << num(std::round(p->K(1, 1) * 1e4) / 1e4);
      } else {
        title << cr.label << ": no stable point";
      }
      const std::string base = stem + "_" + std::to_string(c) + "_" + std::to_string(k);
      tri.write(dir / (base + "_tri.dat"));
      spr.write(dir / (base + "_spr.dat"));
      lim.write(dir / (base + "_lim.dat"));
      jnt.write(dir / (base + "_jnt.dat"));
      near.write(dir / (base + "_near.dat"));
      const double L = cr.chain.length();
      s.body << "set title " << quote(title.str()) << " font ',10'\n";
      s.body << "set xrange [" << num(std::min(x0, -0.1 * L)) << ":" << num(x1) << "]\nset yrange [" << num(y0) << ":"
             << num(y1) << "]\n";
      s.body << "set object 1 rect from " << num(-0.1 * L) << "," << num(-0.3 * L) << " to 0," << num(0.3 * L)
             << " fc rgb '#bbbbbb' fs pattern 4 border lc rgb '#555555'\n";
      s.body << "plot " << quote(base + "_lim.dat") << " using 1:2 with lines lc rgb '#aaaaaa' lw 1, \\\n"
             << "  " << quote(base + "_tri.dat")
             << " using 1:2 with filledcurves closed fc rgb '#c6dbef' fs solid 1.0 border lc rgb '#08306b', \\\n"
             << "  " << quote(base + "_tri.dat") << " using 1:2 with lines lc rgb '#08306b' lw 1.5, \\\n"
             << "  " << quote(base + "_spr.dat") << " using 1:2 with lines lc rgb '#e6550d' lw 1.5, \\\n"
             << "  " << quote(base + "_jnt.dat") << " using 1:2 with points pt 7 ps 0.9 lc rgb 'black', \\\n"
             << "  " << quote(base + "_near.dat") << " using 1:2 with points pt 6 ps 2.5 lw 2 lc rgb 'red'\n";
      s.body << "unset object 1\n";
    }
  }
  s.body << "unset multiplot\n";
}

bool executable(const std::string& path) { return ::access(path.c_str(), X_OK) == 0; }

std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') out += "'\\''";
    else out += c;
  }
  return out + "'";
}

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

PlotReport drawPlots(const Scene& scene, const RunResult& run, const std::string& outDir) {
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
  for (const PlotSpec& spec : scene.plots) {
    Script s;
    s.name = spec.name;
    switch (spec.type) {
      case PlotType::Bifurcation:
      case PlotType::Stiffness: branchPlot(scene, run, spec, dir, s); break;
      case PlotType::TorqueAngle: torquePlot(scene, run, spec, dir, s); break;
      case PlotType::EnergyCurves: energyPlot(scene, run, spec, dir, s); break;
      case PlotType::Shapes: shapesPlot(scene, run, spec, dir, s); break;
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
    const std::string cmd = "cd " + shellQuote(dir.string()) + " && " + shellQuote(gnuplot) + " " +
                            shellQuote(spec.name + ".gp") + " > " + shellQuote(spec.name + ".log") + " 2>&1";
    const int rc = std::system(cmd.c_str());
    const bool ok = rc == 0 && fs::exists(dir / (spec.name + ".png")) && fs::exists(dir / (spec.name + ".svg"));
    if (ok) {
      report.files.push_back("plots/" + spec.name + ".png");
      report.files.push_back("plots/" + spec.name + ".svg");
      std::error_code ec;
      if (fs::file_size(dir / (spec.name + ".log"), ec) == 0) fs::remove(dir / (spec.name + ".log"), ec);
    } else {
      report.failures.push_back(spec.name + " (see plots/" + spec.name + ".log)");
    }
  }
  return report;
}

}  // namespace buckle::scene
