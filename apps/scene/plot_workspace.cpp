// The workspace analysis's plots: `workspace` (the end positions held by a stable equilibrium,
// shaded, with the images of the bounding curves labelled by cause) and `input_map` (the plane of
// the two inputs coloured by the end's stiffness where the equilibrium is stable, with the fold,
// singular and joint-limit curves).
#include "buckle/mechanics/workspace_map.h"
#include "scene/plot_internal.h"

namespace buckle::scene::plot_detail {

namespace {

using mechanics::BoundaryCause;

const char* causeColor(BoundaryCause c) {
  switch (c) {
    case BoundaryCause::InputBound: return "#222222";
    case BoundaryCause::Fold: return "#d62728";
    case BoundaryCause::Singular: return "#1f77b4";
    case BoundaryCause::JointLimit: return "#2ca02c";
  }
  return "#000000";
}

std::string causeTitle(BoundaryCause c) {
  switch (c) {
    case BoundaryCause::InputBound: return "input bound";
    case BoundaryCause::Fold: return "fold (stability lost: the chain snaps)";
    case BoundaryCause::Singular: return "singular (the input-to-position map folds)";
    case BoundaryCause::JointLimit: return "joint limit";
  }
  return "";
}

constexpr BoundaryCause kCauses[] = {BoundaryCause::InputBound, BoundaryCause::Fold, BoundaryCause::Singular,
                                     BoundaryCause::JointLimit};

// The axis label of a plane input: its column label, "of segment i" for one segment's.
std::string inputLabel(const Scene& scene, const mechanics::PlaneInput& in) {
  std::string label = columnLabel(mechanics::controlInputName(in.input), scene.units);
  if (in.segment >= 0) label += " of segment " + std::to_string(in.segment + 1);
  if (in.along.size() > 0) {  // a direction: say what else moves with it
    const std::string other = mechanics::controlInputName(mechanics::complementaryInput(in.input));
    label += ", " + other + (in.along.size() == 1 ? " moved " + num(in.along[0]) + " per unit" : " moved at per-segment rates");
  }
  return label;
}

// Per cause two blocks: the stretches on stable equilibria, then the others; `xy`: in the end's
// (x, y), else in the inputs' plane.
std::vector<std::array<int, 2>> curveBlocks(const mechanics::WorkspaceMap& m, bool xy, BlockFile& f) {
  std::vector<std::array<int, 2>> blocks;
  for (BoundaryCause cause : kCauses) {
    std::array<int, 2> b{};
    for (int stable = 1; stable >= 0; --stable) {
      b[size_t(1 - stable)] = f.begin();
      for (const mechanics::WorkspaceCurve& c : m.curves) {
        if (c.cause != cause) continue;
        for (const mechanics::WorkspaceCurvePoint& p : c.points) {
          if ((p.negative == 0) == bool(stable))
            f.point({xy ? p.pose[0] : p.u1, xy ? p.pose[1] : p.u2});
          else
            f.breakLine();
        }
        f.breakLine();
      }
    }
    blocks.push_back(b);
  }
  return blocks;
}

void plotCurves(Script& s, const std::string& file, const mechanics::WorkspaceMap& m,
                const std::vector<std::array<int, 2>>& blocks, bool withBounds) {
  for (size_t k = 0; k < blocks.size(); ++k) {
    const BoundaryCause cause = kCauses[k];
    if (cause == BoundaryCause::InputBound && !withBounds) continue;
    const bool any = std::any_of(m.curves.begin(), m.curves.end(), [cause](const auto& c) { return c.cause == cause; });
    if (!any) continue;
    s.body << ", \\\n  " << quote(file) << " index " << blocks[k][0] << " using 1:2 with lines lw 2.5 lc rgb "
           << quote(causeColor(cause)) << " title " << quote(causeTitle(cause)) << " noenhanced";
    s.body << ", \\\n  " << quote(file) << " index " << blocks[k][1] << " using 1:2 with lines lw 1 dt 2 lc rgb "
           << quote(causeColor(cause)) << " notitle";
  }
}

}  // namespace

void workspacePlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  const std::string stem = spec.name;
  BlockFile quads, curves, start;
  std::vector<std::vector<std::array<int, 2>>> curveIndex;
  std::vector<int> quadIndex, startIndex;
  for (size_t c : selected(spec)) {
    const CaseResult& cr = run.cases[c];
    quadIndex.push_back(quads.begin());
    startIndex.push_back(start.begin());
    if (!cr.haveWorkspace) {
      curveIndex.push_back(curveBlocks(mechanics::WorkspaceMap(), true, curves));
      continue;
    }
    const mechanics::WorkspaceMap& m = cr.workspace;
    // the image of every grid quad whose four corners are stable on one sheet
    for (int j = 0; j + 1 < m.count2; ++j)
      for (int i = 0; i + 1 < m.count1; ++i) {
        const mechanics::WorkspaceCell* corner[4] = {&m.cell(i, j), &m.cell(i + 1, j), &m.cell(i + 1, j + 1),
                                                     &m.cell(i, j + 1)};
        bool ok = true;
        for (const auto* q : corner) ok = ok && q->stable() && q->folds == corner[0]->folds;
        if (!ok) continue;
        for (int k = 0; k <= 4; ++k) quads.point({corner[k % 4]->pose[0], corner[k % 4]->pose[1]});
        quads.breakLine();
      }
    curveIndex.push_back(curveBlocks(m, true, curves));
    const mechanics::Pose p0 = mechanics::endPose(cr.chain, cr.qStart);
    start.point({p0[0], p0[1]});
  }
  quads.write(dir / (stem + ".dat"));
  curves.write(dir / (stem + "_curves.dat"));
  start.write(dir / (stem + "_start.dat"));
  header(s, spec.title.empty() ? "Workspace of the end under the payload: held by a stable equilibrium (shaded)"
                               : spec.title);
  s.width = 1100;
  s.height = 800;
  s.body << "set size ratio -1\nset xlabel " << quote(columnLabel("x", scene.units)) << "\nset ylabel "
         << quote(columnLabel("y", scene.units)) << "\n";
  s.body << "plot \\\n";
  bool first = true;
  for (size_t k = 0; k < quadIndex.size(); ++k) {
    const CaseResult& cr = run.cases[size_t(spec.cases[k])];
    const std::string label = quadIndex.size() > 1 ? " (" + cr.label + ")" : "";
    s.body << (first ? "  " : ", \\\n  ") << quote(stem + ".dat") << " index " << quadIndex[k]
           << " using 1:2 with filledcurves closed fc rgb " << quote(k == 0 ? "#9ecae1" : color(k))
           << " fs transparent solid 0.5 noborder title " << quote("held by a stable equilibrium" + label)
           << " noenhanced";
    first = false;
    if (cr.haveWorkspace) plotCurves(s, stem + "_curves.dat", cr.workspace, curveIndex[k], true);
    s.body << ", \\\n  " << quote(stem + "_start.dat") << " index " << startIndex[k]
           << " using 1:2 with points pt 3 ps 2 lw 2 lc rgb 'black' title " << quote("start (the chain's own inputs)");
  }
  s.body << "\n";
}

void inputMapPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  const std::string stem = spec.name;
  const size_t c = selected(spec).empty() ? 0 : selected(spec).front();  // one case: one plane
  const CaseResult& cr = run.cases[c];
  const mechanics::WorkspaceMap empty;
  const mechanics::WorkspaceMap& m = cr.haveWorkspace ? cr.workspace : empty;
  // the grid as gnuplot's `with image` reads it: one row of u₁ per u₂, no header block
  std::ostringstream grid;
  BlockFile unstable, curves;
  const int unstableBlock = unstable.begin();
  for (int j = 0; j < m.count2; ++j) {
    for (int i = 0; i < m.count1; ++i) {
      const mechanics::WorkspaceCell& cell = m.cell(i, j);
      const double k = cell.stable() && cell.stiffness > 0.0 ? cell.stiffness : std::numeric_limits<double>::quiet_NaN();
      grid << num(cell.u1) << ' ' << num(cell.u2) << ' ' << num(k) << '\n';
      if (cell.reached && !cell.stable()) unstable.point({cell.u1, cell.u2});
    }
    grid << '\n';
  }
  const std::vector<std::array<int, 2>> blocks = curveBlocks(m, false, curves);
  std::ofstream(dir / (stem + ".dat")) << grid.str();
  unstable.write(dir / (stem + "_unstable.dat"));
  curves.write(dir / (stem + "_curves.dat"));
  const mechanics::WorkspaceMapOptions& o = scene.analyses.workspace.options;
  // long names (inputs along a direction) stay in the axis labels: a title line has no room for them
  const std::string inputs =
      m.input1.size() + m.input2.size() <= 30 ? "Inputs " + m.input1 + ", " + m.input2 : "Over the two inputs";
  header(s, spec.title.empty() ? inputs + ": the end's stiffness where the equilibrium is stable" +
                                     (run.cases.size() > 1 ? " (" + cr.label + ")" : "")
                               : spec.title);
  s.width = 1100;
  s.height = 800;
  s.body << "set xlabel " << quote(inputLabel(scene, o.first.input)) << "\nset ylabel "
         << quote(inputLabel(scene, o.second.input)) << "\n";
  s.body << "set xrange [" << num(o.first.from) << ":" << num(o.first.to) << "]\nset yrange [" << num(o.second.from)
         << ":" << num(o.second.to) << "]\n";
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (const mechanics::WorkspaceCell& x : m.cells)
    if (x.stable() && x.stiffness > 0.0) {
      lo = std::min(lo, x.stiffness);
      hi = std::max(hi, x.stiffness);
    }
  const bool anyStable = hi > 0.0;
  // a log scale over less than a decade has no labelled tic: linear there
  if (anyStable && hi >= 10.0 * lo) s.body << "set logscale cb\n";
  s.body << "set palette rgb 33,13,10\nset cblabel "
         << quote("smallest eigenvalue of the loaded stiffness K_F" + scene.units.suffix(Dimension::Stiffness))
         << " noenhanced\n";
  BlockFile start;
  start.begin();
  start.point({mechanics::controlInputValue(cr.chain, o.first.input.input, o.first.input.segment),
               mechanics::controlInputValue(cr.chain, o.second.input.input, o.second.input.segment)});
  start.write(dir / (stem + "_start.dat"));
  s.body << "plot \\\n  " << quote(stem + "_unstable.dat") << " index " << unstableBlock
         << " using 1:2 with points pt 5 ps 0.6 lc rgb '#999999' title 'unstable equilibrium'";
  if (anyStable)
    s.body << ", \\\n  " << quote(stem + ".dat") << " using 1:2:3 with image pixels notitle";
  plotCurves(s, stem + "_curves.dat", m, blocks, false);
  s.body << ", \\\n  " << quote(stem + "_start.dat") << " index 0 using 1:2 with points pt 3 ps 2 lw 2 lc rgb 'black' title "
         << quote("start (the chain's own inputs)") << "\n";
}

}  // namespace buckle::scene::plot_detail
