#include "scene/scene.h"
#include "scene/json_reader.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <nlohmann/json.hpp>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/unloaded_shape.h"

namespace buckle::scene {

using nlohmann::json;
using Pointer = json::json_pointer;

const char* plotTypeName(PlotType t) {
  switch (t) {
    case PlotType::Bifurcation: return "bifurcation";
    case PlotType::Stiffness: return "stiffness";
    case PlotType::EnergyCurves: return "energy_curves";
    case PlotType::TorqueAngle: return "torque_angle";
    case PlotType::Shapes: return "shapes";
    case PlotType::SuddenLoad: return "sudden_load";
  }
  return "?";
}

int Scene::maxSegments() const {
  int n = 0;
  for (const CaseSpec& c : cases) n = std::max(n, static_cast<int>(c.chain.segments.size()));
  return n;
}

namespace {

using Reader = JsonReader;

const char* const kCoordinateNames[3] = {"x", "y", "phi"};
const char* const kLoadNames[3] = {"Fx", "Fy", "Me"};

int coordinateOfParameter(const std::string& s, bool& isLoad) {
  for (int c = 0; c < 3; ++c) {
    if (s == kLoadNames[c]) {
      isLoad = true;
      return c;
    }
    if (s == kCoordinateNames[c]) {
      isLoad = false;
      return c;
    }
  }
  return -1;
}

// ---- chain ------------------------------------------------------------------------------------

const std::set<std::string> kSegmentKeys = {"a", "b", "k", "L0", "a1", "b1", "a2", "b2", "k1", "k2",
                                            "L1_0", "L2_0", "q_min", "q_max", "q0"};

struct SegmentDefaults {
  std::map<std::string, double> values;  // resolved names a1..L2_0, q_min, q_max, q0
  std::map<std::string, Pointer> source; // where the user set each of them (absent: the default)
};

// Applies the keys of one object (chain level or segment level) on top of `d`.
void applySegmentKeys(const Reader& r, const json& obj, const Pointer& p, SegmentDefaults& d) {
  static const std::map<std::string, std::vector<std::string>> generic = {
      {"a", {"a1", "a2"}}, {"b", {"b1", "b2"}}, {"k", {"k1", "k2"}}, {"L0", {"L1_0", "L2_0"}}};
  // generic keys first, specific ones override
  for (const auto& [key, targets] : generic) {
    if (!obj.contains(key)) continue;
    const Pointer q = p / key;
    double v = 0;
    if (key == "a")
      v = r.nonNegative(obj[key], q);
    else
      v = r.positive(obj[key], q);
    for (const std::string& t : targets) {
      d.values[t] = v;
      d.source[t] = q;
    }
  }
  auto set = [&](const char* key, double v) {
    d.values[key] = v;
    d.source[key] = p / key;
  };
  for (const char* key : {"a1", "a2"})
    if (obj.contains(key)) set(key, r.nonNegative(obj[key], p / key));
  for (const char* key : {"b1", "b2", "k1", "k2", "L1_0", "L2_0"})
    if (obj.contains(key)) set(key, r.positive(obj[key], p / key));
  for (const char* key : {"q_min", "q_max", "q0"})
    if (obj.contains(key)) set(key, r.number(obj[key], p / key));
}

mechanics::SegmentParameters toParameters(const SegmentDefaults& d) {
  mechanics::SegmentParameters s;
  s.a1 = d.values.at("a1");
  s.a2 = d.values.at("a2");
  s.b1 = d.values.at("b1");
  s.b2 = d.values.at("b2");
  s.k1 = d.values.at("k1");
  s.k2 = d.values.at("k2");
  s.L1_0 = d.values.at("L1_0");
  s.L2_0 = d.values.at("L2_0");
  if (d.values.count("q_min")) s.qMinUser = d.values.at("q_min");
  if (d.values.count("q_max")) s.qMaxUser = d.values.at("q_max");
  return s;
}

// The user's key most likely to blame among `names` of one segment: the value farthest from the
// chain's units (b for lengths, k for stiffnesses) by orders of magnitude. A half-height a
// smaller than its b cannot push anything out of range, so it is passed over.
std::optional<Pointer> mostExtremeKey(const SegmentDefaults& d, const std::vector<std::string>& names) {
  std::optional<Pointer> worst;
  double worstOrders = -1.0;
  for (const std::string& name : names) {
    const auto src = d.source.find(name);
    if (src == d.source.end()) continue;
    const double v = d.values.at(name);
    if (name[0] == 'a' && v <= d.values.at(name == "a1" ? "b1" : "b2")) continue;
    const double orders = std::abs(std::log10(v));
    if (orders > worstOrders) {
      worstOrders = orders;
      worst = src->second;
    }
  }
  return worst;
}

std::string show(double v) {
  std::ostringstream os;
  os << std::setprecision(6) << v;
  return os.str();
}

// Checks a segment as the mechanics will use it and names the user's key when it cannot work:
// the triangles must leave the joint a range of motion (β12 < π, eq 1), the user limits must
// overlap it, and the spring model must stay inside the floating-point range at the unloaded
// angle (it forms products of four lengths: b = 1e300 overflows, b = 1e-200 underflows to a
// zero spring length).
void checkSegment(const Reader& r, const SegmentDefaults& d, const Pointer& where, double q0) {
  mechanics::SegmentParameters sp = toParameters(d);
  auto blame = [&](const std::vector<std::string>& names) {
    const std::optional<Pointer> key = mostExtremeKey(d, names);
    return key ? *key : where;
  };
  const double qMin = sp.qMinUser, qMax = sp.qMaxUser;
  sp.qMinUser = -std::numeric_limits<double>::infinity();
  sp.qMaxUser = std::numeric_limits<double>::infinity();
  const double betaSum = std::atan(sp.a1 / sp.b1) + std::atan(sp.a2 / sp.b2);
  if (!(betaSum < M_PI))
    r.fail(blame({"a1", "b1", "a2", "b2"}),
           "expected a smaller half-height a against the half-length b: with a1/b1 = " + show(sp.a1 / sp.b1) +
               " and a2/b2 = " + show(sp.a2 / sp.b2) +
               " the triangles' angles atan(a1/b1) + atan(a2/b2) reach pi and the joint has no range of motion");
  const mechanics::Segment geometric(sp);
  const double lo = std::max(geometric.geometricLowerLimit(), qMin);
  const double hi = std::min(geometric.geometricUpperLimit(), qMax);
  if (!(lo < hi)) {
    const bool minWrong = d.source.count("q_min") && (qMin >= geometric.geometricUpperLimit() || qMin >= qMax);
    const Pointer at = minWrong ? d.source.at("q_min") : d.source.count("q_max") ? d.source.at("q_max") : where;
    r.fail(at, "expected joint limits q_min < q_max that overlap the geometric range (" +
                   show(geometric.geometricLowerLimit()) + ", " + show(geometric.geometricUpperLimit()) +
                   ") rad, got q_min = " + show(qMin) + ", q_max = " + show(qMax));
  }
  const mechanics::Jet3 e = geometric.energyJet(q0 > lo && q0 < hi ? q0 : 0.5 * (lo + hi));
  if (!(std::isfinite(e.value) && std::isfinite(e.d1) && std::isfinite(e.d2) && std::isfinite(e.d3)))
    r.fail(blame({"a1", "b1", "a2", "b2", "L1_0", "L2_0", "k1", "k2"}),
           "out of the range the spring model can compute: with these values its energy at the unloaded "
           "shape is not a finite number (lengths are in units of b, stiffnesses in k: give values near 1)");
}

ChainSpec parseChain(const Reader& r, const json& chain, const Pointer& p) {
  std::set<std::string> keys = kSegmentKeys;
  keys.insert("segments");
  r.onlyKeys(chain, p, keys);
  if (!chain.contains("segments")) r.fail(p / "segments", "missing: expected the segment count (an integer >= 1) or a list of segments");

  SegmentDefaults base;
  base.values = {{"a1", 0.5}, {"a2", 0.5}, {"b1", 1.0}, {"b2", 1.0}, {"k1", 1.0},
                 {"k2", 1.0}, {"L1_0", 2.25}, {"L2_0", 2.25}};
  json chainLevel = chain;
  chainLevel.erase("segments");
  chainLevel.erase("q0");
  applySegmentKeys(r, chainLevel, p, base);

  const json& segs = chain["segments"];
  const Pointer ps = p / "segments";
  std::vector<SegmentDefaults> resolved;
  std::vector<Pointer> segPointers;
  if (segs.is_number()) {
    const int n = r.integer(segs, ps, 1, kMaxSegments);
    resolved.assign(size_t(n), base);
    segPointers.assign(size_t(n), p);
  } else if (segs.is_array()) {
    if (segs.empty()) r.expected(ps, segs, "a segment count >= 1 or a non-empty list of segments");
    // the same cap as for a count: a list is no way around it
    if (segs.size() > size_t(kMaxSegments))
      r.fail(ps, "expected at most " + std::to_string(kMaxSegments) + " segments, got a list of " +
                     std::to_string(segs.size()));
    for (size_t i = 0; i < segs.size(); ++i) {
      const Pointer pi = ps / i;
      r.onlyKeys(segs[i], pi, kSegmentKeys);
      SegmentDefaults d = base;
      applySegmentKeys(r, segs[i], pi, d);
      resolved.push_back(d);
      segPointers.push_back(pi);
    }
  } else {
    r.expected(ps, segs, "a segment count (integer >= 1) or a list of segment objects");
  }
  const size_t n = resolved.size();

  // desired unloaded angles: chain-level list, or per-segment "q0"
  Eigen::VectorXd q0 = Eigen::VectorXd::Zero(Eigen::Index(n));
  std::vector<Pointer> q0Pointers(n);
  bool haveQ0 = false;
  if (chain.contains("q0")) {
    const json& v = chain["q0"];
    const Pointer pq = p / "q0";
    if (!v.is_array() || v.size() != n)
      r.expected(pq, v, "an array of " + std::to_string(n) + " angles (radians), one per segment");
    for (size_t i = 0; i < n; ++i) {
      q0[Eigen::Index(i)] = r.number(v[i], pq / i);
      q0Pointers[i] = pq / i;
    }
    haveQ0 = true;
  }
  for (size_t i = 0; i < n; ++i) {
    if (resolved[i].values.count("q0") && segs.is_array() && segs[i].contains("q0")) {
      if (chain.contains("q0")) r.fail(segPointers[i] / "q0", "q0 given both per segment and as /chain/q0");
      q0[Eigen::Index(i)] = resolved[i].values.at("q0");
      q0Pointers[i] = segPointers[i] / "q0";
      haveQ0 = true;
    }
  }

  ChainSpec spec;
  spec.q0 = q0;
  for (size_t i = 0; i < n; ++i) {
    // the same parameters for every segment of a count: one check does
    if (i == 0 || segs.is_array()) checkSegment(r, resolved[i], segPointers[i], haveQ0 ? q0[Eigen::Index(i)] : 0.0);
    mechanics::SegmentParameters sp = toParameters(resolved[i]);
    if (haveQ0 && q0[Eigen::Index(i)] != 0.0) {
      mechanics::Segment seg(sp);
      const double qi = q0[Eigen::Index(i)];
      if (!(qi > seg.lowerLimit() && qi < seg.upperLimit())) {
        std::ostringstream os;
        os << "expected an angle inside the joint limits (" << seg.lowerLimit() << ", " << seg.upperLimit()
           << ") rad, got " << qi;
        r.fail(q0Pointers[i], os.str());
      }
      try {
        sp = mechanics::preloadsForAngle(sp, qi).parameters;
      } catch (const std::invalid_argument& e) {
        r.fail(q0Pointers[i], e.what());
      }
      spec.preloadsFromQ0 = true;
    }
    spec.segments.push_back(sp);
  }
  return spec;
}

// ---- end and path -----------------------------------------------------------------------------

EndSpec parseEnd(const Reader& r, const json& end, const Pointer& p) {
  r.onlyKeys(end, p, {"x", "y", "phi"});
  EndSpec spec;
  for (int c = 0; c < 3; ++c) {
    spec.condition.control[size_t(c)] = mechanics::Control::Load;
    spec.condition.value[c] = 0.0;
    if (!end.contains(kCoordinateNames[c])) continue;
    const json& v = end[kCoordinateNames[c]];
    const Pointer pc = p / kCoordinateNames[c];
    const std::string what = "\"free\", {\"load\": number} or {\"held\": number | \"start\"}";
    if (v.is_string()) {
      if (v.get<std::string>() != "free") r.expected(pc, v, what);
      continue;
    }
    if (!v.is_object() || v.size() != 1) r.expected(pc, v, what);
    if (v.contains("load")) {
      spec.condition.value[c] = r.number(v["load"], pc / "load");
    } else if (v.contains("held")) {
      spec.condition.control[size_t(c)] = mechanics::Control::Held;
      const json& h = v["held"];
      if (h.is_string()) {
        if (h.get<std::string>() != "start") r.expected(pc / "held", h, "a number or \"start\"");
        spec.heldAtStart[size_t(c)] = true;
      } else {
        spec.condition.value[c] = r.number(h, pc / "held");
      }
    } else {
      r.fail(pc / v.begin().key(), "unknown key \"" + v.begin().key() + "\" (allowed here: load, held)");
    }
  }
  return spec;
}

PathSpec parsePath(const Reader& r, const json& path, const Pointer& p, const EndSpec& end, double startValue) {
  r.onlyKeys(path, p, {"parameter", "from", "to", "direction", "load_limit"});
  for (const char* key : {"parameter", "from", "to"})
    if (!path.contains(key)) r.fail(p / key, "missing (required)");
  PathSpec spec;
  spec.parameter = r.string(path["parameter"], p / "parameter");
  bool isLoad = false;
  spec.coordinate = coordinateOfParameter(spec.parameter, isLoad);
  if (spec.coordinate < 0) r.expected(p / "parameter", path["parameter"], "one of Fx, Fy, Me, x, y, phi");
  const bool held = end.condition.isHeld(static_cast<mechanics::EndCoordinate>(spec.coordinate));
  if (isLoad && held)
    r.fail(p / "parameter", std::string("the load ") + spec.parameter + " cannot be the parameter: /end/" +
                                kCoordinateNames[spec.coordinate] + " is held (use \"" +
                                kCoordinateNames[spec.coordinate] + "\" or make it loaded)");
  if (!isLoad && !held)
    r.fail(p / "parameter", std::string("the coordinate ") + spec.parameter + " cannot be the parameter: /end/" +
                                spec.parameter + " is not held (use {\"held\": value} there, or the load " +
                                kLoadNames[spec.coordinate] + ")");
  spec.from = r.number(path["from"], p / "from");
  spec.to = r.number(path["to"], p / "to");
  if (spec.from == spec.to) r.fail(p / "to", "expected a value different from /path/from (an empty range)");
  const double lo = std::min(spec.from, spec.to), hi = std::max(spec.from, spec.to);
  if (!(startValue >= lo - 1e-12 && startValue <= hi + 1e-12)) {
    std::ostringstream os;
    os << "expected a range [from, to] that contains the start value " << spec.parameter << " = " << startValue
       << " (set by /end/" << kCoordinateNames[spec.coordinate] << "), got [" << spec.from << ", " << spec.to << "]";
    r.fail(p / (std::abs(spec.from - startValue) <= std::abs(spec.to - startValue) ? "from" : "to"), os.str());
  }
  if (path.contains("load_limit")) {
    if (isLoad)
      r.fail(p / "load_limit", "only a displacement-controlled path (parameter x, y or phi) takes a load_limit");
    spec.loadLimit = r.positive(path["load_limit"], p / "load_limit");
  }
  spec.direction.setZero();
  spec.direction[spec.coordinate] = 1.0;
  if (path.contains("direction")) {
    const json& d = path["direction"];
    const Pointer pd = p / "direction";
    r.requireObject(d, pd);
    for (auto it = d.begin(); it != d.end(); ++it) {
      bool keyIsLoad = false;
      const int c = coordinateOfParameter(it.key(), keyIsLoad);
      if (c < 0) r.fail(pd / it.key(), "unknown key \"" + it.key() + "\" (allowed here: Fx, Fy, Me, x, y, phi)");
      if (c == spec.coordinate)
        r.fail(pd / it.key(), "the path parameter's own rate is 1 by definition; remove this key");
      const bool cHeld = end.condition.isHeld(static_cast<mechanics::EndCoordinate>(c));
      if (keyIsLoad == cHeld)
        r.fail(pd / it.key(), std::string("expected ") + (cHeld ? kCoordinateNames[c] : kLoadNames[c]) +
                                  ": /end/" + kCoordinateNames[c] + " is " + (cHeld ? "held" : "loaded"));
      spec.direction[c] = r.number(it.value(), pd / it.key());
    }
  }
  return spec;
}

CaseSpec parseCase(const Reader& r, const json& doc, const std::string& label, bool needPath) {
  CaseSpec cs;
  cs.label = label;
  if (!doc.contains("chain")) r.fail(Pointer("/chain"), "missing (required): the chain to model");
  cs.chain = parseChain(r, doc["chain"], Pointer("/chain"));
  cs.end = parseEnd(r, doc.contains("end") ? doc["end"] : json::object(), Pointer("/end"));
  // "held": "start" takes the unloaded shape's end pose
  mechanics::Chain chain(cs.chain.segments);
  const mechanics::Pose pose0 = mechanics::endPose(chain, cs.chain.q0);
  for (int c = 0; c < 3; ++c)
    if (cs.end.heldAtStart[size_t(c)]) cs.end.condition.value[c] = pose0[c];
  if (!doc.contains("path")) {
    if (needPath)
      r.fail(Pointer("/path"), "missing (required by /analyses/continuation and /analyses/critical_forces): the load path");
    cs.path.parameter = "Fx";
    cs.path.coordinate = 0;
    cs.path.direction = Eigen::Vector3d(1.0, 0.0, 0.0);
    cs.path.from = cs.path.to = cs.end.condition.value[0];
    if (cs.end.condition.isHeld(mechanics::EndCoordinate::X)) cs.path.parameter = "x";
    return cs;
  }
  const json& path = doc["path"];
  r.requireObject(path, Pointer("/path"));
  double start = 0.0;
  if (path.contains("parameter") && path["parameter"].is_string()) {
    bool isLoad = false;
    const int c = coordinateOfParameter(path["parameter"].get<std::string>(), isLoad);
    if (c >= 0) start = cs.end.condition.value[c];
  }
  cs.path = parsePath(r, path, Pointer("/path"), cs.end, start);
  if (cs.path.loadLimit == 0.0 && cs.end.condition.isHeld(static_cast<mechanics::EndCoordinate>(cs.path.coordinate))) {
    mechanics::ChainData data(chain);
    mechanics::forwardKinematics(chain, cs.chain.q0, data);
    mechanics::Matrix J(3, chain.size());
    mechanics::endJacobian(data, J);
    if (J.row(cs.path.coordinate).norm() <= 1e-9 * std::max(1.0, J.norm()))
      r.fail(Pointer("/path/parameter"),
             std::string("the unloaded shape cannot move its end along ") + kCoordinateNames[cs.path.coordinate] +
                 " to first order (e.g. the straight chain along x): displacement control starts at a singular "
                 "point; add /path/load_limit (the largest reaction to trace) so that the branches are traced "
                 "through the reaction force");
  }
  return cs;
}

// ---- analyses, solver, plots ------------------------------------------------------------------

AnalysesSpec parseAnalyses(const Reader& r, const json& a, const Pointer& p) {
  r.onlyKeys(a, p,
             {"continuation", "stiffness", "energy_curves", "critical_forces", "torque_angle", "jump", "load_history",
              "sudden_load"});
  AnalysesSpec s;
  if (a.contains("continuation")) {
    const json& c = a["continuation"];
    const Pointer pc = p / "continuation";
    if (c.is_boolean()) {
      s.continuation.enabled = c.get<bool>();
    } else {
      r.onlyKeys(c, pc, {"branch_switching"});
      s.continuation.enabled = true;
      if (c.contains("branch_switching"))
        s.continuation.branchSwitching = r.integer(c["branch_switching"], pc / "branch_switching", 0, 4);
    }
  }
  if (a.contains("stiffness")) {
    s.stiffness = r.boolean(a["stiffness"], p / "stiffness");
    if (s.stiffness && !s.continuation.enabled)
      r.fail(p / "stiffness", "stiffness is computed along the traced branches: it needs /analyses/continuation");
  }
  if (a.contains("energy_curves")) {
    const json& e = a["energy_curves"];
    const Pointer pe = p / "energy_curves";
    r.onlyKeys(e, pe, {"x", "y", "q1_from", "q1_to", "points", "torque"});
    s.energyCurves.enabled = true;
    if (!e.contains("x") || !e.contains("y")) r.fail(pe / (e.contains("x") ? "y" : "x"), "missing (required): the held end position");
    s.energyCurves.x = r.number(e["x"], pe / "x");
    s.energyCurves.y = r.number(e["y"], pe / "y");
    if (e.contains("q1_from")) s.energyCurves.q1From = r.number(e["q1_from"], pe / "q1_from");
    if (e.contains("q1_to")) s.energyCurves.q1To = r.number(e["q1_to"], pe / "q1_to");
    if (!(s.energyCurves.q1From < s.energyCurves.q1To)) r.fail(pe / "q1_to", "expected q1_to > q1_from");
    if (e.contains("points")) s.energyCurves.points = r.integer(e["points"], pe / "points", 3, 1000000);
    if (e.contains("torque")) s.energyCurves.torque = r.boolean(e["torque"], pe / "torque");
  }
  if (a.contains("torque_angle")) {
    const json& t = a["torque_angle"];
    const Pointer pt = p / "torque_angle";
    if (t.is_boolean()) {
      s.torqueAngle.enabled = t.get<bool>();
    } else {
      r.onlyKeys(t, pt, {"q_from", "q_to", "points"});
      s.torqueAngle.enabled = true;
      if (t.contains("q_from")) s.torqueAngle.qFrom = r.number(t["q_from"], pt / "q_from");
      if (t.contains("q_to")) s.torqueAngle.qTo = r.number(t["q_to"], pt / "q_to");
      if (!(s.torqueAngle.qFrom < s.torqueAngle.qTo)) r.fail(pt / "q_to", "expected q_to > q_from");
      if (t.contains("points")) s.torqueAngle.points = r.integer(t["points"], pt / "points", 3, 1000000);
    }
  }
  if (a.contains("critical_forces")) {
    const json& c = a["critical_forces"];
    const Pointer pc = p / "critical_forces";
    if (c.is_boolean()) {
      s.criticalForces.enabled = c.get<bool>();
    } else {
      r.onlyKeys(c, pc, {"modes"});
      s.criticalForces.enabled = true;
      if (c.contains("modes")) s.criticalForces.modes = r.integer(c["modes"], pc / "modes", 1, 100000);
    }
  }
  if (a.contains("jump")) {
    const json& j = a["jump"];
    const Pointer pj = p / "jump";
    if (j.is_boolean()) {
      s.jump.enabled = j.get<bool>();
    } else {
      r.onlyKeys(j, pj, {"perturbation"});
      s.jump.enabled = true;
      if (j.contains("perturbation")) s.jump.perturbation = r.positive(j["perturbation"], pj / "perturbation");
    }
    if (s.jump.enabled && !s.continuation.enabled)
      r.fail(pj, "jumps are simulated from the folds of the traced branches: it needs /analyses/continuation");
  }
  if (a.contains("load_history")) {
    const json& h = a["load_history"];
    const Pointer ph = p / "load_history";
    r.onlyKeys(h, ph, {"waypoints", "perturbation"});
    if (!h.contains("waypoints")) r.fail(ph / "waypoints", "missing (required): the path-parameter values to visit");
    const json& w = h["waypoints"];
    if (!w.is_array() || w.size() < 2) r.expected(ph / "waypoints", w, "an array of at least two numbers");
    for (size_t i = 0; i < w.size(); ++i) s.loadHistory.waypoints.push_back(r.number(w[i], ph / "waypoints" / i));
    if (h.contains("perturbation")) s.loadHistory.perturbation = r.positive(h["perturbation"], ph / "perturbation");
    s.loadHistory.enabled = true;
  }
  if (a.contains("sudden_load")) {
    const json& d = a["sudden_load"];
    const Pointer pd = p / "sudden_load";
    r.onlyKeys(d, pd, {"value", "mass_per_length", "damping"});
    if (!d.contains("value")) r.fail(pd / "value", "missing (required): the path-parameter value applied at once");
    s.suddenLoad.value = r.number(d["value"], pd / "value");
    if (d.contains("mass_per_length")) s.suddenLoad.massPerLength = r.positive(d["mass_per_length"], pd / "mass_per_length");
    if (d.contains("damping")) s.suddenLoad.damping = r.nonNegative(d["damping"], pd / "damping");
    if (d.contains("damping") && !d.contains("mass_per_length"))
      r.fail(pd / "damping", "joint damping belongs to the inertial model: give mass_per_length too");
    s.suddenLoad.enabled = true;
  }
  if (!s.continuation.enabled && !s.energyCurves.enabled && !s.torqueAngle.enabled && !s.criticalForces.enabled &&
      !s.loadHistory.enabled && !s.suddenLoad.enabled)
    r.fail(p, "expected at least one analysis (continuation, energy_curves, torque_angle, critical_forces, "
              "load_history, sudden_load)");
  return s;
}

SolverSpec parseSolver(const Reader& r, const json& s, const Pointer& p) {
  r.onlyKeys(s, p, {"initial_step", "min_step", "max_step", "tolerance", "max_points", "time_limit"});
  SolverSpec o;
  if (s.contains("initial_step")) o.initialStep = r.positive(s["initial_step"], p / "initial_step");
  if (s.contains("min_step")) o.minStep = r.positive(s["min_step"], p / "min_step");
  if (s.contains("max_step")) o.maxStep = r.positive(s["max_step"], p / "max_step");
  if (s.contains("tolerance")) o.tolerance = r.positive(s["tolerance"], p / "tolerance");
  if (s.contains("max_points")) o.maxPoints = r.integer(s["max_points"], p / "max_points", 2, 10000000);
  if (s.contains("time_limit")) o.timeLimit = r.positive(s["time_limit"], p / "time_limit");
  if (!(o.minStep <= o.initialStep)) r.fail(p / "min_step", "expected min_step <= initial_step");
  if (!(o.initialStep <= o.maxStep)) r.fail(p / "max_step", "expected max_step >= initial_step");
  return o;
}

std::set<std::string> branchColumns(int maxN, bool stiffness) {
  std::set<std::string> c = {"parameter", "Fx", "Fy", "Me", "x", "y", "phi", "dx", "dy", "min_eig"};
  for (int i = 1; i <= maxN; ++i) c.insert("q" + std::to_string(i));
  if (stiffness) c.insert({"Kxx", "Kyy", "Kxy"});
  return c;
}

PlotSpec parsePlot(const Reader& r, const json& v, const Pointer& p, const AnalysesSpec& a, int maxN, int nCases) {
  PlotSpec s;
  json obj = v;
  if (v.is_string()) obj = json{{"type", v}};
  r.onlyKeys(obj, p, {"type", "name", "x", "y", "at", "title", "cases"});
  if (obj.contains("cases")) {
    const json& cs = obj["cases"];
    if (!cs.is_array() || cs.empty()) r.expected(p / "cases", cs, "a non-empty array of case indices (0-based)");
    for (size_t i = 0; i < cs.size(); ++i) s.cases.push_back(r.integer(cs[i], p / "cases" / i, 0, nCases - 1));
  } else {
    for (int i = 0; i < nCases; ++i) s.cases.push_back(i);
  }
  if (!obj.contains("type")) r.fail(p / "type", "missing (required)");
  const Pointer pt = v.is_string() ? p : p / "type";
  const std::string type = r.string(obj["type"], pt);
  const std::map<std::string, PlotType> types = {{"bifurcation", PlotType::Bifurcation},
                                                 {"stiffness", PlotType::Stiffness},
                                                 {"energy_curves", PlotType::EnergyCurves},
                                                 {"torque_angle", PlotType::TorqueAngle},
                                                 {"shapes", PlotType::Shapes},
                                                 {"sudden_load", PlotType::SuddenLoad}};
  auto it = types.find(type);
  if (it == types.end())
    r.expected(pt, obj["type"], "one of bifurcation, stiffness, energy_curves, torque_angle, shapes, sudden_load");
  s.type = it->second;
  auto needs = [&](bool have, const char* analysis) {
    if (!have) r.fail(pt, std::string("a ") + type + " plot needs /analyses/" + analysis);
  };
  switch (s.type) {
    case PlotType::Bifurcation:
    case PlotType::Shapes: needs(a.continuation.enabled || a.loadHistory.enabled, "continuation (or load_history)"); break;
    case PlotType::Stiffness: needs(a.stiffness, "stiffness"); break;
    case PlotType::EnergyCurves: needs(a.energyCurves.enabled, "energy_curves"); break;
    case PlotType::TorqueAngle: needs(a.torqueAngle.enabled, "torque_angle"); break;
    case PlotType::SuddenLoad: needs(a.suddenLoad.enabled, "sudden_load"); break;
  }
  s.name = type;
  if (obj.contains("name")) {
    s.name = r.string(obj["name"], p / "name");
    const bool ok = !s.name.empty() && std::all_of(s.name.begin(), s.name.end(), [](char ch) {
      return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-';
    });
    if (!ok) r.expected(p / "name", obj["name"], "a file stem of letters, digits, '_' and '-'");
  }
  if (obj.contains("title")) s.title = r.string(obj["title"], p / "title");
  const bool columns = s.type == PlotType::Bifurcation || s.type == PlotType::Stiffness;
  if (!columns) {
    for (const char* key : {"x", "y"})
      if (obj.contains(key)) r.fail(p / key, std::string("a ") + type + " plot has fixed axes; remove this key");
  } else {
    const std::set<std::string> allowed = branchColumns(maxN, a.stiffness);
    std::string list;
    for (const std::string& c : allowed) list += (list.empty() ? "" : ", ") + c;
    auto column = [&](const json& c, const Pointer& pc) {
      const std::string name = r.string(c, pc);
      if (!allowed.count(name)) r.expected(pc, c, "a column of branches.csv (" + list + ")");
      return name;
    };
    s.x = obj.contains("x") ? column(obj["x"], p / "x") : "parameter";
    if (obj.contains("y")) {
      const json& y = obj["y"];
      if (y.is_array()) {
        if (y.empty()) r.expected(p / "y", y, "a column name or a non-empty list of them");
        for (size_t i = 0; i < y.size(); ++i) s.y.push_back(column(y[i], p / "y" / i));
      } else {
        s.y.push_back(column(y, p / "y"));
      }
    } else if (s.type == PlotType::Stiffness) {
      s.y = {"Kxx", "Kyy"};
    } else {
      s.y = {"q1"};
    }
  }
  if (s.type == PlotType::Shapes) {
    if (!obj.contains("at")) r.fail(p / "at", "missing (required): parameter values at which to draw the chain");
    const json& at = obj["at"];
    if (!at.is_array() || at.empty()) r.expected(p / "at", at, "a non-empty array of parameter values");
    for (size_t i = 0; i < at.size(); ++i) s.at.push_back(r.number(at[i], p / "at" / i));
  } else if (obj.contains("at")) {
    r.fail(p / "at", "only a shapes plot takes \"at\"");
  }
  return s;
}

// RFC 7386: `target` patched by `patch`, without first copying the parts of `target` that the
// patch replaces (a case replacing a long list of segments does not copy the base's).
json mergePatched(const json& target, const json& patch) {
  if (!patch.is_object()) return patch;
  json out = json::object();
  if (target.is_object())
    for (auto it = target.begin(); it != target.end(); ++it)
      if (!patch.contains(it.key())) out[it.key()] = *it;
  static const json kNone;
  for (auto it = patch.begin(); it != patch.end(); ++it) {
    if (it->is_null()) continue;  // null removes the member
    const bool had = target.is_object() && target.contains(it.key());
    out[it.key()] = mergePatched(had ? target[it.key()] : kNone, *it);
  }
  return out;
}

std::vector<PlotSpec> defaultPlots(const AnalysesSpec& a, int nCases) {
  std::vector<int> all;
  for (int i = 0; i < nCases; ++i) all.push_back(i);
  std::vector<PlotSpec> out;
  if (a.continuation.enabled || a.loadHistory.enabled)
    out.push_back({PlotType::Bifurcation, "bifurcation", "parameter", {"q1"}, {}, "", all});
  if (a.stiffness) out.push_back({PlotType::Stiffness, "stiffness", "parameter", {"Kxx", "Kyy"}, {}, "", all});
  if (a.energyCurves.enabled) out.push_back({PlotType::EnergyCurves, "energy_curves", "", {}, {}, "", all});
  if (a.torqueAngle.enabled) out.push_back({PlotType::TorqueAngle, "torque_angle", "", {}, {}, "", all});
  if (a.suddenLoad.enabled) out.push_back({PlotType::SuddenLoad, "sudden_load", "", {}, {}, "", all});
  return out;
}

}  // namespace

Scene parseScene(const std::string& text, const std::string& file) {
  const Reader r(file);
  const json doc = parseJsonDocument(text, file);
  r.onlyKeys(doc, Pointer(""), {"description", "chain", "end", "path", "cases", "analyses", "solver", "plots"});
  Scene scene;
  scene.file = file;
  if (doc.contains("description")) scene.description = r.string(doc["description"], Pointer("/description"));

  if (!doc.contains("analyses")) r.fail(Pointer("/analyses"), "missing (required): what to compute");
  scene.analyses = parseAnalyses(r, doc["analyses"], Pointer("/analyses"));
  const bool needPath = scene.analyses.continuation.enabled || scene.analyses.criticalForces.enabled ||
                        scene.analyses.loadHistory.enabled || scene.analyses.suddenLoad.enabled;

  // chain, end and path: what a case patches (copied key by key, not with the cases)
  json base = json::object();
  for (const char* key : {"chain", "end", "path"})
    if (doc.contains(key)) base[key] = doc[key];
  int totalSegments = 0;
  if (doc.contains("cases")) {
    const json& cases = doc["cases"];
    if (!cases.is_array() || cases.empty()) r.expected(Pointer("/cases"), cases, "a non-empty array of case objects");
    for (size_t i = 0; i < cases.size(); ++i) {
      const Pointer pi = Pointer("/cases") / i;
      r.onlyKeys(cases[i], pi, {"label", "chain", "end", "path"});
      std::string label = "case " + std::to_string(i + 1);
      if (cases[i].contains("label")) label = r.string(cases[i]["label"], pi / "label");
      json patch = cases[i];
      patch.erase("label");
      try {
        scene.cases.push_back(parseCase(r, mergePatched(base, patch), label, needPath));
      } catch (const SceneError& e) {
        // point into the case when the bad value came from it
        const Pointer bad(e.path().empty() ? "" : e.path());
        if (!e.path().empty() && patch.contains(bad)) throw SceneError(file, (pi / bad).to_string(), e.message());
        throw SceneError(file, e.path(), e.message() + " (in " + pi.to_string() + ", \"" + label + "\")");
      }
      totalSegments += static_cast<int>(scene.cases.back().chain.segments.size());
      if (totalSegments > kMaxSegments)
        r.fail(pi, "expected at most " + std::to_string(kMaxSegments) + " segments in all cases together, got " +
                       std::to_string(totalSegments) + " up to this case");
    }
  } else {
    scene.cases.push_back(parseCase(r, base, "main", needPath));
  }

  if (scene.analyses.energyCurves.enabled)
    for (size_t i = 0; i < scene.cases.size(); ++i)
      if (scene.cases[i].chain.segments.size() != 3)
        r.fail(Pointer("/analyses/energy_curves"),
               "energy curves E(q1) with the end held use the 3-segment inverse kinematics (eq 6): case \"" +
                   scene.cases[i].label + "\" has " + std::to_string(scene.cases[i].chain.segments.size()) +
                   " segments");
  if (scene.analyses.loadHistory.enabled) {
    // The history starts where the path starts and stays inside its range.
    const std::vector<double>& w = scene.analyses.loadHistory.waypoints;
    const Pointer pw = Pointer("/analyses/load_history/waypoints");
    for (const CaseSpec& c : scene.cases) {
      const double start = c.end.condition.value[c.path.coordinate];
      const double lo = std::min(c.path.from, c.path.to), hi = std::max(c.path.from, c.path.to);
      if (std::abs(w[0] - start) > 1e-12 * std::max(1.0, std::abs(start)))
        r.fail(pw / 0, "expected the start value " + c.path.parameter + " = " + std::to_string(start) + " of case \"" +
                           c.label + "\"");
      for (size_t i = 0; i < w.size(); ++i)
        if (w[i] < lo - 1e-12 || w[i] > hi + 1e-12)
          r.fail(pw / i, "expected a value inside the path range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
  }
  if (scene.analyses.suddenLoad.enabled)
    for (const CaseSpec& c : scene.cases) {
      const double lo = std::min(c.path.from, c.path.to), hi = std::max(c.path.from, c.path.to);
      const double v = scene.analyses.suddenLoad.value;
      if (v < lo - 1e-12 || v > hi + 1e-12)
        r.fail(Pointer("/analyses/sudden_load/value"),
               "expected a value inside the path range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      // The inertial model divides by the rods' masses m = ρ l and inertias m l²/12: both must be
      // ordinary (normal, finite) numbers.
      const double rho = scene.analyses.suddenLoad.massPerLength;
      if (rho > 0.0)
        for (const mechanics::LinkInertia& link : mechanics::InertiaData::uniformRods(mechanics::Chain(c.chain.segments), rho).links)
          if (!std::isnormal(link.mass) || !std::isnormal(link.inertia))
            r.fail(Pointer("/analyses/sudden_load/mass_per_length"),
                   "out of the range the inertial model can compute: the rods' masses rho l or inertias rho l^3/12 "
                   "(l the link lengths of case \"" + c.label + "\") are not ordinary finite numbers; got " + show(rho));
    }
  if (doc.contains("solver")) scene.solver = parseSolver(r, doc["solver"], Pointer("/solver"));
  if (doc.contains("plots")) {
    const json& plots = doc["plots"];
    if (!plots.is_array()) r.expected(Pointer("/plots"), plots, "an array of plot names or plot objects");
    std::set<std::string> names;
    for (size_t i = 0; i < plots.size(); ++i) {
      PlotSpec ps = parsePlot(r, plots[i], Pointer("/plots") / i, scene.analyses, scene.maxSegments(),
                              static_cast<int>(scene.cases.size()));
      if (!names.insert(ps.name).second)
        r.fail(Pointer("/plots") / i, "two plots named \"" + ps.name + "\": give one a distinct \"name\"");
      scene.plots.push_back(ps);
    }
  } else {
    scene.plots = defaultPlots(scene.analyses, static_cast<int>(scene.cases.size()));
  }
  return scene;
}

Scene loadScene(const std::string& file) { return parseScene(readInputFile(file), file); }

}  // namespace buckle::scene
