// work_precision: time against error over a grid of solver settings (maximum step, Newton and
// location tolerances) for
//   (a) the first two branch points of the 3-segment clamped–pinned chain vs eq 17
//       (Fx = λκ/b, λ_U = (√21 − 14)/10, λ_Z = −(√21 + 14)/10, κ = 0.75);
//   (b) the fold of AUTO's I_up case (free end, L0 = 0.5, Fy = 0.01) vs a tightly converged
//       reference (max step 0.002, tolerances 1e-14), checked against ref.py's 0.1777097421507;
//   (c) the whole U-branch (A_U: from BP1 to |q| = 1.5): the largest distance ‖u − u*(λ)‖∞ of
//       its points from the reference curve (each point re-solved at its λ to 1e-14); the end
//       point's Fx vs the tight run is printed beside it (column endErr).
// Times are in-process medians of --reps runs (default 5). Output: a table on stdout and
// gnuplot data/plot files in --out DIR (default benchmarks/results).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "buckle/continuation/corrector.h"
#include "cases.h"

using namespace buckle::bench;

namespace {

struct Row {
  std::string problem;
  Settings s;
  double seconds = 0, error = 0;
  int points = 0;
  double endError = NAN;  ///< (c) only: |end Fx − reference|
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double bpError(const CaseResult& r) {
  int found = 0;
  double e = 0;
  for (const auto& l : r.located)
    if (l.label == "BP" && std::isfinite(l.reference)) {
      e = std::max(e, std::abs(l.Fx - l.reference));
      ++found;
    }
  return found >= 2 ? e : INFINITY;
}

double foldValue(const CaseResult& r) {
  for (const auto& l : r.located)
    if (l.label == "LP") return l.Fx;
  return NAN;
}

double endValue(const CaseResult& r) {
  for (auto it = r.located.rbegin(); it != r.located.rend(); ++it)
    if (it->label == "BD") return it->Fx;
  return NAN;
}

double branchDistance(const CaseResult& r) {
  auto problem = pinned3(2.25, 1.5);
  buckle::continuation::CorrectorOptions co;
  co.residualTolerance = 1e-14;
  co.maxIterations = 20;
  buckle::continuation::Corrector corr(problem, co);
  double d = 0;
  Eigen::VectorXd u(problem.dimension());
  for (size_t i = 1; i < r.branch.points.size(); ++i) {
    const auto& p = r.branch.points[i];
    corr.solveAtFixedParameter(p.u, p.lambda, u);
    d = std::max(d, (u - p.u).lpNorm<Eigen::Infinity>());
  }
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5;
  bool quick = false;
  std::string out = BUCKLE_BENCH_DIR "/results";
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) reps = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
    else if (!std::strcmp(argv[i], "--quick")) quick = true;
  }
  std::vector<double> steps = {0.2, 0.1, 0.05, 0.02, 0.01, 0.005};
  std::vector<std::pair<double, double>> tols = {{1e-6, 1e-4}, {1e-8, 1e-8}, {1e-10, 1e-12}};  // (Newton, location)
  if (quick) {
    steps = {0.1, 0.02};
    tols = {{1e-10, 1e-12}};
    reps = 1;
  }

  // References.
  Settings tight;
  tight.maxStep = 0.002;
  tight.initialStep = 0.002;
  tight.newtonTolerance = 1e-13;
  tight.locationTolerance = 1e-14;
  CaseResult refFold, refU;
  runCase("I_up", tight, refFold);
  runCase("A_U", tight, refU);
  const double foldRef = foldValue(refFold), endRef = endValue(refU);
  std::printf("# references: fold Fx = %.14f (ref.py 0.1777097421507, diff %.1e); A_U end Fx = %.14f\n", foldRef,
              std::abs(foldRef - 0.1777097421507), endRef);
  if (!std::isfinite(foldRef) || !std::isfinite(endRef)) {
    std::fprintf(stderr, "reference run failed\n");
    return 1;
  }

  std::vector<Row> rows;
  for (const auto& tol : tols)
    for (double h : steps) {
      Settings s;
      s.maxStep = h;
      s.initialStep = std::min(0.01, h);
      s.newtonTolerance = tol.first;
      s.locationTolerance = tol.second;
      for (const char* prob : {"a_branch_points", "b_fold", "c_branch"}) {
        std::vector<double> t;
        CaseResult r;
        for (int k = 0; k < reps; ++k) {
          runCase(prob[0] == 'a' ? "A_triv" : prob[0] == 'b' ? "I_up" : "A_U", s, r);
          t.push_back(r.seconds);
        }
        Row row{prob, s, median(t), 0, r.points, NAN};
        if (prob[0] == 'a') row.error = bpError(r);
        else if (prob[0] == 'b') row.error = std::abs(foldValue(r) - foldRef);
        else {
          row.error = branchDistance(r);
          row.endError = std::abs(endValue(r) - endRef);
        }
        if (!std::isfinite(row.error)) row.error = INFINITY;
        rows.push_back(row);
      }
    }

  std::printf("%-16s %8s %10s %10s %7s %12s %12s %12s\n", "problem", "maxStep", "newtonTol", "locTol", "points",
              "time_ms", "error", "endErr");
  for (const auto& r : rows)
    std::printf("%-16s %8.3f %10.0e %10.0e %7d %12.4f %12.3e %12.3e\n", r.problem.c_str(), r.s.maxStep,
                r.s.newtonTolerance, r.s.locationTolerance, r.points, 1e3 * r.seconds, r.error, r.endError);

  const std::string dat = out + "/work_precision.dat", gp = out + "/work_precision.gp";
  std::ofstream f(dat);
  for (const char* prob : {"a_branch_points", "b_fold", "c_branch"}) {
    f << "# " << prob << ": maxStep newtonTol locTol points time_ms error (error floored at 1e-17)\n";
    for (const auto& r : rows)
      if (r.problem == prob && std::isfinite(r.error))
        f << r.s.maxStep << " " << r.s.newtonTolerance << " " << r.s.locationTolerance << " " << r.points << " "
          << 1e3 * r.seconds << " " << std::max(r.error, 1e-17) << "\n";
    f << "\n\n";
  }
  std::ofstream g(gp);
  g << "set terminal png size 900,600\nset output '" << out << "/work_precision.png'\n"
    << "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\nset grid\n"
    << "set xlabel 'error'\nset ylabel 'time per run [ms]'\n"
    << "set title 'buckle work-precision, n = 3 (errors of 0 shown as 1e-17)'\nset key top right\n"
    << "plot '" << dat << "' index 0 using 6:5 with points pt 7 title '(a) BP1, BP2 vs eq 17', \\\n"
    << "     '' index 1 using 6:5 with points pt 5 title '(b) fold vs tight reference', \\\n"
    << "     '' index 2 using 6:5 with points pt 9 title '(c) U-branch vs reference curve'\n";
  std::printf("# wrote %s, %s (gnuplot %s)\n", dat.c_str(), gp.c_str(), gp.c_str());
  return 0;
}
