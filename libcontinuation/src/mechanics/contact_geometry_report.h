// Internal to reportBranch (branch_report.cpp): the geometric contacts of a branch as special
// points of its report. Apart from contact_geometry.h so that the geometry does not depend on the
// report (branch_report.h includes contact_geometry.h, never the other way round).
#pragma once

#include <vector>

#include "buckle/continuation/branch.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/contact_geometry.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

/// The located contacts of `branch` as special points "BC" / "SC" of its report `r` (its points
/// `all`: every point of the branch, with their locked joints), the reported parameter as the
/// report's (ReportOptions::heldCoordinate). `contacts`: those of locateGeometricContacts, or
/// located here when null or empty with contacts.given false.
void reportGeometricContacts(EquilibriumProblem& problem, const continuation::Branch& branch,
                             const std::vector<PointReport>& all, const ReportOptions& options, BranchReport& r,
                             GeometricContacts* contacts = nullptr);

}  // namespace buckle::mechanics
