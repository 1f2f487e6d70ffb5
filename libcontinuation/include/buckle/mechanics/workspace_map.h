// Workspace and stability maps over two control inputs (issue 29; docs/mechanics.md, "Workspace
// and stability maps"). Under a fixed payload, over the box [from₁, to₁] × [from₂, to₂] of two
// inputs (input_plane.h):
//   the map     a grid of equilibria on the sheet reached from the chain's own inputs u⁰ by
//               moving the inputs quasi-statically (continuation along u₂ through u₁⁰, then
//               along u₁ at every grid value of u₂), each with its stability (the inertia and
//               smallest eigenvalue of K_q − K_g), the loaded stiffness K_F of the end (eq 29)
//               and the end pose; a grid value first reached past a fold of its row is the
//               state the chain snaps to there (reported with the folds passed);
//   the curves  the boundary of the part of the workspace held by a stable equilibrium, traced
//               by continuation (InputPlaneCurveProblem): the input bounds (the box's four edges
//               as control paths), the folds of the sheet (loss of stability), the folds of the
//               input-to-position map (det ∂p/∂u = 0) and the joint stops, each started where
//               its condition changes sign between neighbouring grid values and followed both
//               ways until it leaves the box, closes, or ends.
// The end pose p(u) of the stable grid values is the workspace; its boundary lies on the images
// of the curves (the image of a region is bounded by the image of its boundary and of the
// critical set of the map).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "buckle/continuation/tracer_options.h"
#include "buckle/mechanics/input_plane.h"

namespace buckle::mechanics {

struct InputAxisRange {
  PlaneInput input;
  double from = 0.0, to = 1.0;
  int count = 21;  ///< grid values, from and to included
  double value(int i) const { return count == 1 ? from : from + (to - from) * i / (count - 1); }
};

/// Several processes computing one map (`mpirun -np N buckle-mpi run`): this one traces the rows
/// j with j mod parts = part (interleaved: a row's cost grows towards the folds), the rows are
/// exchanged, and every process holds the whole grid. The library knows nothing of how the bytes
/// travel; every part must call computeWorkspaceMap with the same plane and options.
struct WorkspaceShare {
  int part = 0, parts = 1;
  /// Collective: every part's bytes in part order, on every part (an all-gather). A part's empty
  /// string: it took no part in this map (interrupted first); its rows are then traced here.
  std::function<std::vector<std::string>(const std::string&)> exchange;
  /// Return once the rows are exchanged: a process whose map is not written (the curves and the
  /// rows the others did not send are left to the process that writes it).
  bool rowsOnly = false;
  bool shared() const { return parts > 1 && exchange != nullptr; }
  bool owns(int row) const { return !shared() || row % parts == part; }
};

struct WorkspaceMapOptions {
  InputAxisRange first, second;
  /// Tracing of the rows, the edges and the curves (its detection settings are set per use; its
  /// interrupt is honoured, its onStep / onLocated callbacks are not called: the rows run in parallel).
  continuation::TracerOptions tracer;
  bool folds = true, singular = true, limits = true;  ///< which curves are traced
  int maxCurves = 16;       ///< per kind: crossings already on a traced curve start none
  int maxCurvePoints = 2000;
  int threads = 0;          ///< rows computed in parallel; 0: std::thread::hardware_concurrency()
  WorkspaceShare share;     ///< the rows shared among processes (default: all rows here)
  /// Empty when valid, else what is wrong, the field named by its path after `prefix`.
  std::string validate(const std::string& prefix = "") const;
};

struct WorkspaceCell {
  double u1 = 0.0, u2 = 0.0;
  bool reached = false;
  std::string note;          ///< why not reached (the row's stop), empty when reached
  Vector q;
  Pose pose = Pose::Zero();
  int negative = -1;         ///< negative eigenvalues of K_q − K_g (0: stable)
  double smallestEigenvalue = 0.0;
  /// Smallest eigenvalue of the end's loaded stiffness K_F (eq 29; NaN where K_F is not
  /// positive definite: unstable, or a direction of infinite compliance).
  double stiffness = 0.0;
  int folds = 0;             ///< folds of its row passed between u₁⁰ and the cell
  double residual = 0.0;     ///< ‖F‖ of the equilibrium (the problem's units)
  bool stable() const { return reached && negative == 0; }
};

enum class BoundaryCause { InputBound, Fold, Singular, JointLimit };
/// "input bound", "fold", "singular", "joint limit".
const char* boundaryCauseName(BoundaryCause cause);

struct WorkspaceCurvePoint {
  double u1 = 0.0, u2 = 0.0;
  Vector q;                  ///< the joint angles of the equilibrium there
  Pose pose = Pose::Zero();
  int negative = -1;         ///< stability of the equilibrium there
  double residual = 0.0;     ///< ‖(F, c)‖ of the augmented system at the point (accuracy)
};

struct WorkspaceCurve {
  BoundaryCause cause = BoundaryCause::InputBound;
  std::string name;          ///< e.g. "u1 = from", "fold", "joint 2 at q_max"
  std::vector<WorkspaceCurvePoint> points;
  std::string stop;          ///< why each of its two halves ended
};

struct WorkspaceMap {
  std::string input1, input2;             ///< PlaneInput::name()
  int count1 = 0, count2 = 0;
  std::vector<WorkspaceCell> cells;        ///< row-major: u₂ outer, u₁ inner
  std::vector<WorkspaceCurve> curves;
  bool interrupted = false;
  std::vector<std::string> problems;      ///< what could not be computed, in words
  const WorkspaceCell& cell(int i1, int i2) const { return cells[size_t(i2) * size_t(count1) + size_t(i1)]; }
};

/// The map and its bounding curves (file comment). `q0`: the equilibrium at the chain's own
/// inputs under the payload. The chain's inputs must lie in the box. Throws
/// std::invalid_argument for invalid options or input (naming the field).
WorkspaceMap computeWorkspaceMap(const InputPlane& plane, ConstVectorRef q0, const WorkspaceMapOptions& options);

}  // namespace buckle::mechanics
