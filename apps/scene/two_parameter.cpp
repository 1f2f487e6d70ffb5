// The two_parameter analysis of a scene (docs/scenes.md): each case's critical loads as curves in
// a second parameter (mechanics/critical_curves.h), their CSV / JSON records (docs/outputs.md)
// and the critical_curves plot.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/critical_curves.h"
#include "scene/case_runner.h"
#include "scene/escape.h"
#include "scene/output.h"

namespace buckle::scene {

namespace mech = buckle::mechanics;
namespace cont = buckle::continuation;
namespace fs = std::filesystem;

namespace {
std::string g15(double v) {
  if (!std::isfinite(v)) return "nan";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}
nlohmann::json finiteOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

// Which post-buckling kind a point has, for the CSV and the plot.
const char* kindName(const mech::CriticalPoint& p, const std::string& type) {
  if (type == "LP") return "fold";
  switch (p.kind) {
    case mech::PostBuckling::Supercritical: return "supercritical";
    case mech::PostBuckling::Subcritical: return "subcritical";
    default: return "unknown";
  }
}
}  // namespace

void CaseRunner::twoParameter() {
  const TwoParameterSpec& t = scene_.analyses.twoParameter;
  const mech::EndCondition end = loadPath().problemEnd();  // λ is the path parameter (pathProblem())
  const std::string where = "case \"" + spec_.label + "\": two_parameter: ";
  try {
    mech::ChainParameterProblem problem(spec_.chain.segments, end, spec_.path.direction,
                                        mech::SecondParameter::parse(t.parameter, t.segment));
    mech::CriticalCurveOptions o;
    o.muMin = t.from;
    o.muMax = t.to;
    o.tracer = solverOptions();
    for (int mode = 0; mode < t.modes && !interrupted(); ++mode)
      out_.criticalCurves.push_back(mech::branchPointCurve(problem, mode, o));
    if (t.folds && !interrupted()) {
      // the folds of the path from the start, both ways through the path range
      cont::TracerOptions to = solverOptions();
      to.lambdaMin = std::min(spec_.path.from, spec_.path.to);
      to.lambdaMax = std::max(spec_.path.from, spec_.path.to);
      const Eigen::VectorXd u0 = problem.equilibrium().initialGuess(out_.q0, out_.startValue);
      for (const cont::InitialDirection& d : {cont::InitialDirection::increasingLambda(),
                                              cont::InitialDirection::decreasingLambda()}) {
        const cont::Branch path = cont::trace(problem, u0, out_.startValue, d, to);
        for (const cont::SpecialPoint* f : path.specialPointsOfType(cont::SpecialPointType::Fold))
          if (!interrupted()) out_.criticalCurves.push_back(mech::foldCurve(problem, *f, o));
      }
    }
  } catch (const std::invalid_argument& e) {
    run_.complete = false;
    run_.problems.push_back(where + e.what());
  }
}

void writeCriticalCurvesCsv(const RunResult& run, const std::string& dir) {
  std::ostringstream os;
  os << "case,curve,type,parameter,mu,lambda,kappa,koiter_a,koiter_b,post_buckling\n";
  for (size_t c = 0; c < run.cases.size(); ++c) {
    const auto& curves = run.cases[c].criticalCurves;
    for (size_t k = 0; k < curves.size(); ++k)
      for (const mech::CriticalPoint& p : curves[k].points)
        os << c << ',' << k << ',' << escape::csvField(curves[k].type) << ',' << escape::csvField(curves[k].parameter.name()) << ',' << g15(p.mu) << ','
           << g15(p.lambda) << ',' << g15(p.kappa) << ',' << g15(p.koiterA) << ',' << g15(p.koiterB) << ','
           << kindName(p, curves[k].type) << "\n";
  }
  std::ofstream out(fs::path(dir) / "critical_curves.csv", std::ios::binary);
  out << os.str();
  if (!out) throw std::runtime_error("cannot write " + (fs::path(dir) / "critical_curves.csv").string());
}

nlohmann::json criticalCurvesJson(const RunResult& run) {
  nlohmann::json all = nlohmann::json::array();
  for (size_t c = 0; c < run.cases.size(); ++c) {
    const auto& curves = run.cases[c].criticalCurves;
    for (size_t k = 0; k < curves.size(); ++k) {
      nlohmann::json points = nlohmann::json::array();
      for (const mech::Codim2Point& s : curves[k].special) {
        nlohmann::json e{{"label", s.label},     {"mu", finiteOrNull(s.mu)}, {"lambda", finiteOrNull(s.lambda)},
                         {"accuracy", s.accuracy}, {"converged", s.converged}};
        if (!s.note.empty()) e["note"] = s.note;
        points.push_back(e);
      }
      all.push_back(nlohmann::json{{"case", c},
                                   {"case_label", run.cases[c].label},
                                   {"curve", k},
                                   {"type", curves[k].type},
                                   {"parameter", curves[k].parameter.name()},
                                   {"points", curves[k].points.size()},
                                   {"stop", curves[k].stopMessage},
                                   {"codim2", points}});
    }
  }
  return all;
}

void criticalCurvesPlotBody(const Scene& scene, const RunResult& run, const PlotSpec& spec, const std::string& dir,
                            std::ostream& body) {
  static const char* const colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf"};
  // one data file: per case and curve, index blocks of the supercritical, subcritical and fold
  // parts (pieces separated by blank lines), then one block of the codimension-two points
  std::ostringstream data, plots;
  int block = 0;
  const std::string file = spec.name + "_curves.dat";
  auto quoteName = [](const std::string& s) { return escape::gnuplotString(s); };
  bool first = true;
  for (size_t ci = 0; ci < spec.cases.size(); ++ci) {
    const int c = spec.cases[ci];
    const CaseResult& cr = run.cases[size_t(c)];
    const std::string color = colors[ci % (sizeof colors / sizeof colors[0])];
    bool titled = false;  // one key entry per case: its colour
    for (const char* part : {"supercritical", "subcritical", "fold"}) {
      bool any = false;
      for (const mech::CriticalCurve& curve : cr.criticalCurves) {
        bool open = false;
        for (const mech::CriticalPoint& p : curve.points) {
          if (std::string(kindName(p, curve.type)) != part) {
            if (open) data << "\n";
            open = false;
            continue;
          }
          data << g15(p.mu) << ' ' << g15(p.lambda) << "\n";
          open = any = true;
        }
        if (open) data << "\n";
      }
      if (!any) data << "nan nan\n";
      data << "\n\n";
      const std::string style = std::string(part) == "supercritical" ? "dt 1 lw 2.5"
                                : std::string(part) == "subcritical" ? "dt 2 lw 2.5"
                                                                     : "dt 3 lw 2";
      if (any) {
        plots << (first ? "plot " : ", \\\n     ") << quoteName(file) << " index " << block << " with lines " << style
              << " lc rgb '" << color << "' " << (titled ? std::string("notitle") : "title " + quoteName(cr.label));
        first = false;
        titled = true;
      }
      ++block;
    }
  }
  // codimension-two points: label and marker
  for (const int c : spec.cases)
    for (const mech::CriticalCurve& curve : run.cases[size_t(c)].criticalCurves)
      for (const mech::Codim2Point& s : curve.special) data << g15(s.mu) << ' ' << g15(s.lambda) << ' ' << escape::datField(s.label) << "\n";
  data << "nan nan -\n";
  std::ofstream(fs::path(dir) / file) << data.str();
  const TwoParameterSpec& t = scene.analyses.twoParameter;
  body << "set encoding utf8\nset grid lc rgb '#dddddd'\nset key outside right top box opaque samplen 3 font ',9'\n"
       << "set label 1 \"solid: supercritical\\ndashed: subcritical\\ndotted: fold curve\\n\\nK0: zero critical load\\n"
          "DP: degenerate pitchfork\\nCP: cusp\\nBD: joint limit\" at screen 0.845, screen 0.72 font ',9'\n";
  body << "set title " << quoteName(spec.title.empty() ? "Critical loads against " + t.parameter +
                                                             " (solid: supercritical, dashed: subcritical, dotted: folds)"
                                                       : spec.title)
       << " noenhanced\n";
  // the second parameter with its unit: a, b (lengths) and k (a stiffness) are segment
  // parameters, L0, dL0, x, y and phi columns of branches.csv (columns.h)
  const std::string second = t.parameter == "a" || t.parameter == "b" ? t.parameter + scene.units.suffix(Dimension::Length)
                             : t.parameter == "k" ? t.parameter + scene.units.suffix(Dimension::Stiffness)
                                                  : columnLabel(t.parameter, scene.units);
  body << "set xlabel " << quoteName(second) << "\nset ylabel "
       << quoteName(columnLabel(scene.cases.front().path.parameter, scene.units)) << "\n";
  body << "set xzeroaxis lt -1 lc rgb '#888888'\n";
  body << plots.str() << (first ? "plot " : ", \\\n     ") << quoteName(file) << " index " << block
       << " using 1:2 with points pt 7 ps 1.4 lc rgb 'black' title 'codim-2 point', \\\n     "
       << quoteName(file) << " index " << block
       << " using 1:2:3 with labels offset 1.2,0.8 font ',10' tc rgb 'black' notitle\n";
}

}  // namespace buckle::scene
