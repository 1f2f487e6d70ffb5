// work_precision: speed against error, side by side (issue 17). Three programs on the same tasks:
//   buckle  : the tracer, over a grid of maximum steps and (Newton, location) tolerances;
//   naive   : the paper's approach: Newton solves at fixed load on a uniform grid of Fx (from the
//             previous solution), a stability count at every grid point; the special points are
//             the grid points where the stability index changes (or the solution is lost: a
//             fold, or the joint limit is passed), refined by nothing;
//   AUTO-07p: read from the b-files and timings that work_precision.sh writes (--auto DIR);
//   buckle-P2: buckle with the second-order predictor (TracerOptions::secondOrderPredictor).
// Tasks (3-segment chain, main segment a = 0.5, b = 1, k = 1):
//   diagram: the full clamped–pinned diagram (L0 = 2.25): trivial branch Fx 0 → −2.5, both
//            branch points, the U and Z branches to the joint limit |q_i| = 1.5 (AUTO's A_auto);
//   fold   : free end, L0 = 0.5, Fy = 0.01, Fx increasing from 0 through the fold to the geometric
//            joint limit |q| = 2 atan(b/a) (AUTO's I_up, stopped there);
//   long   : the U branch alone from its branch point to |q_i| = 1.5 (AUTO's A_U / A_Ufine
//            restarted run; buckle's switch and branch), swept down to small steps.
// Errors: special points = max |ΔFx| of BP1, BP2 (eq 17), the end points at the joint limit and
// the fold (tight buckle runs, the fold checked against ref.py's 0.1777097421507); branch = the
// largest distance max(‖Δq‖∞, |ΔFx|) of any computed point from the true curve, found by Newton
// projection to 1e-14 along the normal of the point's own tangent (tangent from the kernel of
// [F_u, F_λ] at the point). Times: in-process wall (steady_clock) and CPU (getrusage), per run,
// median of --reps batches; AUTO's are its own "Total Time" (in-process wall) and that time scaled
// by its process's CPU/wall ratio (work_precision.sh).
// Output: a table per task, a ratio table (time to reach a combined error level), and for each
// task results/work_precision_<task>.{dat,gp} (gnuplot → .png).
#include <sys/resource.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "buckle/continuation/corrector.h"
#include "cases.h"

using namespace buckle::bench;
namespace cont = buckle::continuation;

namespace {

const char* const kTasks[] = {"diagram", "fold", "long"};
// buckle-P2: buckle with TracerOptions::secondOrderPredictor (off by default).
const char* const kPrograms[] = {"buckle", "AUTO", "naive", "buckle-P2"};
constexpr int kProgramCount = 4;
constexpr double kQLimit = 1.5;
// Geometric joint limit of the main segment: tan(q/2) = b/a (one spring at zero length).
const double kGeometricLimit = 2.0 * std::atan(2.0);

double cpuSeconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[v.size() / 2];
}

std::string fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[128];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

/// A computed diagram, whatever the program: the points of each branch (q, Fx) and its special points.
struct Outcome {
  std::vector<std::vector<std::pair<Eigen::VectorXd, double>>> branches;
  double bp1 = NAN, bp2 = NAN, endU = NAN, endZ = NAN, fold = NAN;
  int points = 0;
  std::string note;  ///< naive: where a buckled branch was not found or lost
};

struct Row {
  std::string program, task, config;
  int points = 0;
  double wall = NAN, cpu = NAN;  ///< seconds per run
  double special = INFINITY, branch = INFINITY;
  std::string note{};
};

/// Times f() (one run) in batches lasting ≥ 20 ms; per-run wall and CPU, median of `reps` batches.
void timeRuns(const std::function<void()>& f, int reps, bool quick, double& wall, double& cpu) {
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  f();
  const double once = std::chrono::duration<double>(Clock::now() - t0).count();
  const int batch = quick ? 1 : std::max(1, int(0.02 / std::max(once, 1e-7)));
  std::vector<double> walls, cpus;
  for (int r = 0; r < (quick ? 1 : reps); ++r) {
    const double c0 = cpuSeconds();
    t0 = Clock::now();
    for (int k = 0; k < batch; ++k) f();
    walls.push_back(std::chrono::duration<double>(Clock::now() - t0).count() / batch);
    cpus.push_back((cpuSeconds() - c0) / batch);
  }
  wall = median(walls);
  cpu = median(cpus);
}

// ---- the reference curve: Newton projection of a point onto the true branch ----------------

class Projector {
 public:
  /// free == false: the clamped–pinned chain (unknowns q and the end reaction), else the free end.
  Projector(bool free, double L0)
      : problem_(free ? free3(L0, 0.01) : pinned3(L0)),
        bound_(problem_),
        free_(free),
        corrector_(problem_, options()),
        n_(problem_.dimension()) {}

  /// Distance max(‖Δq‖∞, |ΔFx|) from (q, Fx) to the nearest point of the true curve.
  double distance(const Eigen::VectorXd& q, double fx) {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(n_);
    u.head(3) = q;
    if (!free_) {
      // The reaction is linear in the residual: its least-squares value at (q, Fx).
      Eigen::VectorXd f0(n_), f1(n_);
      u[3] = 0.0;
      bound_.residual(u, fx, f0);
      u[3] = 1.0;
      bound_.residual(u, fx, f1);
      const Eigen::VectorXd c = f1 - f0;
      u[3] = -c.dot(f0) / c.squaredNorm();
    }
    Eigen::VectorXd xp(n_ + 1), x(n_ + 1);
    xp << u, fx;
    Eigen::MatrixXd J(n_, n_ + 1);
    Eigen::VectorXd Fl(n_);
    bound_.jacobian(u, fx, J.leftCols(n_), Fl);
    J.col(n_) = Fl;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullV);
    const Eigen::VectorXd t = svd.matrixV().col(n_);
    double d = INFINITY;
    if (corrector_.correct(xp, t, x).converged)
      d = std::max((x.head(3) - q).lpNorm<Eigen::Infinity>(), std::abs(x[n_] - fx));
    // Near a branch point the kernel is two-dimensional: also try the solve at fixed load.
    if (!(d < 1e-3)) {
      Eigen::VectorXd v(n_);
      if (corrector_.solveAtFixedParameter(u, fx, v).converged) d = std::min(d, (v.head(3) - q).lpNorm<Eigen::Infinity>());
    }
    return d;
  }

  double maxDistance(const Outcome& o) {
    double d = 0.0;
    for (const auto& b : o.branches)
      for (const auto& p : b) d = std::max(d, distance(p.first, p.second));
    return d;
  }

 private:
  static cont::CorrectorOptions options() {
    cont::CorrectorOptions co;
    co.tolerance = 1e-14;
    co.maxIterations = 30;
    return co;
  }
  EquilibriumProblem problem_;
  cont::BoundProblem bound_;  // its workspace
  bool free_;
  cont::Corrector corrector_;
  int n_;
};

// ---- buckle ---------------------------------------------------------------------------------

void addBranch(const cont::Branch& b, Outcome& o) {
  std::vector<std::pair<Eigen::VectorXd, double>> pts;
  for (const auto& p : b.points) pts.emplace_back(p.u.head(3), p.lambda);
  o.points += int(b.points.size()) - 1;
  o.branches.push_back(std::move(pts));
}

double boundaryValue(const cont::Branch& b) {
  for (auto it = b.specialPoints.rbegin(); it != b.specialPoints.rend(); ++it)
    if (it->type == cont::SpecialPointType::Boundary) return it->lambda;
  return NAN;
}

/// Step control of every buckle run: TracerOptions' defaults unless --rule, --growth,
/// --target-angle or --target-contraction change them.
cont::TracerOptions gStepOptions;

cont::TracerOptions options(const Settings& s, double lambdaMin, double lambdaMax, bool secondOrder) {
  cont::TracerOptions o = tracerOptions(s, lambdaMin, lambdaMax);
  o.step.secondOrderPredictor = secondOrder;
  o.step.rule = gStepOptions.step.rule;
  o.step.stepGrowth = gStepOptions.step.stepGrowth;
  o.step.targetAngle = gStepOptions.step.targetAngle;
  o.step.targetContraction = gStepOptions.step.targetContraction;
  return o;
}

/// The full diagram: trivial branch, both BPs, U and Z branches to |q_i| = 1.5.
void buckleDiagram(const Settings& s, bool secondOrder, std::vector<cont::Branch>& out) {
  out.clear();
  auto problem = pinned3(2.25, kQLimit);
  cont::Tracer tracer(problem, options(s, -2.5, 0.0, secondOrder));
  out.push_back(tracer.trace(Eigen::VectorXd::Zero(4), 0.0, cont::InitialDirection::decreasingLambda()));
  const auto bps = out[0].specialPointsOfType(cont::SpecialPointType::BranchPoint);
  for (size_t i = 0; i < std::min<size_t>(2, bps.size()); ++i) {
    Eigen::VectorXd direction;
    if (!cont::bifurcatingDirection(problem, *bps[i], direction)) continue;
    out.push_back(cont::switchBranch(tracer, *bps[i], direction, 1));
  }
}

Outcome diagramOutcome(const std::vector<cont::Branch>& branches) {
  Outcome o;
  for (const auto& b : branches) addBranch(b, o);
  const auto bps = branches[0].specialPointsOfType(cont::SpecialPointType::BranchPoint);
  if (bps.size() >= 1) o.bp1 = bps[0]->lambda;
  if (bps.size() >= 2) o.bp2 = bps[1]->lambda;
  if (branches.size() >= 2) o.endU = boundaryValue(branches[1]);
  if (branches.size() >= 3) o.endZ = boundaryValue(branches[2]);
  return o;
}

void buckleFold(const Settings& s, bool secondOrder, cont::Branch& out) {
  auto problem = free3(0.5, 0.01);
  cont::Tracer tracer(problem, options(s, -3.0, 3.0, secondOrder));
  out = tracer.trace(Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda());
}

Outcome foldOutcome(const cont::Branch& b) {
  Outcome o;
  addBranch(b, o);
  for (const auto& sp : b.specialPoints)
    if (sp.type == cont::SpecialPointType::Fold) {
      o.fold = sp.lambda;
      break;
    }
  return o;
}

// ---- naive: Newton on a uniform load grid with a stability check -----------------------------

class GridSolver {
 public:
  explicit GridSolver(EquilibriumProblem& p)
      : p_(p), bound_(p), n_(p.dimension()), F_(n_), Fl_(n_), J_(n_, n_), du_(n_) {}

  /// Newton at fixed Fx from u (in place): ‖F‖∞ ≤ 1e-12 (the residual's own scale is 1 here).
  bool solve(Eigen::VectorXd& u, double fx) {
    for (int it = 0; it < 40; ++it) {
      if (!bound_.residual(u, fx, F_)) return false;
      if (F_.lpNorm<Eigen::Infinity>() <= 1e-12) return true;
      if (!bound_.jacobian(u, fx, J_, Fl_)) return false;
      lu_.compute(J_);
      du_ = lu_.solve(F_);
      if (!du_.allFinite()) return false;
      u -= du_;
    }
    return false;
  }
  int index(const Eigen::VectorXd& u, double fx) {
    cont::StabilityInfo info;
    bound_.stability(u, fx, 0, info);
    return info.negative;
  }

 private:
  EquilibriumProblem& p_;
  cont::BoundProblem bound_;  // its workspace
  int n_;
  Eigen::VectorXd F_, Fl_;
  Eigen::MatrixXd J_;
  Eigen::VectorXd du_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
};

double maxAngle(const Eigen::VectorXd& u) { return u.head(3).lpNorm<Eigen::Infinity>(); }

/// March from the first grid point past a branch point along the buckled branch until the joint
/// limit is first exceeded; that grid point is the end. False when the branch is lost. The start guess is the trivial state plus
/// a multiple of the critical mode (the smallest singular vector of F_u there).
bool naiveBuckledBranch(EquilibriumProblem& p, GridSolver& g, const char* name, double fxStart, double h, Outcome& o,
                        double& end) {
  Eigen::MatrixXd J(4, 4);
  Eigen::VectorXd Fl(4), zero = Eigen::VectorXd::Zero(4);
  cont::BoundProblem(p).jacobian(zero, fxStart, J, Fl);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullV);
  const Eigen::VectorXd mode = svd.matrixV().col(3) / svd.matrixV().col(3).head(3).lpNorm<Eigen::Infinity>();
  Eigen::VectorXd u;
  bool found = false;
  // A guess is accepted when Newton lands on a bent state along the mode (not on the trivial
  // state, nor on the other buckled branch, which also exists past the second branch point).
  for (double a : {0.3, 0.1, 0.03, 0.01, 0.003, 0.001, 0.6, 1.0}) {
    u = a * mode;
    if (g.solve(u, fxStart) && maxAngle(u) > 1e-6 &&
        std::abs(u.head(3).normalized().dot(mode.head(3).normalized())) > 0.7) {
      found = true;
      break;
    }
  }
  if (!found) {
    o.note += std::string(" ") + name + ": not found at Fx = " + fmt("%.4g", fxStart);
    return false;
  }
  std::vector<std::pair<Eigen::VectorXd, double>> pts;
  double fx = fxStart;
  pts.emplace_back(u.head(3), fx);
  // Newton's start at the next load: the linear extrapolation of the last two solutions (from
  // the previous one alone, the amplitude ~ √|Fx − Fx_c| near the branch point is not kept and
  // Newton falls back onto the trivial state).
  Eigen::VectorXd prev = u, next(u.size());
  for (int k = 1; k < 1000000 && fx > -2.5; ++k) {
    fx = fxStart - k * h;
    if (k > 1) {
      next.noalias() = 2.0 * u - prev;
      prev = u;
      u.swap(next);
    }
    if (!g.solve(u, fx) || maxAngle(u) < 1e-8) {  // lost, or back on the trivial state
      o.note += std::string(" ") + name + ": lost at Fx = " + fmt("%.4g", fx);
      return false;
    }
    g.index(u, fx);
    pts.emplace_back(u.head(3), fx);
    if (maxAngle(u) >= kQLimit) {
      end = fx;
      break;
    }
  }
  o.points += int(pts.size());
  o.branches.push_back(std::move(pts));
  return std::isfinite(end);
}

Outcome naiveDiagram(double h) {
  Outcome o;
  auto p = pinned3(2.25);
  GridSolver g(p);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(4);
  std::vector<std::pair<Eigen::VectorXd, double>> pts;
  int index = g.index(u, 0.0);
  std::vector<double> changes;
  const int steps = int(std::lround(2.5 / h));
  for (int k = 0; k <= steps; ++k) {
    const double fx = -k * h;
    if (!g.solve(u, fx)) return o;
    const int i = g.index(u, fx);
    if (i != index) changes.push_back(fx);
    index = i;
    pts.emplace_back(u.head(3), fx);
  }
  o.points = int(pts.size());
  o.branches.push_back(std::move(pts));
  if (changes.size() >= 1) o.bp1 = changes[0];
  if (changes.size() >= 2) o.bp2 = changes[1];
  if (std::isfinite(o.bp1)) naiveBuckledBranch(p, g, "U", o.bp1, h, o, o.endU);
  if (std::isfinite(o.bp2)) naiveBuckledBranch(p, g, "Z", o.bp2, h, o, o.endZ);
  return o;
}

/// The U branch alone, from the first grid point past BP1 (the trivial branch is not timed, as
/// for the restarted runs of the other programs).
Outcome naiveLong(double h) {
  Outcome o;
  auto p = pinned3(2.25);
  GridSolver g(p);
  const double bp = std::ceil(analyticFx(2.25, false) / -h) * -h;  // the grid point the trivial march flags
  naiveBuckledBranch(p, g, "U", bp, h, o, o.endU);
  return o;
}

/// Fx increasing from 0 on the free chain: the fold is the last grid point before the solution
/// is lost (Newton fails, or jumps: a change of the stability index or a step in q ten times the
/// previous one). The march cannot pass the fold, so the branch beyond it is not computed.
Outcome naiveFold(double h) {
  Outcome o;
  auto p = free3(0.5, 0.01);
  GridSolver g(p);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3), prev;
  if (!g.solve(u, 0.0)) return o;
  int index = g.index(u, 0.0);
  double lastJump = INFINITY;
  std::vector<std::pair<Eigen::VectorXd, double>> pts;
  pts.emplace_back(u, 0.0);
  for (int k = 1; k * h <= 3.0; ++k) {
    const double fx = k * h;
    prev = u;
    const bool ok = g.solve(u, fx);
    const double jump = (u - prev).lpNorm<Eigen::Infinity>();
    if (!ok || g.index(u, fx) != index || jump > 10.0 * lastJump + 1e-3 || maxAngle(u) >= kGeometricLimit) {
      o.fold = fx - h;
      break;
    }
    lastJump = k > 1 ? jump : INFINITY;
    pts.emplace_back(u, fx);
  }
  o.points = int(pts.size()) - 1;
  o.branches.push_back(std::move(pts));
  return o;
}

// ---- AUTO: b-files written by work_precision.sh -----------------------------------------------

/// A labelled point of AUTO's b-file: its type (1, 6 BP; 2, 5 LP; −4 UZ; 9 EP), Fx, and the index
/// of its branch in the file's order.
struct AutoLabel {
  int type;
  double fx;
  int branch;
};

/// Reads AUTO's fort.7: the continuation points (q1..q3, Fx) of every branch and the labelled ones.
bool readAutoBFile(const std::string& path, Outcome& o, std::vector<AutoLabel>& labelled) {
  std::ifstream in(path);
  if (!in) return false;
  std::string line;
  std::map<std::string, int> col;
  int lastBranch = -1;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::vector<std::string> f;
    for (std::string w; ls >> w;) f.push_back(w);
    if (f.size() < 2) continue;
    if (f[0] == "0") {
      if (f[1] == "PT") {
        col.clear();
        // The header's "0" stands where the data rows have BR: the columns line up.
        for (size_t i = 0; i < f.size(); ++i) col[f[i]] = int(i);
      }
      continue;
    }
    if (!col.count("Fx") || !col.count("q3") || int(f.size()) <= col["q3"]) continue;
    const int br = std::atoi(f[0].c_str()), type = std::atoi(f[2].c_str());
    Eigen::VectorXd q(3);
    // AUTO writes mantissa and exponent without the 'E' for three-digit exponents (1.7976+308).
    auto num = [](const std::string& s) { return std::strtod(s.c_str(), nullptr); };
    q << num(f[size_t(col["q1"])]), num(f[size_t(col["q2"])]), num(f[size_t(col["q3"])]);
    const double fx = num(f[size_t(col["Fx"])]);
    if (br != lastBranch) o.branches.emplace_back();
    lastBranch = br;
    o.branches.back().emplace_back(q, fx);
    ++o.points;
    if (type != 0) labelled.push_back({type, fx, int(o.branches.size()) - 1});
  }
  return o.points > 0;
}

// ---- error measures ---------------------------------------------------------------------------

struct References {
  double bp1 = analyticFx(2.25, false), bp2 = analyticFx(2.25, true);
  double endU = NAN, endZ = NAN, fold = NAN;
};

double absErr(double v, double ref) { return std::isfinite(v) ? std::abs(v - ref) : INFINITY; }

double specialError(const std::string& task, const Outcome& o, const References& r) {
  if (task == "diagram")
    return std::max({absErr(o.bp1, r.bp1), absErr(o.bp2, r.bp2), absErr(o.endU, r.endU), absErr(o.endZ, r.endZ)});
  if (task == "fold") return absErr(o.fold, r.fold);
  return absErr(o.endU, r.endU);
}

/// Rows on the lower envelope: sorted by error, each faster than every more accurate one.
std::vector<const Row*> front(const std::vector<Row>& rows, const std::string& program, const std::string& task,
                              double Row::*err, double Row::*time) {
  std::vector<const Row*> v;
  for (const auto& r : rows)
    if (r.program == program && r.task == task && std::isfinite(r.special) && std::isfinite(r.branch) &&
        std::isfinite(r.*time))
      v.push_back(&r);
  std::sort(v.begin(), v.end(), [&](const Row* a, const Row* b) { return a->*err < b->*err; });
  std::vector<const Row*> f;
  for (const Row* r : v)
    if (f.empty() || r->*time < f.back()->*time) f.push_back(r);
  return f;
}

/// Least time of a program over its settings whose special and branch errors are both ≤ level.
double timeAtLevel(const std::vector<Row>& rows, const std::string& program, const std::string& task, double level,
                   double Row::*time) {
  double best = INFINITY;
  for (const auto& r : rows)
    if (r.program == program && r.task == task && r.special <= level && r.branch <= level) best = std::min(best, r.*time);
  return best;
}

void writePlot(const std::vector<Row>& rows, const std::string& task, const std::string& out) {
  const std::string dat = out + "/work_precision_" + task + ".dat", gp = out + "/work_precision_" + task + ".gp";
  std::ofstream f(dat);
  // Per program: index 5p = all settings; 5p+1..5p+4 = envelopes (wall/special, wall/branch, CPU/special, CPU/branch).
  for (const char* prog : kPrograms) {
    f << "# " << prog << " " << task << ": config points wall_ms cpu_ms special_err branch_err (errors floored at 1e-17)\n";
    auto line = [&](const Row& r) {
      f << r.config << " " << r.points << " " << 1e3 * r.wall << " " << 1e3 * r.cpu << " "
        << std::max(r.special, 1e-17) << " " << std::max(r.branch, 1e-17) << "\n";
    };
    bool any = false;
    for (const auto& r : rows)
      if (r.program == prog && r.task == task && std::isfinite(r.special) && std::isfinite(r.branch)) line(r), any = true;
    if (!any) f << "nan 0 nan nan nan nan\n";
    f << "\n\n";
    for (auto time : {&Row::wall, &Row::cpu})
      for (auto err : {&Row::special, &Row::branch}) {
        const auto fr = front(rows, prog, task, err, time);
        for (const Row* r : fr) line(*r);
        if (fr.empty()) f << "nan 0 nan nan nan nan\n";
        f << "\n\n";
      }
  }
  const char* titles[] = {"diagram: full n = 3 clamped-pinned diagram (trivial, BP1, BP2, U and Z to |q| = 1.5)",
                          "fold: free end, L0 = 0.5, Fy = 0.01 (AUTO I-up) to the joint limit",
                          "long: U branch from BP1 to |q| = 1.5 (AUTO A-U, restarted)"};
  const int t = task == "diagram" ? 0 : task == "fold" ? 1 : 2;
  std::ofstream g(gp);
  g << "set terminal pngcairo size 1400,1000 font ',10'\nset output '" << out << "/work_precision_" << task << ".png'\n"
    << "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\nset grid\nset key top left\n"
    << "set multiplot layout 2,2 title \"" << titles[t]
    << "\\nbuckle vs AUTO-07p vs naive load grid; buckle-P2: second-order predictor (lines: lower envelopes; errors of 0 at 1e-17)\"\n";
  const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd"};
  const char* panels[4][3] = {{"special-point error |dFx|", "wall time per run [ms]", "3:5"},
                              {"branch error (max distance to the true curve)", "wall time per run [ms]", "3:6"},
                              {"special-point error |dFx|", "CPU time per run [ms]", "4:5"},
                              {"branch error (max distance to the true curve)", "CPU time per run [ms]", "4:6"}};
  for (int k = 0; k < 4; ++k) {
    const std::string using_ = std::string(panels[k][2]);
    const std::string xy = using_.substr(2) + ":" + using_.substr(0, 1);  // x = error, y = time
    g << "set xlabel '" << panels[k][0] << "'\nset ylabel '" << panels[k][1] << "'\nplot ";
    for (int p = 0; p < kProgramCount; ++p) {
      g << (p ? ", \\\n     " : "") << "'" << dat << "' index " << 5 * p << " using " << xy << " with points pt 7 ps 0.8 lc rgb '"
        << colors[p] << "' title '" << kPrograms[p] << "', \\\n     '' index " << 5 * p + 1 + k << " using " << xy
        << " with lines lw 2 lc rgb '" << colors[p] << "' notitle";
    }
    g << "\n";
  }
  g << "unset multiplot\n";
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5;
  bool quick = false, buckleOnly = false;
  std::string out = BUCKLE_BENCH_DIR "/results", autoDir, onlyTask;
  std::vector<double> steps = {1.6, 0.8, 0.4, 0.2, 0.1, 0.05, 0.02, 0.01, 0.005, 0.002};
  // (Newton, location) tolerances.
  std::vector<std::pair<double, double>> tols = {{1e-4, 1e-3}, {1e-7, 1e-6}, {1e-9, 1e-10}, {1e-10, 1e-12}, {1e-13, 1e-14}};
  std::vector<double> grid = {0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 1e-3, 5e-4, 2e-4, 1e-4};
  std::vector<bool> predictors = {false, true};  // buckle, buckle-P2
  std::vector<double> onlySteps;
  std::vector<std::pair<double, double>> onlyTols;
  auto usage = [](const char* arg) {
    std::fprintf(stderr,
                 "usage: work_precision [--quick] [--reps R] [--out DIR] [--auto DIR] [--buckle-only] [--task T]\n"
                 "         [--max-step H]... [--tolerances NEWTON:LOCATION]... [--predictor euler|p2] [--rule curvature|count]\n"
                 "         [--growth G] [--target-angle RAD] [--target-contraction THETA]\n"
                 "  unknown or incomplete argument %s\n",
                 arg);
    return 2;
  };
  for (int i = 1; i < argc; ++i) {
    const bool more = i + 1 < argc;
    if (!std::strcmp(argv[i], "--reps") && more) reps = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--out") && more) out = argv[++i];
    else if (!std::strcmp(argv[i], "--auto") && more) autoDir = argv[++i];
    else if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--buckle-only")) buckleOnly = true;
    // Single settings (instruction counts under callgrind, comparisons): one task, given knobs.
    else if (!std::strcmp(argv[i], "--task") && more) onlyTask = argv[++i];
    else if (!std::strcmp(argv[i], "--max-step") && more) onlySteps.push_back(std::atof(argv[++i]));
    else if (!std::strcmp(argv[i], "--tolerances") && more) {
      double n = 0, l = 0;
      if (std::sscanf(argv[++i], "%lf:%lf", &n, &l) != 2) return usage(argv[i]);
      onlyTols.emplace_back(n, l);
    } else if (!std::strcmp(argv[i], "--predictor") && more) {
      const std::string v = argv[++i];
      if (v != "euler" && v != "p2") return usage(argv[i]);
      predictors = {v == "p2"};
    } else if (!std::strcmp(argv[i], "--rule") && more) {
      const std::string v = argv[++i];
      if (v != "curvature" && v != "count") return usage(argv[i]);
      gStepOptions.step.rule = v == "count" ? cont::StepOptions::Rule::NewtonCount : cont::StepOptions::Rule::Curvature;
    } else if (!std::strcmp(argv[i], "--growth") && more) gStepOptions.step.stepGrowth = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--target-angle") && more) gStepOptions.step.targetAngle = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--target-contraction") && more) gStepOptions.step.targetContraction = std::atof(argv[++i]);
    else return usage(argv[i]);
  }
  if (!onlyTask.empty() && onlyTask != "diagram" && onlyTask != "fold" && onlyTask != "long") return usage(onlyTask.c_str());
  if (quick) {
    steps = {0.1, 0.02};
    tols = {{1e-10, 1e-12}};
    grid = {0.01};
  }
  if (!onlySteps.empty()) steps = onlySteps;
  if (!onlyTols.empty()) tols = onlyTols;
  auto wanted = [&](const char* task) { return onlyTask.empty() || onlyTask == task; };

  // References: tight buckle runs (the end points at the joint limit and the fold).
  Settings tight;
  tight.maxStep = tight.initialStep = 0.002;
  tight.newtonTolerance = 1e-13;
  tight.locationTolerance = 1e-14;
  References ref;
  {
    std::vector<cont::Branch> d;
    buckleDiagram(tight, false, d);
    const Outcome o = diagramOutcome(d);
    ref.endU = o.endU;
    ref.endZ = o.endZ;
    cont::Branch f;
    buckleFold(tight, false, f);
    ref.fold = foldOutcome(f).fold;
  }
  std::printf("# references: BP1 %.15f BP2 %.15f (eq 17); ends at |q| = 1.5: U %.14f Z %.14f; fold %.14f "
              "(ref.py 0.1777097421507, diff %.1e)\n",
              ref.bp1, ref.bp2, ref.endU, ref.endZ, ref.fold, std::abs(ref.fold - 0.1777097421507));
  if (!std::isfinite(ref.endU) || !std::isfinite(ref.endZ) || !std::isfinite(ref.fold)) {
    std::fprintf(stderr, "reference run failed\n");
    return 1;
  }

  Projector pinned(false, 2.25), freeEnd(true, 0.5);
  auto projectorFor = [&](const std::string& task) -> Projector& { return task == "fold" ? freeEnd : pinned; };
  std::vector<Row> rows;
  auto finish = [&](Row row, const Outcome& o) {
    row.points = o.points;
    row.note = o.note;
    row.special = specialError(row.task, o, ref);
    row.branch = o.branches.empty() ? INFINITY : projectorFor(row.task).maxDistance(o);
    rows.push_back(row);
  };

  // buckle: every task over the grid of settings (lowest eigenvalue recorded: AUTO's PVLS computes emin).
  for (const bool secondOrder : predictors)
  for (const auto& tol : tols)
    for (double h : steps) {
      const std::string program = secondOrder ? "buckle-P2" : "buckle";
      Settings s;
      s.maxStep = h;
      s.initialStep = std::min(0.01, h);
      s.newtonTolerance = tol.first;
      s.locationTolerance = tol.second;
      s.lowestEigenvalues = 1;
      const std::string cfg = fmt("h%g_tol%g_loc%g", h, tol.first, tol.second);
      Row row{program, "diagram", cfg};
      if (wanted("diagram")) {
        std::vector<cont::Branch> d;
        timeRuns([&] { buckleDiagram(s, secondOrder, d); }, reps, quick, row.wall, row.cpu);
        finish(row, diagramOutcome(d));
      }
      row.task = "fold";
      if (wanted("fold")) {
        cont::Branch f;
        timeRuns([&] { buckleFold(s, secondOrder, f); }, reps, quick, row.wall, row.cpu);
        finish(row, foldOutcome(f));
      }
      if (!wanted("long")) continue;

      // long: the switch and the U branch (the trivial branch traced once, untimed).
      auto problem = pinned3(2.25, kQLimit);
      cont::Tracer tracer(problem, options(s, -3.0, 0.0, secondOrder));
      const cont::Branch trivial = tracer.trace(Eigen::VectorXd::Zero(4), 0.0, cont::InitialDirection::decreasingLambda());
      const auto bps = trivial.specialPointsOfType(cont::SpecialPointType::BranchPoint);
      row.task = "long";
      if (bps.empty()) continue;
      cont::Branch u;
      timeRuns([&] {
            Eigen::VectorXd direction;
            cont::bifurcatingDirection(problem, *bps[0], direction);
            u = cont::switchBranch(tracer, *bps[0], direction, 1);
          },
          reps, quick, row.wall, row.cpu);
      Outcome o;
      addBranch(u, o);
      o.endU = boundaryValue(u);
      finish(row, o);
    }

  // naive: the uniform load grid.
  if (buckleOnly) grid.clear();
  for (double h : grid) {
    const std::string cfg = fmt("grid%g", h);
    Outcome o;
    Row row{"naive", "diagram", cfg};
    if (wanted("diagram")) {
      timeRuns([&] { o = naiveDiagram(h); }, reps, quick, row.wall, row.cpu);
      finish(row, o);
    }
    row.task = "fold";
    if (wanted("fold")) {
      timeRuns([&] { o = naiveFold(h); }, reps, quick, row.wall, row.cpu);
      finish(row, o);
    }
    row.task = "long";
    if (wanted("long")) {
      timeRuns([&] { o = naiveLong(h); }, reps, quick, row.wall, row.cpu);
      finish(row, o);
    }
  }

  // AUTO: index.txt lines "task config wall_ms cpu_ms bfile" (work_precision.sh).
  if (!autoDir.empty()) {
    std::ifstream index(autoDir + "/index.txt");
    if (!index) {
      std::fprintf(stderr, "no %s/index.txt (run benchmarks/work_precision.sh)\n", autoDir.c_str());
      return 1;
    }
    std::string line;
    while (std::getline(index, line)) {
      std::istringstream ls(line);
      std::string task, cfg, wall, cpu, bfile;
      if (!(ls >> task >> cfg >> wall >> cpu >> bfile) || !wanted(task.c_str())) continue;
      // strtod: a value may be "nan" (then the row has no CPU time).
      const double wallMs = std::strtod(wall.c_str(), nullptr), cpuMs = std::strtod(cpu.c_str(), nullptr);
      Outcome o;
      std::vector<AutoLabel> labelled;
      Row row{"AUTO", task, cfg};
      row.wall = 1e-3 * wallMs;
      row.cpu = 1e-3 * cpuMs;
      if (!readAutoBFile(autoDir + "/" + bfile, o, labelled)) {
        std::fprintf(stderr, "unreadable AUTO b-file %s\n", bfile.c_str());
        rows.push_back(row);
        continue;
      }
      // A_auto: the BPs on the trivial branch (the file's first), the U and Z branches switched
      // onto at the first two (second and third), each ending on its last UZ (qmax); the trivial
      // branch's own UZ at Fx = −2.5 is not an end at the joint limit. A_U: one branch.
      std::vector<double> bps;
      const int uBranch = task == "diagram" ? 1 : 0;
      for (const auto& l : labelled) {
        if ((l.type == 1 || l.type == 6) && l.branch == 0) bps.push_back(l.fx);
        if ((l.type == 2 || l.type == 5) && !std::isfinite(o.fold)) o.fold = l.fx;
        if (l.type == -4 && l.branch == uBranch) o.endU = l.fx;
        if (l.type == -4 && l.branch == 2 && task == "diagram") o.endZ = l.fx;
      }
      if (task == "diagram" && bps.size() >= 1) o.bp1 = bps[0];
      if (task == "diagram" && bps.size() >= 2) o.bp2 = bps[1];
      finish(row, o);
    }
  }

  // ---- report -----------------------------------------------------------------------------
  for (const char* task : kTasks) {
    std::printf("\n## %s\n%-7s %-28s %7s %10s %10s %11s %11s\n", task, "program", "setting", "points", "wall_ms", "cpu_ms",
                "special", "branch");
    for (const auto& r : rows)
      if (r.task == task)
        std::printf("%-7s %-28s %7d %10.4f %10.4f %11.2e %11.2e%s\n", r.program.c_str(), r.config.c_str(), r.points,
                    1e3 * r.wall, 1e3 * r.cpu, r.special, r.branch, r.note.c_str());
  }
  std::printf("\n## least time to reach both errors (special points and branch) <= level; ratios = other / buckle;"
              " _w wall, _c CPU, ms per run\n");
  std::printf("%-8s %7s | %9s %9s %9s | %9s %9s %9s | %8s %8s | %8s %8s | %9s %8s\n", "task", "level", "buckle_w",
              "AUTO_w", "naive_w", "buckle_c", "AUTO_c", "naive_c", "AUTO/b_w", "AUTO/b_c", "naive/b_w", "naive/b_c", "P2_c",
              "AUTO/P2_c");
  for (const char* task : kTasks)
    for (double level : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12}) {
      double t[kProgramCount][2];
      for (int p = 0; p < kProgramCount; ++p)
        for (int k = 0; k < 2; ++k) t[p][k] = 1e3 * timeAtLevel(rows, kPrograms[p], task, level, k ? &Row::cpu : &Row::wall);
      auto ratio = [](double a, double b) { return std::isfinite(a) && std::isfinite(b) ? fmt("%8.2f", a / b) : std::string("       -"); };
      auto ms = [](double a) { return std::isfinite(a) ? fmt("%9.4f", a) : std::string("        -"); };
      std::printf("%-8s %7.0e | %s %s %s | %s %s %s | %s %s | %s %s | %s %s\n", task, level, ms(t[0][0]).c_str(),
                  ms(t[1][0]).c_str(), ms(t[2][0]).c_str(), ms(t[0][1]).c_str(), ms(t[1][1]).c_str(), ms(t[2][1]).c_str(),
                  ratio(t[1][0], t[0][0]).c_str(), ratio(t[1][1], t[0][1]).c_str(), ratio(t[2][0], t[0][0]).c_str(),
                  ratio(t[2][1], t[0][1]).c_str(), ms(t[3][1]).c_str(), ratio(t[1][1], t[3][1]).c_str());
    }
  for (const char* task : kTasks)
    if (wanted(task)) writePlot(rows, task, out);
  std::printf("# wrote %s/work_precision_{diagram,fold,long}.{dat,gp} (gnuplot FILE.gp → .png)%s\n", out.c_str(),
              autoDir.empty() ? "; AUTO not included (no --auto DIR)" : "");
  // Every buckle run must have found its special points (the quick mode is CI's smoke test).
  for (const auto& r : rows)
    if (r.program.rfind("buckle", 0) == 0 && !std::isfinite(r.special)) {
      std::fprintf(stderr, "buckle missed a special point: %s %s\n", r.task.c_str(), r.config.c_str());
      return 1;
    }
  return 0;
}
