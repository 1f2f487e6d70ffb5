// `buckle regress`'s comparison (apps/regress/compare.cpp) of a special point: a complete run is
// held to the baseline's allowance; a run stopped by its time limit may report a point whose
// location the stop cut short, and agrees when within the accuracy that run states for it — not
// beyond it, and never more loosely in a complete run. A branch point's post-buckling direction
// is known once its branches are traced: a stopped run may not have reached it, a complete run must.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "regress/baseline.h"
#include "regress/compare.h"
#include "regress/measurement.h"

namespace reg = buckle::regress;

namespace {

// A baseline of one case with one special point at λ = −0.0094 (allowance 2e-12), and a run that
// reports it at λ + shift with the stated accuracy and post-buckling direction; the status of the
// row named `quantity` ("lambda", "post_buckling").
reg::Status pointRow(const std::string& type, bool stopped, double shift, double accuracy,
                     const std::string& basePostBuckling, const std::string& postBuckling,
                     const std::string& quantity) {
  reg::Baseline b;
  b.name = "limited";
  b.source.timeLimit = stopped ? 0.05 : 0.0;
  reg::CaseEntry c;
  c.label = "limited";
  c.branches = 1;
  reg::SpecialEntry s;
  s.branch = 0;
  s.type = type;
  s.postBuckling = basePostBuckling;
  s.lambda = -0.0094;
  s.tolerance.absolute = 2e-12;
  s.tolerance.relative = 1e-10;
  c.specials.push_back(s);
  b.cases.push_back(c);
  reg::Measurement m;
  m.interrupted = stopped;
  m.seconds = {0.05};
  reg::MeasuredCase mc;
  mc.label = "limited";
  mc.branches.resize(1);
  mc.branches[0].id = 0;
  mc.specials.push_back({0, type, s.lambda + shift, "", accuracy, postBuckling});
  m.cases.push_back(mc);
  const std::string row = "b0 " + type + "#0 " + quantity;
  for (const reg::Row& r : reg::compare(b, m, reg::TimingCheck{}))
    if (r.quantity == row) return r.status;
  FAIL("no row " << row);
  return reg::Status::Fail;
}

reg::Status selfContact(bool stopped, double shift, double accuracy) {
  return pointRow("SC", stopped, shift, accuracy, "", "", "lambda");
}

reg::Status bifurcation(bool stopped, const std::string& postBuckling) {
  return pointRow("BP", stopped, 0.0, 1e-13, "supercritical", postBuckling, "post_buckling");
}

}  // namespace

TEST_CASE("regress: a stopped run's point agrees within the accuracy it states, a complete run's within the baseline's",
          "[regress]") {
  // located as well as the baseline: agrees either way
  CHECK(selfContact(false, 1e-13, 1e-13) == reg::Status::Pass);
  CHECK(selfContact(true, 1e-13, 1e-13) == reg::Status::Pass);
  // stopped while locating: reported to the point spacing 3e-4, 2.9e-4 off
  CHECK(selfContact(true, 2.9e-4, 3e-4) == reg::Status::Pass);
  CHECK(selfContact(true, 2.9e-4, 1e-5) == reg::Status::Fail);  // more off than it claims
  // a complete run that got worse fails, whatever accuracy it states
  CHECK(selfContact(false, 2.9e-4, 3e-4) == reg::Status::Fail);
}

TEST_CASE("regress: a stopped run may not have traced a branch point's branches, a complete run must",
          "[regress]") {
  CHECK(bifurcation(true, "") == reg::Status::Info);
  CHECK(bifurcation(false, "") == reg::Status::Fail);
  CHECK(bifurcation(true, "supercritical") == reg::Status::Pass);
  CHECK(bifurcation(true, "subcritical") == reg::Status::Fail);
  CHECK(bifurcation(false, "subcritical") == reg::Status::Fail);
}
