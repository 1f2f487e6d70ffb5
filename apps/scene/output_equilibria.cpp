#include "scene/output_equilibria.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "scene/json_values.h"

namespace buckle::scene {

namespace {

using nlohmann::json;

json equilibriumJson(const mechanics::FoundEquilibrium& e, const mechanics::EndCondition& end) {
  json j{{"q", jsonVector(e.q)},
         {"index", e.index},
         {"stable", e.stable},
         {"potential", jsonNumber(e.potential)},
         {"shape", e.shape},
         {"loads", wrenchJson(e.wrench)},
         {"pose", poseJson(e.pose)},
         {"accuracy", jsonNumber(e.accuracy)},
         {"by_deflation", e.byDeflation},
         {"by_sweep", e.bySweep}};
  if (e.zeroEigenvalues > 0) j["zero_eigenvalues"] = e.zeroEigenvalues;
  const std::vector<int> held = end.heldIndices();
  if (!held.empty()) {
    json r = json::object();
    for (size_t k = 0; k < held.size(); ++k) r[kEndLoadNames[held[k]]] = jsonNumber(e.reactions[Eigen::Index(k)]);
    j["reactions"] = r;
  }
  return j;
}

}  // namespace

json equilibriaJson(const RunResult& run) {
  json out = json::array();
  for (size_t c = 0; c < run.cases.size(); ++c)
    for (const EquilibriumSet& set : run.cases[c].equilibriumSets) {
    const CaseResult& cr = run.cases[c];
    const mechanics::AllEquilibria& a = set.found;
    json list = json::array();
    for (size_t i = 0; i < a.equilibria.size(); ++i) {
      list.push_back(equilibriumJson(a.equilibria[i], a.endCondition));
      // the id of a branch through it (branches traced: "branches": true), null when none
      if (!set.onBranch.empty()) list.back()["branch"] = set.onBranch[i] >= 0 ? json(set.onBranch[i]) : json(nullptr);
    }
    int stable = 0;
    for (const mechanics::FoundEquilibrium& e : a.equilibria) stable += e.stable;
    json held = json::array();
    for (int k : a.endCondition.heldIndices()) held.push_back(kEndCoordinateNames[k]);
    out.push_back(json{{"case", c},
                       {"case_label", cr.label},
                       {"at", jsonNumber(set.at)},
                       {"held", held},
                       {"count", a.equilibria.size()},
                       {"stable_count", stable},
                       {"method", a.method},
                       {"guarantee", a.guarantee},
                       {"starts", a.starts},
                       {"newton_runs", a.newtonRuns},
                       {"newton_failures", a.newtonFailures},
                       {"duplicates", a.duplicates},
                       {"outside_limits", a.outsideLimits},
                       {"sweep_count", a.sweepCount},
                       {"sweep_refined", a.sweepRefined},
                       {"deflation_only", a.deflationOnly},
                       {"sweep_only", a.sweepOnly},
                       {"morse", json{{"applies", a.morse.applies},
                                      {"sum", a.morse.sum},
                                      {"expected", a.morse.expected},
                                      {"holds", a.morse.holds()},
                                      {"loops", a.morse.loops},
                                      {"arcs", a.morse.arcs},
                                      {"basis", a.morse.basis}}},
                       {"interrupted", a.interrupted},
                       {"equilibria", list}});
  }
  return out;
}

std::string equilibriaCsv(const RunResult& run) {
  int maxN = 0;
  bool branches = false;  // the branches through the equilibria were traced: their ids
  for (const CaseResult& cr : run.cases)
    for (const EquilibriumSet& set : cr.equilibriumSets) {
      maxN = std::max(maxN, cr.chain.size());
      branches = branches || !set.onBranch.empty();
    }
  std::ostringstream os;
  os.precision(15);
  os << "case,at,rank,potential,index,stable,shape,Fx,Fy,Me,x,y,phi,accuracy";
  if (branches) os << ",branch";
  for (int i = 1; i <= maxN; ++i) os << ",q" << i;
  os << "\n";
  for (size_t c = 0; c < run.cases.size(); ++c)
    for (const EquilibriumSet& set : run.cases[c].equilibriumSets) {
    int rank = 0;
    for (const mechanics::FoundEquilibrium& e : set.found.equilibria) {
      os << c << ',' << set.at << ',' << ++rank << ',' << e.potential << ',' << e.index << ',' << (e.stable ? 1 : 0) << ',' << e.shape;
      for (int k = 0; k < 3; ++k) os << ',' << e.wrench[k];
      for (int k = 0; k < 3; ++k) os << ',' << e.pose[k];
      os << ',' << e.accuracy;
      if (branches) {
        const size_t i = size_t(rank - 1);
        os << ',';  // empty: no branch through it (or not traced in this case)
        if (i < set.onBranch.size() && set.onBranch[i] >= 0) os << set.onBranch[i];
      }
      for (int i = 0; i < maxN; ++i) {
        os << ',';
        if (i < e.q.size()) os << e.q[i];
      }
      os << "\n";
    }
  }
  return os.str();
}

}  // namespace buckle::scene
