// A scene run's results as NumPy arrays for buckle.run_scene: the columns of branches.csv, the
// special points in the same columns, the rows of equilibria.csv, and each column's axis label
// in the scene's units (scene/columns.h: the labels of the plots and report.html).
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "scene/runner.h"
#include "scene/scene.h"

namespace buckle::python {

/// The columns of branches.csv beside case, branch, point, q, stable and negative, in the CSV's
/// order: parameter, loads, pose, min_eig, the stiffness and frequency columns and a task path's
/// inputs when the scene computes them.
std::vector<std::string> valueColumns(const scene::Scene& s);

/// The columns of branches.csv for one case (docs/outputs.md) as arrays, in its order; q as a
/// P×n matrix, `locked` a list of str.
pybind11::dict branchArrays(const scene::Scene& s, const scene::CaseResult& cr);

/// The case's special points (in the order of special_points.json) in the value columns of its
/// branches but min_eig (NaN where a column does not apply, e.g. stiffness away from a KMIN), with `type`,
/// `field`, `shape` (lists of str), `branch` and `index` (into run_scene's `special_points`).
pybind11::dict specialArrays(const scene::Scene& s, const scene::CaseResult& cr, int firstIndex);

/// The equilibria of one case (the rows of equilibria.csv) as arrays, q as an m×n matrix; with
/// "branches", the branch through each (−1: none) and the disconnected branches' seeds.
pybind11::dict equilibriaArrays(const scene::CaseResult& cr);

/// The workspace analysis of a case: the grid as (count2 × count1) arrays (u1, u2, reached, x, y,
/// phi, stable, negative_eigenvalues, min_eig, stiffness_min, folds, residual: the columns of
/// workspace_map.csv) and the curves, each a dict of cause, name, stop and its points' arrays.
pybind11::dict workspaceArrays(const scene::CaseResult& cr);

/// Column name → axis label with the scene's unit, plain Unicode ("Fx (N)", "δx = x₀ − x (m)"),
/// as report.html writes them: every value column, q1 … qn and "parameter" (the path
/// parameter's label).
pybind11::dict columnLabels(const scene::Scene& s, int segments);

/// Plot specifications as dicts {type, name, title, x, y, at, cases}: what RunResult.plot draws
/// by name or type (the scene's `plots`, after their defaults, and the default plots).
pybind11::list plotSpecs(const std::vector<scene::PlotSpec>& plots);

}  // namespace buckle::python
