#include "regress/compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

#include "regress/sampling.h"

namespace buckle::regress {

const char* toString(Status s) {
  switch (s) {
    case Status::Pass: return "PASS";
    case Status::Fail: return "FAIL";
    case Status::Info: return "INFO";
  }
  return "?";
}

namespace {

std::string fmt(const char* format, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

std::string value(double x) { return fmt("%.12g", x); }
std::string small(double x) { return fmt("%.2e", x); }

/// One numeric quantity: drift |now − baseline| against the tolerance.
Row numeric(const std::string& name, const std::string& quantity, double base, double now, double allowed) {
  const double drift = std::abs(now - base);
  return {name, quantity, value(base), value(now), small(drift), small(allowed),
          drift <= allowed ? Status::Pass : Status::Fail};
}

std::string where(int branch) { return branch >= 0 ? "b" + std::to_string(branch) + " " : ""; }

Row missing(const std::string& name, const std::string& quantity, const std::string& base, const std::string& now) {
  return {name, quantity, base, now, "-", "-", Status::Fail};
}

/// `partial`: the run was stopped by a time limit, so what the complete run has beyond what was
/// computed is not a failure (INFO "not reached"); everything computed must still agree, to the
/// accuracy the stopped run states for it.
void compareCase(const std::string& name, const std::string& prefix, const CaseEntry& c, const MeasuredCase& m,
                 const TolerancePolicy& policy, bool partial, std::vector<Row>& rows) {
  const int branches = int(m.branches.size());
  const bool branchesOk = partial ? branches <= c.branches : branches == c.branches;
  rows.push_back({name, prefix + "branches", std::to_string(c.branches), std::to_string(branches), std::to_string(branches - c.branches),
                  partial ? "<= baseline" : "0", branchesOk ? Status::Pass : Status::Fail});

  // special points matched by branch, type and order along the branch
  std::map<std::tuple<int, std::string, int>, SpecialEntry> now;
  for (const SpecialEntry& s : numberSpecials(m, policy)) now[{s.branch, s.type, s.order}] = s;
  for (const SpecialEntry& s : c.specials) {
    const std::string q = prefix + where(s.branch) + s.type + "#" + std::to_string(s.order);
    const auto it = now.find({s.branch, s.type, s.order});
    if (it == now.end()) {
      rows.push_back(missing(name, q, value(s.lambda), partial ? "not reached" : "missing"));
      if (partial) rows.back().status = Status::Info;
      continue;
    }
    // A stopped run may report a point whose location the stop cut short, to the accuracy it
    // states (e.g. the point spacing): agreement within that is a correct partial answer. A
    // complete run keeps the baseline's allowance, so a location that got worse still fails.
    const double allowed = partial ? std::max(s.tolerance.allowed(s.lambda), it->second.tolerance.allowed(it->second.lambda))
                                   : s.tolerance.allowed(s.lambda);
    rows.push_back(numeric(name, q + " lambda", s.lambda, it->second.lambda, allowed));
    rows.push_back({name, q + " shape", s.shape, it->second.shape, s.shape == it->second.shape ? "-" : "differs", "equal",
                    s.shape == it->second.shape ? Status::Pass : Status::Fail});
    if (!s.postBuckling.empty()) {
      const bool same = s.postBuckling == it->second.postBuckling;
      rows.push_back({name, q + " post_buckling", s.postBuckling, it->second.postBuckling.empty() ? "none" : it->second.postBuckling,
                      same ? "-" : "differs", "equal", same ? Status::Pass : Status::Fail});
      // the direction is known once the branch point's branches are traced: a run stopped
      // before that has not reached it (a different direction still fails)
      if (partial && it->second.postBuckling.empty()) {
        rows.back().now = "not reached";
        rows.back().drift = "-";
        rows.back().status = Status::Info;
      }
    }
    now.erase(it);
  }
  for (const auto& [key, s] : now)
    rows.push_back(missing(name, prefix + where(s.branch) + s.type + "#" + std::to_string(s.order),
                           "none", "new at " + value(s.lambda)));

  // branch samples at the recorded λ; the allowance grows with this run's own interpolation
  // error so that a change of step sizes alone cannot fail a sample
  for (const SampleEntry& s : c.samples) {
    const std::string q = prefix + "b" + std::to_string(s.branch) + " @" + fmt("%.6g", s.lambda) +
                          (s.crossing ? "#" + std::to_string(s.crossing) : "");
    const MeasuredBranch* br = nullptr;
    for (const MeasuredBranch& b : m.branches)
      if (b.id == s.branch) br = &b;
    const SampleValue v = br ? sampleAt(*br, {s.lambda, s.crossing}, s.coordinates) : SampleValue{};
    if (!v.found) {
      rows.push_back(missing(name, q, "on branch", br ? "branch does not reach it" : "no such branch"));
      if (partial) rows.back().status = Status::Info;
      continue;
    }
    for (size_t k = 0; k < s.values.size(); ++k) {
      const double allowed = std::max(s.tolerance.allowed(s.values[k]), policy.sampleErrorFactor * v.errorEstimate);
      rows.push_back(numeric(name, q + " q" + std::to_string(s.coordinates[k] + 1), s.values[k], v.values[k], allowed));
    }
  }
}

}  // namespace

std::vector<Row> compare(const Baseline& b, const Measurement& m, const TimingCheck& timing) {
  std::vector<Row> rows;
  const bool limited = b.source.timeLimit > 0.0;
  if (limited) {
    // the run must have been stopped by its limit, and on time: within one step of it
    const double t = m.seconds.empty() ? 0.0 : m.seconds.front();
    const double allowed = b.source.timeLimit + timing.stopSlackSeconds;
    rows.push_back({b.name, "stopped by the time limit", "yes", m.interrupted ? "yes" : "no", "-", "-",
                    m.interrupted ? Status::Pass : Status::Fail});
    rows.push_back({b.name, "stopped on time", fmt("<= %.3g s", allowed), fmt("%.3g s", t), "-", "-",
                    t <= allowed ? Status::Pass : Status::Fail});
  } else if (!m.complete) {
    std::string why;
    for (const std::string& p : m.problems) why += (why.empty() ? "" : "; ") + p;
    rows.push_back({b.name, "run complete", "yes", "no: " + why, "-", "-", Status::Fail});
  }
  std::map<std::string, const MeasuredCase*> now;
  for (const MeasuredCase& c : m.cases) now[c.label] = &c;
  for (const CaseEntry& c : b.cases) {
    const std::string prefix = c.label == b.name || (b.cases.size() == 1 && c.label == "main") ? "" : c.label + ": ";
    const auto it = now.find(c.label);
    if (it == now.end()) {
      rows.push_back(missing(b.name, prefix + "case", c.label, "missing"));
      continue;
    }
    compareCase(b.name, prefix, c, *it->second, b.policy, limited && m.interrupted, rows);
    now.erase(it);
  }
  for (const auto& [label, c] : now) rows.push_back(missing(b.name, label + ": case", "none", "new"));

  const double t = m.medianSeconds(), ref = b.referenceSeconds;
  Row time{b.name, "time (median of " + std::to_string(m.seconds.size()) + ")", fmt("%.3g s", ref), fmt("%.3g s", t),
           ref > 0 ? fmt("x%.2f", t / ref) : "-", "-", Status::Info};
  if (timing.factor > 0) {
    time.tolerance = fmt("x%g", timing.factor) + fmt(" +%gs", timing.slackSeconds);
    time.status = t <= timing.factor * ref + timing.slackSeconds ? Status::Pass : Status::Fail;
  }
  rows.push_back(time);
  return rows;
}

}  // namespace buckle::regress
