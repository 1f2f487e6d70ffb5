#include "scene_arrays.h"

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>

#include "scene/columns.h"
#include "scene/output.h"
#include "scene/special_marks.h"

namespace buckle::python {

namespace py = pybind11;
using Eigen::VectorXd;

namespace {

/// Columns `columns` of `rows`, each an array.
template <class Record>
void addValues(py::dict& d, const std::vector<std::string>& columns, const std::vector<const Record*>& rows,
               const scene::CaseResult& cr) {
  const auto P = static_cast<Eigen::Index>(rows.size());
  for (const std::string& c : columns) {
    VectorXd v(P);
    for (Eigen::Index i = 0; i < P; ++i) v[i] = scene::columnValue(c, *rows[static_cast<size_t>(i)], cr);
    d[py::str(c)] = v;
  }
}

/// q of `rows` as a P×n matrix (NaN rows where a record has no angles).
template <class Record>
Eigen::MatrixXd angles(const std::vector<const Record*>& rows, const scene::CaseResult& cr) {
  const auto P = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd q(P, cr.chain.size());
  for (Eigen::Index i = 0; i < P; ++i) {
    const Eigen::VectorXd& qi = rows[static_cast<size_t>(i)]->q;
    q.row(i) = qi.size() == cr.chain.size() ? Eigen::RowVectorXd(qi.transpose())
                                             : Eigen::RowVectorXd::Constant(cr.chain.size(), NAN);
  }
  return q;
}

/// The value columns before q in branches.csv (the rest follow stable and negative).
const std::vector<std::string>& leadColumns() {
  static const std::vector<std::string> kLead{"parameter", "Fx", "Fy", "Me", "x", "y", "phi", "dx", "dy"};
  return kLead;
}

/// The value columns after q, stable, negative, min_eig, locked and contact_torque.
std::vector<std::string> tailColumns(const scene::Scene& s) {
  const std::vector<std::string> all = valueColumns(s);
  return std::vector<std::string>(all.begin() + static_cast<std::ptrdiff_t>(leadColumns().size()) + 1, all.end());
}

}  // namespace

std::vector<std::string> valueColumns(const scene::Scene& s) {
  std::vector<std::string> columns{"parameter", "Fx", "Fy", "Me", "x", "y", "phi", "dx", "dy", "min_eig"};
  if (s.analyses.stiffness)
    columns.insert(columns.end(), scene::stiffnessColumns().begin(), scene::stiffnessColumns().end());
  if (s.analyses.frequencies.enabled) {
    const std::vector<std::string> omega = scene::frequencyColumns(s.analyses.frequencies.count);
    columns.insert(columns.end(), omega.begin(), omega.end());
  }
  const std::vector<std::string> inputs = s.inputColumns();  // a task path's inputs
  columns.insert(columns.end(), inputs.begin(), inputs.end());
  return columns;
}

py::dict branchArrays(const scene::Scene& s, const scene::CaseResult& cr) {
  const auto P = static_cast<Eigen::Index>(cr.points.size());
  py::dict d;
  Eigen::VectorXi branch(P), point(P), negative(P);
  VectorXd contactTorque(P), wallForce(P), selfForce(P);
  py::array_t<bool> stable(P);
  auto stableView = stable.mutable_unchecked<1>();
  std::vector<std::string> locked, wall, self;
  std::vector<const mechanics::PointReport*> rows;
  for (Eigen::Index i = 0; i < P; ++i) {
    const mechanics::PointReport& p = cr.points[static_cast<size_t>(i)];
    rows.push_back(&p);
    branch[i] = p.branch;
    point[i] = p.index;
    negative[i] = p.negative;
    stableView(i) = p.stable;
    locked.push_back(p.locked.label());
    contactTorque[i] = p.contactTorque;
    wall.push_back(p.locked.wallLabel());
    wallForce[i] = p.wallForces.sum();
    self.push_back(p.locked.selfLabel());
    selfForce[i] = p.selfForces.sum();
  }
  // in the order of branches.csv's columns
  d["branch"] = branch;
  d["point"] = point;
  addValues(d, leadColumns(), rows, cr);
  d["q"] = angles(rows, cr);
  d["stable"] = stable;
  d["negative"] = negative;
  addValues(d, {"min_eig"}, rows, cr);
  d["locked"] = locked;
  d["contact_torque"] = contactTorque;
  d["wall"] = wall;
  d["wall_force"] = wallForce;
  const scene::ContinuationSpec& c = s.analyses.continuation;
  if (c.enabled && c.contact && c.self) {  // as branches.csv: with self contact traced
    d["self"] = self;
    d["self_force"] = selfForce;
  }
  addValues(d, tailColumns(s), rows, cr);
  return d;
}

py::dict specialArrays(const scene::Scene& s, const scene::CaseResult& cr, int firstIndex) {
  const auto m = static_cast<Eigen::Index>(cr.specials.size());
  py::dict d;
  Eigen::VectorXi branch(m), index(m);
  std::vector<std::string> type, field, shape;
  std::vector<const scene::SpecialPointResult*> rows;
  for (Eigen::Index i = 0; i < m; ++i) {
    const scene::SpecialPointResult& r = cr.specials[static_cast<size_t>(i)];
    rows.push_back(&r);
    branch[i] = r.branch;
    index[i] = firstIndex + static_cast<int>(i);
    type.push_back(mechanics::label(r.type));
    field.push_back(scene::fieldName(cr, r));
    shape.push_back(r.shape);
  }
  d["index"] = index;
  d["type"] = type;
  d["field"] = field;
  d["branch"] = branch;
  addValues(d, leadColumns(), rows, cr);
  d["q"] = angles(rows, cr);
  addValues(d, tailColumns(s), rows, cr);
  d["shape"] = shape;
  return d;
}

py::dict equilibriaArrays(const scene::CaseResult& cr) {
  Eigen::Index m = 0;
  for (const scene::EquilibriumSet& set : cr.equilibriumSets) m += static_cast<Eigen::Index>(set.found.equilibria.size());
  py::dict d;
  Eigen::MatrixXd q(m, cr.chain.size());
  VectorXd potential(m), at(m);
  Eigen::VectorXi index(m), rank(m), branch = Eigen::VectorXi::Constant(m, -1);
  py::array_t<bool> stable(m);
  auto stableView = stable.mutable_unchecked<1>();
  std::vector<std::string> shape;
  Eigen::Index k = 0;
  for (const scene::EquilibriumSet& set : cr.equilibriumSets)
    for (size_t i = 0; i < set.found.equilibria.size(); ++i, ++k) {  // the rows of equilibria.csv
      const mechanics::FoundEquilibrium& e = set.found.equilibria[i];
      at[k] = set.at;
      rank[k] = static_cast<int>(i) + 1;
      q.row(k) = e.q.transpose();
      potential[k] = e.potential;
      index[k] = e.index;
      stableView(k) = e.stable;
      shape.push_back(e.shape);
      if (i < set.onBranch.size()) branch[k] = set.onBranch[i];
    }
  d["at"] = at;
  d["rank"] = rank;
  d["q"] = q;
  d["potential"] = potential;
  d["index"] = index;
  d["stable"] = stable;
  d["shape"] = shape;
  d["branch"] = branch;
  py::list disconnected;
  for (const scene::BranchRecord& b : cr.branches)
    if (b.fromEquilibrium > 0) {
      py::dict r;
      r["id"] = b.id;
      r["parent"] = b.parent;
      r["from_equilibrium"] = b.fromEquilibrium;
      r["from_equilibrium_at"] = b.fromEquilibriumAt;
      r["joins"] = b.joins >= 0 ? py::object(py::int_(b.joins)) : py::object(py::none());
      disconnected.append(r);
    }
  d["disconnected_branches"] = disconnected;
  return d;
}

py::dict columnLabels(const scene::Scene& s, int segments) {
  py::dict labels;
  auto label = [&](const std::string& column, const std::string& as) {
    labels[py::str(column)] = scene::columnLabel(as, s.units, scene::LabelStyle::Plain);
  };
  // the path parameter's label, as the plots and report.html write it (plot_internal.h)
  label("parameter", s.cases.empty() ? std::string("parameter") : s.cases.front().path.parameter);
  for (const std::string& c : valueColumns(s))
    if (c != "parameter") label(c, c);
  for (int i = 1; i <= segments; ++i) label("q" + std::to_string(i), "q" + std::to_string(i));
  return labels;
}

py::list plotSpecs(const std::vector<scene::PlotSpec>& plots) {
  py::list out;
  for (const scene::PlotSpec& p : plots) {
    py::dict d;
    d["type"] = scene::toString(p.type);
    d["name"] = p.name;
    d["title"] = p.title;
    d["x"] = p.x;
    d["y"] = p.y;
    d["at"] = p.at;
    d["cases"] = p.cases;
    out.append(d);
  }
  return out;
}


py::dict workspaceArrays(const scene::CaseResult& cr) {
  const mechanics::WorkspaceMap& m = cr.workspace;
  const Eigen::Index r = m.count2, c = m.count1;
  Eigen::MatrixXd u1(r, c), u2(r, c), x(r, c), y(r, c), phi(r, c), minEig(r, c), stiffness(r, c), residual(r, c);
  Eigen::MatrixXi reached(r, c), stable(r, c), negative(r, c), folds(r, c);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Eigen::Index j = 0; j < r; ++j)
    for (Eigen::Index i = 0; i < c; ++i) {
      const mechanics::WorkspaceCell& cell = m.cell(int(i), int(j));
      u1(j, i) = cell.u1;
      u2(j, i) = cell.u2;
      reached(j, i) = cell.reached;
      stable(j, i) = cell.stable();
      negative(j, i) = cell.reached ? cell.negative : -1;
      folds(j, i) = cell.reached ? cell.folds : -1;
      x(j, i) = cell.reached ? cell.pose[0] : nan;
      y(j, i) = cell.reached ? cell.pose[1] : nan;
      phi(j, i) = cell.reached ? cell.pose[2] : nan;
      minEig(j, i) = cell.reached ? cell.smallestEigenvalue : nan;
      stiffness(j, i) = cell.reached ? cell.stiffness : nan;
      residual(j, i) = cell.reached ? cell.residual : nan;
    }
  py::dict d;
  d["inputs"] = std::vector<std::string>{m.input1, m.input2};
  d["u1"] = u1;
  d["u2"] = u2;
  d["reached"] = reached;
  d["x"] = x;
  d["y"] = y;
  d["phi"] = phi;
  d["stable"] = stable;
  d["negative_eigenvalues"] = negative;
  d["min_eig"] = minEig;
  d["stiffness_min"] = stiffness;
  d["folds"] = folds;
  d["residual"] = residual;
  py::list curves;
  for (const mechanics::WorkspaceCurve& cu : m.curves) {
    const Eigen::Index k = static_cast<Eigen::Index>(cu.points.size());
    VectorXd a1(k), a2(k), ax(k), ay(k), aphi(k), ares(k);
    Eigen::VectorXi ast(k);
    for (Eigen::Index i = 0; i < k; ++i) {
      const mechanics::WorkspaceCurvePoint& p = cu.points[size_t(i)];
      a1[i] = p.u1;
      a2[i] = p.u2;
      ax[i] = p.pose[0];
      ay[i] = p.pose[1];
      aphi[i] = p.pose[2];
      ares[i] = p.residual;
      ast[i] = p.negative == 0;
    }
    py::dict cd;
    cd["cause"] = mechanics::boundaryCauseName(cu.cause);
    cd["name"] = cu.name;
    cd["stop"] = cu.stop;
    cd["u1"] = a1;
    cd["u2"] = a2;
    cd["x"] = ax;
    cd["y"] = ay;
    cd["phi"] = aphi;
    cd["stable"] = ast;
    cd["residual"] = ares;
    curves.append(cd);
  }
  d["curves"] = curves;
  d["problems"] = m.problems;
  return d;
}

}  // namespace buckle::python
