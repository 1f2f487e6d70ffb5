// What a regression baseline pins down, measured afresh: the special points and branches of a
// scene (through the same runner as `buckle run`, in memory) or of a benchmark problem
// (apps/problems), and how long the computation took.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace buckle::regress {

/// Where a baseline's numbers come from: a scene file or a named benchmark problem.
struct Source {
  enum class Kind { Scene, Problem };
  Kind kind = Kind::Scene;
  std::string name;  ///< scene file name (relative to the scenes directory) or problem name
  /// Scenes only: > 0, the run is stopped after this many seconds (a time-limited baseline:
  /// it must stop on time, and what it computed must agree with the complete run's values).
  double timeLimit = 0.0;
};

/// A located result. On branches (branch >= 0): the special points of special_points.json (BP,
/// LP, LPF, BD, KMIN, JUMP), λ the path parameter. Off branches (branch −1): CRIT critical
/// loads of the start configuration (λ the load), EQ equilibria of the energy curves (λ = q1),
/// TEQ zeros of the torque-angle curve (λ = q), REST the sudden load's rest state (λ = q_i,
/// one per joint).
struct MeasuredSpecial {
  int branch = 0;
  std::string type;
  double lambda = 0.0;
  std::string shape;
  double accuracy = 0.0; ///< how precisely λ is known (location accuracy or point spacing)
  /// A branch point's post-buckling name (mechanics::postBucklingName, e.g. "degenerate
  /// subcritical"); empty elsewhere.
  std::string postBuckling;
};

/// One traced branch: path parameter and joint angles at each point, in tracing order.
struct MeasuredBranch {
  int id = 0;
  std::vector<int> index;  ///< point index along the branch (gaps: points left out of the range)
  std::vector<double> lambda;
  std::vector<Eigen::VectorXd> q;
};

struct MeasuredCase {
  std::string label;
  std::vector<MeasuredSpecial> specials;
  std::vector<MeasuredBranch> branches;
};

struct Measurement {
  std::vector<MeasuredCase> cases;
  std::vector<double> seconds;        ///< one per repetition
  bool complete = true;
  std::vector<std::string> problems;  ///< why not complete
  bool interrupted = false;           ///< stopped by the source's time limit
  double medianSeconds() const;
};

/// Thrown when the source cannot be run at all (unknown problem, unreadable scene); the
/// message says why. Numerical trouble is not an error: it is recorded in the Measurement.
struct SourceError {
  std::string message;
};

/// Runs the source `repetitions` times (values from the first run, every run timed). Scene
/// names are resolved against `scenesDir`. `limited`: honour the source's time limit (false
/// for --update, whose values are the complete run's).
Measurement measure(const Source& source, const std::string& scenesDir, int repetitions, bool limited = true);

/// The benchmark problems a baseline can name.
const std::vector<std::string>& problemNames();

}  // namespace buckle::regress
