// Workspace and stability maps over two control inputs (workspace_map.h; issue 29): every grid
// equilibrium solved and classified (against a dense eigen-solve), every change of stability or
// of the map's orientation between neighbouring grid values crossed by a traced curve, every
// curve point on its curve (the condition recomputed), a fold curve's point found again as the
// fold of a one-parameter control path, the same map in scaled units, and the same map when
// several parts (the processes of buckle-mpi, threads here) share its rows.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/unloaded_shape.h"
#include "buckle/mechanics/workspace_map.h"
#include "fixed_lambda_newton.h"
#include "payload_start.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

// The default segment (a/b = 0.5, L0/b = 2.25) under Fx = Fy = −0.3 k b, three segments; L, k the units.
struct MapCase {
  double L = 1.0, k = 1.0;
  Chain chain() const { return Chain::uniform(3, SegmentParameters::symmetric(0.5 * L, L, k, 2.25 * L)); }
  Eigen::Vector3d payload() const { return Eigen::Vector3d(-0.3 * k * L, -0.3 * k * L, 0.0); }
  WorkspaceMapOptions options() const {
    WorkspaceMapOptions o;
    o.first = {{ControlInput::L0, -1}, 1.7 * L, 2.6 * L, 13};
    o.second = {{ControlInput::dL0, -1}, -3.0 * L, 1.6 * L, 17};
    o.tracer.maxPoints = 4000;
    o.threads = 2;
    return o;
  }
};

struct Computed {
  MapCase c;
  std::unique_ptr<InputPlane> plane;
  WorkspaceMap map;
};

Computed compute(const MapCase& c) {
  Computed out;
  out.c = c;
  const Chain chain = c.chain();
  out.plane = std::make_unique<InputPlane>(chain, EndCondition::freeEnd(c.payload()), BodyLoads{},
                                           c.options().first.input, c.options().second.input);
  out.map = computeWorkspaceMap(*out.plane, buckle::test::underPayload(chain, c.payload()), c.options());
  return out;
}

const Computed& reference() {
  static const Computed computed = compute(MapCase{});
  return computed;
}

// Distance from (u1, u2) to the nearest point of a curve of `cause`, in grid cells.
double cellsToCurve(const WorkspaceMap& m, const WorkspaceMapOptions& o, BoundaryCause cause, double u1, double u2) {
  const double w1 = (o.first.to - o.first.from) / (o.first.count - 1);
  const double w2 = (o.second.to - o.second.from) / (o.second.count - 1);
  double best = std::numeric_limits<double>::infinity();
  for (const WorkspaceCurve& c : m.curves)
    if (c.cause == cause)
      for (const WorkspaceCurvePoint& p : c.points) best = std::min(best, std::hypot((p.u1 - u1) / w1, (p.u2 - u2) / w2));
  return best;
}

}  // namespace

TEST_CASE("workspace map: every grid equilibrium solved and classified as a dense eigen-solve does",
          "[workspace_map]") {
  const Computed& r = reference();
  const WorkspaceMap& m = r.map;
  REQUIRE(m.problems.empty());
  int reached = 0, stable = 0, unstable = 0;
  for (const WorkspaceCell& cell : m.cells) {
    if (!cell.reached) {
      CHECK(!cell.note.empty());  // why (the row ended, or turned back past a fold, first)
      continue;
    }
    ++reached;
    auto p = r.plane->along(0, cell.u2);
    const cont::BoundProblem bound(*p);
    Eigen::VectorXd F(3), Fl(3);
    Eigen::MatrixXd H(3, 3);
    REQUIRE(bound.residual(cell.q, cell.u1, F));
    REQUIRE(bound.jacobian(cell.q, cell.u1, H, Fl));
    CHECK(F.norm() < 1e-10);
    const Eigen::VectorXd mu = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues();
    const int negative = int((mu.array() < 0.0).count());
    CHECK(cell.negative == negative);
    CHECK(cell.smallestEigenvalue == Approx(mu[0]).margin(1e-12));
    CHECK(cell.pose.head<2>().isApprox(endPose(p->chain(), cell.q).head<2>(), 1e-14));
    stable += negative == 0;
    unstable += negative > 0;
    if (negative == 0) CHECK(cell.stiffness > 0.0);
  }
  // the box was chosen to hold both: the test would mean little on a map of one kind
  CHECK(reached > int(m.cells.size()) * 9 / 10);
  CHECK(stable > 0);
  CHECK(unstable > 0);
}

TEST_CASE("workspace map: every change of stability or orientation between grid neighbours is crossed by a curve",
          "[workspace_map]") {
  const Computed& r = reference();
  const WorkspaceMap& m = r.map;
  const WorkspaceMapOptions o = r.c.options();
  const InputPlaneCurveProblem singular(*r.plane, InputPlaneCurveProblem::Condition::Singular);
  auto ws = singular.createWorkspace();
  std::vector<double> c(m.cells.size(), std::numeric_limits<double>::quiet_NaN());
  for (size_t k = 0; k < m.cells.size(); ++k)
    if (m.cells[k].reached) singular.condition(*ws, m.cells[k].q, m.cells[k].u1, m.cells[k].u2, c[k]);
  int stabilityChanges = 0, orientationChanges = 0;
  // along a row the path between two neighbours is the traced branch itself (a fold of the row
  // is where stability changes); between rows only neighbours on one sheet are comparable
  const auto pair = [&](int i1, int j1, int i2, int j2) {
    const WorkspaceCell &a = m.cell(i1, j1), &b = m.cell(i2, j2);
    const bool row = j1 == j2;
    if (!a.reached || !b.reached || (!row && a.folds != b.folds) || std::abs(a.folds - b.folds) > 1) return;
    const double u1 = 0.5 * (a.u1 + b.u1), u2 = 0.5 * (a.u2 + b.u2);
    if ((a.negative == 0) != (b.negative == 0)) {
      ++stabilityChanges;
      INFO("stability changes between (" << a.u1 << ", " << a.u2 << ") and (" << b.u1 << ", " << b.u2 << ")");
      CHECK(cellsToCurve(m, o, BoundaryCause::Fold, u1, u2) < 1.5);
    }
    const double ca = c[size_t(&a - m.cells.data())], cb = c[size_t(&b - m.cells.data())];
    if (std::isfinite(ca) && std::isfinite(cb) && (ca > 0) != (cb > 0) && a.negative == 0 && b.negative == 0 &&
        a.folds == b.folds) {
      ++orientationChanges;
      INFO("det dp/du changes sign between (" << a.u1 << ", " << a.u2 << ") and (" << b.u1 << ", " << b.u2 << ")");
      CHECK(cellsToCurve(m, o, BoundaryCause::Singular, u1, u2) < 1.5);
    }
  };
  for (int j = 0; j < m.count2; ++j)
    for (int i = 0; i < m.count1; ++i) {
      if (i + 1 < m.count1) pair(i, j, i + 1, j);
      if (j + 1 < m.count2) pair(i, j, i, j + 1);
    }
  CHECK(stabilityChanges > 0);
  CHECK(orientationChanges > 0);
}

TEST_CASE("workspace map: every curve point is an equilibrium on its curve, inside the box", "[workspace_map]") {
  const Computed& r = reference();
  const WorkspaceMapOptions o = r.c.options();
  std::map<BoundaryCause, int> count;
  for (const WorkspaceCurve& curve : r.map.curves) {
    ++count[curve.cause];
    std::unique_ptr<InputPlaneCurveProblem> problem;
    if (curve.cause == BoundaryCause::Fold)
      problem = std::make_unique<InputPlaneCurveProblem>(*r.plane, InputPlaneCurveProblem::Condition::Fold);
    if (curve.cause == BoundaryCause::Singular)
      problem = std::make_unique<InputPlaneCurveProblem>(*r.plane, InputPlaneCurveProblem::Condition::Singular);
    auto ws = problem ? problem->createWorkspace() : nullptr;
    for (const WorkspaceCurvePoint& p : curve.points) {
      INFO(curve.name << " at (" << p.u1 << ", " << p.u2 << ")");
      const double e1 = 1e-12 * (o.first.to - o.first.from), e2 = 1e-12 * (o.second.to - o.second.from);
      CHECK(p.u1 >= o.first.from - e1);
      CHECK(p.u1 <= o.first.to + e1);
      CHECK(p.u2 >= o.second.from - e2);
      CHECK(p.u2 <= o.second.to + e2);
      auto eq = r.plane->along(0, p.u2);
      Eigen::VectorXd F(3);
      REQUIRE(cont::BoundProblem(*eq).residual(p.q, p.u1, F));
      CHECK(F.norm() < 1e-9);
      if (!problem) continue;
      double c = 1.0;
      REQUIRE(problem->condition(*ws, p.q, p.u1, p.u2, c));
      CHECK(std::abs(c) < 1e-8);
    }
  }
  CHECK(count[BoundaryCause::InputBound] == 4);
  CHECK(count[BoundaryCause::Fold] >= 1);
  CHECK(count[BoundaryCause::Singular] >= 1);
}

TEST_CASE("workspace map: a fold curve's point is the fold of the control path through it", "[workspace_map]") {
  const Computed& r = reference();
  const WorkspaceCurve* fold = nullptr;
  for (const WorkspaceCurve& c : r.map.curves)
    if (c.cause == BoundaryCause::Fold && c.points.size() > 4) fold = &c;
  REQUIRE(fold != nullptr);
  const WorkspaceCurvePoint& P = fold->points[fold->points.size() / 2];
  // the control path along u1 at P's u2, from an equilibrium a little off the fold on the side
  // where equilibria exist, traced both ways: one direction meets the fold at P's u1
  auto p = r.plane->along(0, P.u2);
  const double scale = p->scales().parameter;
  bool found = false;
  for (double side : {-1.0, 1.0}) {
    const double u1 = P.u1 + side * 1e-3 * scale;
    Eigen::VectorXd q = P.q;
    Eigen::VectorXd F(3), Fl(3);
    Eigen::MatrixXd H(3, 3);
    const cont::BoundProblem bound(*p);
    bool converged = false;
    for (int it = 0; it < 30 && !converged; ++it) {
      REQUIRE(bound.residual(q, u1, F));
      converged = F.norm() < 1e-13;
      REQUIRE(bound.jacobian(q, u1, H, Fl));
      q -= H.partialPivLu().solve(F);
    }
    if (!converged || !q.allFinite()) continue;
    cont::TracerOptions o;
    o.lambdaMin = P.u1 - 0.05 * scale;
    o.lambdaMax = P.u1 + 0.05 * scale;
    for (const auto& dir : {cont::InitialDirection::increasingLambda(), cont::InitialDirection::decreasingLambda()}) {
      const cont::Branch b = cont::trace(bound, q, u1, dir, o);
      for (const cont::SpecialPoint* sp : b.specialPointsOfType(cont::SpecialPointType::Fold))
        if (std::abs(sp->lambda - P.u1) < 1e-8 * scale) found = true;
    }
  }
  CHECK(found);
}

TEST_CASE("workspace map: the same map in scaled units", "[workspace_map]") {
  const Computed& ref = reference();
  const double L = GENERATE(1e-4, 1e4);
  const double k = GENERATE(1e-8, 1e8);
  INFO("L = " << L << ", k = " << k);
  const Computed scaled = compute(MapCase{L, k});
  REQUIRE(scaled.map.cells.size() == ref.map.cells.size());
  for (size_t i = 0; i < ref.map.cells.size(); ++i) {
    const WorkspaceCell &a = ref.map.cells[i], &b = scaled.map.cells[i];
    REQUIRE(a.reached == b.reached);
    if (!a.reached) continue;
    CHECK(a.negative == b.negative);
    CHECK((b.pose.head<2>() / L - a.pose.head<2>()).norm() < 1e-9);
    CHECK(b.smallestEigenvalue / (k * L * L) == Approx(a.smallestEigenvalue).margin(1e-9));
    if (a.negative == 0) CHECK(b.stiffness / k == Approx(a.stiffness).epsilon(1e-8));
  }
  std::map<BoundaryCause, int> ca, cb;
  for (const WorkspaceCurve& c : ref.map.curves) ++ca[c.cause];
  for (const WorkspaceCurve& c : scaled.map.curves) ++cb[c.cause];
  CHECK(ca == cb);
}

namespace {

// An all-gather among the threads of this process standing for the processes of buckle-mpi (one
// exchange per map). A part in `absent` never calls it: its slot stays "" (it took no part).
class ThreadExchange {
 public:
  ThreadExchange(int parts, std::vector<int> absent) : slots_(size_t(parts)), arrived_(int(absent.size())) {}
  std::vector<std::string> operator()(int part, const std::string& mine) {
    std::unique_lock<std::mutex> lock(mutex_);
    slots_[size_t(part)] = mine;
    if (++arrived_ == int(slots_.size()))
      ready_.notify_all();
    else
      ready_.wait(lock, [&] { return arrived_ == int(slots_.size()); });
    return slots_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable ready_;
  std::vector<std::string> slots_;
  int arrived_;
};

// The map of each part, the parts run on threads (`rowsOnly`: parts that return after the exchange).
std::vector<WorkspaceMap> sharedMaps(int parts, const std::vector<int>& absent, const std::vector<int>& rowsOnly) {
  const MapCase c;
  const Chain chain = c.chain();
  const InputPlane plane(chain, EndCondition::freeEnd(c.payload()), BodyLoads{}, c.options().first.input,
                         c.options().second.input);
  const Vector q0 = buckle::test::underPayload(chain, c.payload());
  ThreadExchange exchange(parts, absent);
  std::vector<WorkspaceMap> maps(static_cast<size_t>(parts));
  std::vector<std::thread> threads;
  for (int part = 0; part < parts; ++part) {
    if (std::count(absent.begin(), absent.end(), part)) continue;
    threads.emplace_back([&, part] {
      WorkspaceMapOptions o = c.options();
      o.threads = 1;
      o.share.part = part;
      o.share.parts = parts;
      o.share.rowsOnly = std::count(rowsOnly.begin(), rowsOnly.end(), part) > 0;
      o.share.exchange = [&exchange, part](const std::string& mine) { return exchange(part, mine); };
      maps[size_t(part)] = computeWorkspaceMap(plane, q0, o);
    });
  }
  for (std::thread& t : threads) t.join();
  return maps;
}

bool same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

void requireSameCell(const WorkspaceCell& a, const WorkspaceCell& b) {
  REQUIRE(a.reached == b.reached);
  CHECK(a.u1 == b.u1);
  CHECK(a.u2 == b.u2);
  CHECK(a.note == b.note);
  CHECK(a.q == b.q);  // bit for bit: the same computation from the same spine state
  CHECK(a.pose == b.pose);
  CHECK(a.negative == b.negative);
  CHECK(same(a.smallestEigenvalue, b.smallestEigenvalue));
  CHECK(same(a.stiffness, b.stiffness));
  CHECK(a.folds == b.folds);
  CHECK(same(a.residual, b.residual));
}

void requireSameMap(const WorkspaceMap& a, const WorkspaceMap& b) {
  REQUIRE(a.cells.size() == b.cells.size());
  for (size_t i = 0; i < a.cells.size(); ++i) requireSameCell(a.cells[i], b.cells[i]);
  REQUIRE(a.curves.size() == b.curves.size());
  for (size_t k = 0; k < a.curves.size(); ++k) {
    const WorkspaceCurve &x = a.curves[k], &y = b.curves[k];
    CHECK(x.cause == y.cause);
    CHECK(x.name == y.name);
    CHECK(x.stop == y.stop);
    REQUIRE(x.points.size() == y.points.size());
    for (size_t p = 0; p < x.points.size(); ++p) {
      CHECK(x.points[p].q == y.points[p].q);
      CHECK(x.points[p].u1 == y.points[p].u1);
      CHECK(x.points[p].u2 == y.points[p].u2);
      CHECK(x.points[p].negative == y.points[p].negative);
    }
  }
  CHECK(a.problems == b.problems);
}

}  // namespace

TEST_CASE("workspace map: rows shared among parts give every part the map computed alone, bit for bit",
          "[workspace_map]") {
  const WorkspaceMap& alone = reference().map;
  REQUIRE(alone.curves.size() >= 5);  // edges and curves travel: every kind is compared
  for (int parts : {2, 3}) {
    INFO(parts << " parts");
    for (const WorkspaceMap& m : sharedMaps(parts, {}, {})) requireSameMap(m, alone);
  }
}

TEST_CASE("workspace map: the rows of a part that takes no part are traced by the writer, and rowsOnly parts stop at the rows",
          "[workspace_map]") {
  const WorkspaceMap& alone = reference().map;
  const std::vector<WorkspaceMap> maps = sharedMaps(3, {2}, {1});
  requireSameMap(maps[0], alone);
  const WorkspaceMap& rowsOnly = maps[1];
  CHECK(rowsOnly.curves.empty());
  for (int j = 0; j < rowsOnly.count2; ++j)
    for (int i = 0; i < rowsOnly.count1; ++i) {
      if (j % 3 == 2) continue;  // the absent part's rows: nobody sent them to part 1
      requireSameCell(rowsOnly.cell(i, j), alone.cell(i, j));
    }
}

TEST_CASE("workspace map: rows from another part that do not fit the grid are refused", "[workspace_map]") {
  const MapCase c;
  const Chain chain = c.chain();
  const InputPlane plane(chain, EndCondition::freeEnd(c.payload()), BodyLoads{}, c.options().first.input,
                         c.options().second.input);
  const Vector q0 = buckle::test::underPayload(chain, c.payload());
  WorkspaceMapOptions o = c.options();
  o.share.parts = 2;
  for (const std::string& other : {std::string("\x01\x02\x03", 3), std::string(4, '\x7f') + std::string(64, '\0')}) {
    o.share.exchange = [&other](const std::string& mine) { return std::vector<std::string>{mine, other}; };
    CHECK_THROWS_AS(computeWorkspaceMap(plane, q0, o), std::runtime_error);
  }
  o.share.part = 2;
  CHECK_THROWS_WITH(computeWorkspaceMap(plane, q0, o), Catch::Contains("share.part"));
}

namespace {

double distanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double t = d.squaredNorm() > 0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (p - (a + t * d)).norm();
}

}  // namespace

TEST_CASE("workspace map: the edge of a 4x denser grid's stable region lies on the traced curves",
          "[workspace_map]") {
  // An independent sample: a grid four times finer, its stable equilibria on the start's sheet.
  // The workspace is their image; its edge must lie on the images of the curves traced on the
  // coarse grid (the image of a region is bounded by the image of its boundary and of the map's
  // critical set). Checked twice:
  //  - in the inputs' plane: every sample with a neighbour that is not one (unstable, another
  //    sheet, not reached, or outside the box) lies within 1.5 fine cells of a traced curve;
  //  - in the end's plane: the images of the cells with four stable corners, filled on a lattice
  //    of spacing h (the median distance between neighbouring samples' images); every occupied
  //    lattice cell beside an empty one lies within 2h of a traced curve's image, where the map is
  //    regular at that scale (the cells that fill it no larger than 2h: next to a fold the image
  //    of the last fine cell before it grows like the square root of its distance).
  const Computed& r = reference();
  WorkspaceMapOptions o = r.c.options();
  o.first.count = 4 * (o.first.count - 1) + 1;
  o.second.count = 4 * (o.second.count - 1) + 1;
  o.folds = o.singular = o.limits = false;  // the dense grid is the sample, not the curves
  const WorkspaceMap dense =
      computeWorkspaceMap(*r.plane, buckle::test::underPayload(r.c.chain(), r.c.payload()), o);
  const auto sample = [&](int i, int j) {
    return i >= 0 && j >= 0 && i < dense.count1 && j < dense.count2 && dense.cell(i, j).stable() &&
           dense.cell(i, j).folds == 0;
  };
  const double w1 = (o.first.to - o.first.from) / (o.first.count - 1);
  const double w2 = (o.second.to - o.second.from) / (o.second.count - 1);
  int inputEdges = 0;
  for (int j = 0; j < dense.count2; ++j)
    for (int i = 0; i < dense.count1; ++i) {
      if (!sample(i, j) || (sample(i + 1, j) && sample(i - 1, j) && sample(i, j + 1) && sample(i, j - 1))) continue;
      ++inputEdges;
      const WorkspaceCell& c = dense.cell(i, j);
      const Eigen::Vector2d at(c.u1 / w1, c.u2 / w2);
      double d = std::numeric_limits<double>::infinity();
      for (const WorkspaceCurve& curve : r.map.curves)
        for (size_t k = 0; k + 1 < curve.points.size(); ++k)
          d = std::min(d, distanceToSegment(at, {curve.points[k].u1 / w1, curve.points[k].u2 / w2},
                                            {curve.points[k + 1].u1 / w1, curve.points[k + 1].u2 / w2}));
      INFO("edge sample at (" << c.u1 << ", " << c.u2 << ")");
      CHECK(d < 1.5);
    }
  CHECK(inputEdges > 50);

  const auto xy = [&](int i, int j) { return Eigen::Vector2d(dense.cell(i, j).pose.head<2>()); };
  std::vector<std::array<Eigen::Vector2d, 4>> quads;
  std::vector<double> spacing;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
  for (int j = 0; j + 1 < dense.count2; ++j)
    for (int i = 0; i + 1 < dense.count1; ++i) {
      if (!sample(i, j) || !sample(i + 1, j) || !sample(i, j + 1) || !sample(i + 1, j + 1)) continue;
      quads.push_back({xy(i, j), xy(i + 1, j), xy(i + 1, j + 1), xy(i, j + 1)});
      spacing.push_back((xy(i, j) - xy(i + 1, j)).norm());
      spacing.push_back((xy(i, j) - xy(i, j + 1)).norm());
      for (const Eigen::Vector2d& p : quads.back()) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    }
  REQUIRE(quads.size() > 500);
  std::nth_element(spacing.begin(), spacing.begin() + long(spacing.size() / 2), spacing.end());
  const double h = spacing[spacing.size() / 2];
  const int nx = int((hi[0] - lo[0]) / h) + 1, ny = int((hi[1] - lo[1]) / h) + 1;
  std::vector<double> largest(size_t(nx) * size_t(ny), -1.0);  // the largest quad filling a lattice cell; < 0: empty
  const auto at = [&](int ix, int iy) -> double& { return largest[size_t(iy) * size_t(nx) + size_t(ix)]; };
  for (const auto& q : quads) {
    double side = 0.0;
    for (size_t k = 0; k < 4; ++k) side = std::max(side, (q[k] - q[(k + 1) % 4]).norm());
    const int m = 4 + int(4.0 * side / h);
    for (int a = 0; a <= m; ++a)
      for (int b = 0; b <= m; ++b) {
        const double s = double(a) / m, t = double(b) / m;
        const Eigen::Vector2d p = (1 - s) * (1 - t) * q[0] + s * (1 - t) * q[1] + s * t * q[2] + (1 - s) * t * q[3];
        double& cell = at(std::min(nx - 1, int((p[0] - lo[0]) / h)), std::min(ny - 1, int((p[1] - lo[1]) / h)));
        cell = std::max(cell, side);
      }
  }
  int edges = 0;
  for (int iy = 0; iy < ny; ++iy)
    for (int ix = 0; ix < nx; ++ix) {
      if (at(ix, iy) < 0 || at(ix, iy) > 2.0 * h) continue;
      bool edge = false;
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
        const int x = ix + dx, y = iy + dy;
        edge = edge || x < 0 || y < 0 || x >= nx || y >= ny || at(x, y) < 0;
      }
      if (!edge) continue;
      ++edges;
      const Eigen::Vector2d centre = lo + h * Eigen::Vector2d(ix + 0.5, iy + 0.5);
      double d = std::numeric_limits<double>::infinity();
      for (const WorkspaceCurve& c : r.map.curves)
        for (size_t k = 0; k + 1 < c.points.size(); ++k)
          d = std::min(d, distanceToSegment(centre, c.points[k].pose.head<2>(), c.points[k + 1].pose.head<2>()));
      INFO("edge cell at (" << centre[0] << ", " << centre[1] << "), h = " << h);
      CHECK(d < 2.0 * h);
    }
  CHECK(edges > 20);
}
