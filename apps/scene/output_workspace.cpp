#include "scene/output_workspace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "scene/escape.h"
#include "scene/json_values.h"

namespace buckle::scene {

namespace {

using nlohmann::json;

// NaN as an empty CSV field.
void field(std::ostream& os, double v) {
  os << ',';
  if (std::isfinite(v)) os << v;
}

}  // namespace

json workspaceJson(const RunResult& run) {
  json out = json::array();
  for (size_t c = 0; c < run.cases.size(); ++c) {
    const CaseResult& cr = run.cases[c];
    if (!cr.haveWorkspace) continue;
    const mechanics::WorkspaceMap& m = cr.workspace;
    int reached = 0, stable = 0;
    double xLo = std::numeric_limits<double>::infinity(), xHi = -xLo, yLo = xLo, yHi = -xLo;
    for (const mechanics::WorkspaceCell& cell : m.cells) {
      reached += cell.reached;
      if (!cell.stable()) continue;
      ++stable;
      xLo = std::min(xLo, cell.pose[0]);
      xHi = std::max(xHi, cell.pose[0]);
      yLo = std::min(yLo, cell.pose[1]);
      yHi = std::max(yHi, cell.pose[1]);
    }
    json curves = json::array();
    for (size_t k = 0; k < m.curves.size(); ++k) {
      const mechanics::WorkspaceCurve& cu = m.curves[k];
      double worst = 0.0;
      int stablePoints = 0;
      for (const mechanics::WorkspaceCurvePoint& p : cu.points) {
        worst = std::max(worst, p.residual);
        stablePoints += p.negative == 0;
      }
      curves.push_back(json{{"curve", k},
                            {"cause", mechanics::boundaryCauseName(cu.cause)},
                            {"name", cu.name},
                            {"points", cu.points.size()},
                            {"stable_points", stablePoints},
                            {"worst_residual", jsonNumber(worst)},
                            {"stop", cu.stop}});
    }
    out.push_back(json{{"case", c},
                       {"case_label", cr.label},
                       {"inputs", json::array({m.input1, m.input2})},
                       {"grid", json::array({m.count1, m.count2})},
                       {"reached", reached},
                       {"stable", stable},
                       {"stable_extent", json{{"x", json::array({jsonNumber(xLo), jsonNumber(xHi)})},
                                              {"y", json::array({jsonNumber(yLo), jsonNumber(yHi)})}}},
                       {"curves", curves},
                       {"problems", m.problems},
                       {"interrupted", m.interrupted}});
  }
  return out;
}

std::string workspaceMapCsv(const RunResult& run) {
  std::ostringstream os;
  os.precision(15);
  os << "case,input1,input2,u1,u2,reached,x,y,phi,stable,negative_eigenvalues,min_eig,stiffness_min,folds,residual,"
        "note\n";
  for (size_t c = 0; c < run.cases.size(); ++c) {
    const CaseResult& cr = run.cases[c];
    if (!cr.haveWorkspace) continue;
    const mechanics::WorkspaceMap& m = cr.workspace;
    for (const mechanics::WorkspaceCell& cell : m.cells) {
      os << c << ',' << escape::csvField(m.input1) << ',' << escape::csvField(m.input2) << ',' << cell.u1 << ',' << cell.u2 << ','
         << (cell.reached ? 1 : 0);
      if (!cell.reached) {
        os << ",,,,,,,,,," << escape::csvField(cell.note) << '\n';
        continue;
      }
      for (int k = 0; k < 3; ++k) field(os, cell.pose[k]);
      os << ',' << (cell.stable() ? 1 : 0) << ',' << cell.negative;
      field(os, cell.smallestEigenvalue);
      field(os, cell.stiffness);
      os << ',' << cell.folds;
      field(os, cell.residual);
      os << ",\n";
    }
  }
  return os.str();
}

std::string workspaceCurvesCsv(const RunResult& run) {
  std::ostringstream os;
  os.precision(15);
  os << "case,curve,cause,name,u1,u2,x,y,phi,stable,residual\n";
  for (size_t c = 0; c < run.cases.size(); ++c) {
    const CaseResult& cr = run.cases[c];
    if (!cr.haveWorkspace) continue;
    for (size_t k = 0; k < cr.workspace.curves.size(); ++k) {
      const mechanics::WorkspaceCurve& cu = cr.workspace.curves[k];
      for (const mechanics::WorkspaceCurvePoint& p : cu.points) {
        os << c << ',' << k << ',' << escape::csvField(mechanics::boundaryCauseName(cu.cause)) << ',' << escape::csvField(cu.name)
           << ',' << p.u1 << ',' << p.u2;
        for (int j = 0; j < 3; ++j) field(os, p.pose[j]);
        os << ',' << (p.negative == 0 ? 1 : 0);
        field(os, p.residual);
        os << '\n';
      }
    }
  }
  return os.str();
}

}  // namespace buckle::scene
