#include "scene/scene_parsing.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/unloaded_shape.h"

namespace buckle::scene::detail {

namespace {

using Reader = JsonReader;


int coordinateOfParameter(const std::string& s, bool& isLoad) {
  for (int c = 0; c < 3; ++c) {
    if (s == kEndLoadNames[c]) {
      isLoad = true;
      return c;
    }
    if (s == kEndCoordinateNames[c]) {
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
  // a subnormal stiffness (5e-324) makes every stiffness product zero: a singular Jacobian
  for (const char* key : {"k1", "k2"})
    if (!std::isnormal(d.values.at(key)))
      r.fail(d.source.count(key) ? d.source.at(key) : where,
             "expected a stiffness of at least 2.2e-308 (the smallest normal double; stiffnesses in any unit), got " +
                 show(d.values.at(key)));
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

SegmentDefaults defaultSegment() {
  SegmentDefaults d;
  d.values = {{"a1", 0.5}, {"a2", 0.5}, {"b1", 1.0}, {"b2", 1.0}, {"k1", 1.0}, {"k2", 1.0}, {"L1_0", 2.25}, {"L2_0", 2.25}};
  return d;
}

ChainSpec parseChain(const Reader& r, const json& chain, const Pointer& p) {
  std::set<std::string> keys = kSegmentKeys;
  keys.insert("segments");
  r.onlyKeys(chain, p, keys);
  if (!chain.contains("segments")) r.fail(p / "segments", "missing: expected the segment count (an integer >= 1) or a list of segments");

  SegmentDefaults base = defaultSegment();
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
    } else {
      const mechanics::Segment seg(sp);
      if (!(seg.lowerLimit() < 0.0 && seg.upperLimit() > 0.0)) {
        const bool minWrong = seg.lowerLimit() >= 0.0;
        const char* key = minWrong ? "q_min" : "q_max";
        const auto src = resolved[i].source.find(key);
        r.fail(src != resolved[i].source.end() ? src->second : segPointers[i],
               std::string("expected ") + (minWrong ? "q_min < 0" : "q_max > 0") +
                   ": the chain starts straight (q = 0), which must lie strictly inside the joint limits (" +
                   show(seg.lowerLimit()) + ", " + show(seg.upperLimit()) +
                   ") rad; or give /chain/q0, a start shape inside them");
      }
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
    if (!end.contains(kEndCoordinateNames[c])) continue;
    const json& v = end[kEndCoordinateNames[c]];
    const Pointer pc = p / kEndCoordinateNames[c];
    const std::string what = "\"free\", {\"load\": number} or {\"held\": number | \"start\"}";
    if (v.is_string()) {
      if (v.get<std::string>() != "free") r.expected(pc, v, what);
      continue;
    }
    if (!v.is_object() || v.empty()) r.expected(pc, v, what);
    for (auto it = v.begin(); it != v.end(); ++it)
      if (it.key() != "load" && it.key() != "held")
        r.fail(pc / it.key(), "unknown key \"" + it.key() + "\" (allowed here: load, held)");
    if (v.size() != 1) r.fail(pc, "expected one of load, held, got both (a coordinate is either loaded or held)");
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
  if (spec.coordinate < 0)
    r.expected(p / "parameter", path["parameter"], "one of Fx, Fy, Me, x, y, phi, or a control input L1_0, L2_0, L0, dL0");
  const bool held = end.condition.isHeld(static_cast<mechanics::EndCoordinate>(spec.coordinate));
  if (isLoad && held)
    r.fail(p / "parameter", std::string("the load ") + spec.parameter + " cannot be the parameter: /end/" +
                                kEndCoordinateNames[spec.coordinate] + " is held (use \"" +
                                kEndCoordinateNames[spec.coordinate] + "\" or make it loaded)");
  if (!isLoad && !held)
    r.fail(p / "parameter", std::string("the coordinate ") + spec.parameter + " cannot be the parameter: /end/" +
                                spec.parameter + " is not held (use {\"held\": value} there, or the load " +
                                kEndLoadNames[spec.coordinate] + ")");
  spec.from = r.number(path["from"], p / "from");
  spec.to = r.number(path["to"], p / "to");
  if (spec.from == spec.to) r.fail(p / "to", "expected a value different from /path/from (an empty range)");
  const double lo = std::min(spec.from, spec.to), hi = std::max(spec.from, spec.to);
  // rounding of a start taken from the unloaded shape's pose: relative to the values' size
  const double slack = 1e-12 * std::max({hi - lo, std::abs(lo), std::abs(hi)});
  if (!(startValue >= lo - slack && startValue <= hi + slack)) {
    std::ostringstream os;
    os << "expected a range [from, to] that contains the start value " << spec.parameter << " = " << startValue
       << " (set by /end/" << kEndCoordinateNames[spec.coordinate] << "), got [" << spec.from << ", " << spec.to << "]";
    r.fail(p / (std::abs(spec.from - startValue) <= std::abs(spec.to - startValue) ? "from" : "to"), os.str());
  }
  if (path.contains("load_limit")) {
    if (isLoad)
      r.fail(p / "load_limit", "only a displacement-controlled path (parameter x, y or phi) takes a load_limit");
    spec.loadLimit = r.positive(path["load_limit"], p / "load_limit");
    spec.throughReaction = true;
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
        r.fail(pd / it.key(), std::string("expected ") + (cHeld ? kEndCoordinateNames[c] : kEndLoadNames[c]) +
                                  ": /end/" + kEndCoordinateNames[c] + " is " + (cHeld ? "held" : "loaded"));
      spec.direction[c] = r.number(it.value(), pd / it.key());
    }
  }
  return spec;
}

// A held end coordinate the chain cannot reach, or a load beyond any the chain can carry in
// doubles, leaves the equilibrium equations without a solution the solver could find (KINSOL
// gives up with a code): answered here instead, before computing. The chain's own scales: its
// length L (the farthest the end gets from the base), the force unit k b and moment unit k b².
void checkEndAgainstChain(const Reader& r, const CaseSpec& cs) {
  const mechanics::Chain chain(cs.chain.segments);
  const double L = chain.length();
  double k = 0.0, b = 0.0;
  for (const mechanics::SegmentParameters& sp : cs.chain.segments) {
    k = std::max({k, sp.k1, sp.k2});
    b = std::max({b, sp.b1, sp.b2});
  }
  const mechanics::EndCondition& end = cs.end.condition;
  for (int c = 0; c < 2; ++c) {
    if (!end.isHeld(static_cast<mechanics::EndCoordinate>(c)) || cs.end.heldAtStart[size_t(c)]) continue;
    const double v = end.value[c];
    if (std::abs(v) > L * (1.0 + 1e-12))
      r.fail(Pointer("/end") / kEndCoordinateNames[c] / "held",
             std::string("expected a position the end can reach: |") + kEndCoordinateNames[c] + "| <= " + show(L) +
                 " (the length of the straight chain), got " + show(v));
  }
  if (end.isHeld(mechanics::EndCoordinate::X) && end.isHeld(mechanics::EndCoordinate::Y) &&
      !cs.end.heldAtStart[0] && !cs.end.heldAtStart[1] && std::hypot(end.value[0], end.value[1]) > L * (1.0 + 1e-12))
    r.fail(Pointer("/end/y/held"), "expected a position the end can reach: sqrt(x^2 + y^2) <= " + show(L) +
                                       " (the length of the straight chain), got (" + show(end.value[0]) + ", " +
                                       show(end.value[1]) + ")");
  // loads up to 1e12 of the chain's units: far beyond any equilibrium the springs can resist
  const double unit[3] = {k * b, k * b, k * b * b};
  const auto checkLoad = [&](int c, double v, const Pointer& at) {
    const double limit = 1e12 * unit[c];
    if (!(std::abs(v) <= limit))
      r.fail(at, std::string("expected a load |") + kEndLoadNames[c] + "| <= " + show(limit) + " (1e12 times the chain's " +
                     (c == 2 ? "moment unit k b^2" : "force unit k b") + "), got " + show(v));
  };
  for (int c = 0; c < 3; ++c)
    if (!end.isHeld(static_cast<mechanics::EndCoordinate>(c)))
      checkLoad(c, end.value[c], Pointer("/end") / kEndCoordinateNames[c] / "load");
  bool isLoad = false;
  const int c = coordinateOfParameter(cs.path.parameter, isLoad);
  if (c >= 0 && isLoad && cs.path.from != cs.path.to) {
    checkLoad(c, cs.path.from, Pointer("/path/from"));
    checkLoad(c, cs.path.to, Pointer("/path/to"));
  }
}

}  // namespace

CaseSpec parseCase(const Reader& r, const json& doc, const std::string& label, bool needPath) {
  CaseSpec cs;
  cs.label = label;
  if (!doc.contains("chain")) r.fail(Pointer("/chain"), "missing (required): the chain to model");
  cs.chain = parseChain(r, doc["chain"], Pointer("/chain"));
  cs.end = parseEnd(r, doc.contains("end") ? doc["end"] : json::object(), Pointer("/end"));
  // "held": "start" takes the unloaded shape's end pose
  mechanics::Chain chain(cs.chain.segments);
  cs.body = parseBody(r, doc, chain);
  const mechanics::Pose pose0 = mechanics::endPose(chain, cs.chain.q0);
  for (int c = 0; c < 3; ++c)
    if (cs.end.heldAtStart[size_t(c)]) cs.end.condition.value[c] = pose0[c];
  if (!doc.contains("path")) {
    checkEndAgainstChain(r, cs);
    if (needPath)
      r.fail(Pointer("/path"), "missing (required by /analyses/continuation, critical_forces, two_parameter, "
                               "load_history, sudden_load and equilibria with \"at\"): the load path");
    cs.path.parameter = "Fx";
    cs.path.coordinate = 0;
    cs.path.direction = Eigen::Vector3d(1.0, 0.0, 0.0);
    cs.path.from = cs.path.to = cs.end.condition.value[0];
    if (cs.end.condition.isHeld(mechanics::EndCoordinate::X)) cs.path.parameter = "x";
    return cs;
  }
  const json& path = doc["path"];
  r.requireObject(path, Pointer("/path"));
  if (isTaskPath(path)) {
    cs.path = parseTaskPath(r, path, Pointer("/path"), chain, cs.end);
    checkEndAgainstChain(r, cs);
    return cs;
  }
  if (isControlPath(path)) {
    cs.path = parseControlPath(r, path, Pointer("/path"), chain);
    checkEndAgainstChain(r, cs);
    return cs;
  }
  if (path.contains("parameter") && path["parameter"] == "gravity") {
    cs.path = parseGravityPath(r, path, Pointer("/path"), cs.body);
    checkEndAgainstChain(r, cs);
    return cs;
  }
  double start = 0.0;
  if (path.contains("parameter") && path["parameter"].is_string()) {
    bool isLoad = false;
    const int c = coordinateOfParameter(path["parameter"].get<std::string>(), isLoad);
    if (c >= 0) start = cs.end.condition.value[c];
  }
  cs.path = parsePath(r, path, Pointer("/path"), cs.end, start);
  checkEndAgainstChain(r, cs);
  // displacement control from a singular start (the straight chain along x): through the
  // reaction, with the load limit derived from the critical reactions unless given
  if (!cs.path.throughReaction && cs.end.condition.isHeld(static_cast<mechanics::EndCoordinate>(cs.path.coordinate)) &&
      !mechanics::endMovesAlong(chain, cs.chain.q0, cs.path.coordinate))
    cs.path.throughReaction = true;
  return cs;
}

}  // namespace buckle::scene::detail

namespace buckle::scene {

mechanics::SegmentParameters segmentFromKeys(const nlohmann::json& keys, const std::string& source) {
  const JsonReader r(source);
  std::set<std::string> allowed = detail::kSegmentKeys;
  allowed.erase("q0");
  r.onlyKeys(keys, detail::Pointer(""), allowed);
  detail::SegmentDefaults d = detail::defaultSegment();
  detail::applySegmentKeys(r, keys, detail::Pointer(""), d);
  detail::checkSegment(r, d, detail::Pointer(""), 0.0);
  return detail::toParameters(d);
}

}  // namespace buckle::scene
