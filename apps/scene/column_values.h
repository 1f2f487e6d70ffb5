// The value of a branches.csv column (columns.h: names, labels, units) at a traced point or a
// special point of a case: what the writers, plots, report.html and the Python arrays read.
#pragma once

#include <string>

#include "buckle/mechanics/branch_report.h"
#include "scene/runner.h"

namespace buckle::scene {

/// Value of a branches.csv column at a point of case `cr` (NaN when it does not apply).
double columnValue(const std::string& column, const mechanics::PointReport& p, const CaseResult& cr);
/// The same for a special point (stiffness columns are NaN there unless it carries its own K_F).
double columnValue(const std::string& column, const mechanics::SpecialPointReport& s, const CaseResult& cr);

}  // namespace buckle::scene
