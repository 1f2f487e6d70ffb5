// The loads on the chain's body (docs/scenes.md, "Weight and point loads"): /gravity,
// /point_loads, the gravity path (/path/parameter "gravity") and the analyses that do not take
// them yet.
#include <cmath>
#include <sstream>

#include "scene/scene_parsing.h"

namespace buckle::scene::detail {

namespace {

// Forces and accelerations up to 1e12 of the chain's units (as the end loads: scene_case.cpp).
double forceUnit(const mechanics::Chain& chain) {
  double k = 0.0, b = 0.0;
  for (int i = 0; i < chain.size(); ++i) {
    const mechanics::SegmentParameters& p = chain.segment(i).parameters();
    k = std::max({k, p.k1, p.k2});
    b = std::max({b, p.b1, p.b2});
  }
  return k * b;
}

double boundedForce(const JsonReader& r, const json& v, const Pointer& p, double unit) {
  const double f = r.number(v, p);
  if (!(std::abs(f) <= 1e12 * unit))
    r.fail(p, "expected a force with |F| <= " + show(1e12 * unit) + " (1e12 times the chain's force unit k b), got " +
                  show(f));
  return f;
}

// {"Fx": …, "Fy": …} (each optional, 0 when absent)
Eigen::Vector2d forceObject(const JsonReader& r, const json& v, const Pointer& p, double unit) {
  r.requireObject(v, p);
  r.onlyKeys(v, p, {"Fx", "Fy"});
  Eigen::Vector2d f = Eigen::Vector2d::Zero();
  if (v.contains("Fx")) f.x() = boundedForce(r, v["Fx"], p / "Fx", unit);
  if (v.contains("Fy")) f.y() = boundedForce(r, v["Fy"], p / "Fy", unit);
  return f;
}

void parseGravity(const JsonReader& r, const json& v, const Pointer& p, BodySpec& body) {
  r.requireObject(v, p);
  r.onlyKeys(v, p, {"value", "direction", "mass_per_length", "payload"});
  if (!v.contains("value")) r.fail(p / "value", "missing (required): the gravitational acceleration's magnitude");
  body.haveGravity = true;
  body.gravity = r.nonNegative(v["value"], p / "value");
  if (v.contains("direction")) {
    const json& d = v["direction"];
    if (!d.is_array() || d.size() != 2) r.expected(p / "direction", d, "an array [x, y] of two numbers");
    const Eigen::Vector2d dir(r.number(d[0], p / "direction" / 0), r.number(d[1], p / "direction" / 1));
    if (!(dir.norm() > 0.0) || !std::isfinite(dir.norm()))
      r.fail(p / "direction", "expected a direction [x, y] that is not zero (its length does not matter)");
    body.direction = dir.normalized();
  }
  if (v.contains("mass_per_length")) body.massPerLength = r.nonNegative(v["mass_per_length"], p / "mass_per_length");
  if (v.contains("payload")) body.payload = r.nonNegative(v["payload"], p / "payload");
  if (!(body.massPerLength > 0.0 || body.payload > 0.0))
    r.fail(p / "mass_per_length", "missing: gravity needs masses, a mass_per_length > 0 (the links as uniform rods) "
                                  "or a payload > 0 (a point mass at the end)");
}

void parsePointLoads(const JsonReader& r, const json& v, const Pointer& p, const mechanics::Chain& chain, BodySpec& body) {
  if (!v.is_array() || v.empty()) r.expected(p, v, "a non-empty array of {\"joint\", \"Fx\", \"Fy\", \"rate\"} objects");
  const int n = chain.size();
  const double unit = forceUnit(chain);
  for (size_t i = 0; i < v.size(); ++i) {
    const Pointer pi = p / i;
    r.requireObject(v[i], pi);
    r.onlyKeys(v[i], pi, {"joint", "Fx", "Fy", "rate"});
    if (!v[i].contains("joint")) r.fail(pi / "joint", "missing (required): the joint (1 … " + std::to_string(n) + ")");
    PointLoadSpec load;
    load.joint = r.integer(v[i]["joint"], pi / "joint", 1, n);
    json force = json::object();
    for (const char* key : {"Fx", "Fy"})
      if (v[i].contains(key)) force[key] = v[i][key];
    load.force = forceObject(r, force, pi, unit);
    if (v[i].contains("rate")) load.rate = forceObject(r, v[i]["rate"], pi / "rate", unit);
    body.points.push_back(load);
  }
}

}  // namespace

BodySpec parseBody(const JsonReader& r, const json& doc, const mechanics::Chain& chain) {
  BodySpec body;
  if (doc.contains("gravity")) parseGravity(r, doc["gravity"], Pointer("/gravity"), body);
  if (doc.contains("point_loads")) parsePointLoads(r, doc["point_loads"], Pointer("/point_loads"), chain, body);
  return body;
}

PathSpec parseGravityPath(const JsonReader& r, const json& path, const Pointer& p, const BodySpec& body) {
  r.onlyKeys(path, p, {"parameter", "from", "to"});
  for (const char* key : {"from", "to"})
    if (!path.contains(key)) r.fail(p / key, "missing (required)");
  if (!body.haveGravity)
    r.fail(p / "parameter", "the path parameter \"gravity\" needs /gravity (its direction and the masses)");
  PathSpec spec;
  spec.parameter = "gravity";
  spec.gravity = true;
  spec.from = r.nonNegative(path["from"], p / "from");
  spec.to = r.nonNegative(path["to"], p / "to");
  if (spec.from == spec.to) r.fail(p / "to", "expected a value different from /path/from (an empty range)");
  const double lo = std::min(spec.from, spec.to), hi = std::max(spec.from, spec.to);
  if (!(body.gravity >= lo && body.gravity <= hi)) {
    std::ostringstream os;
    os << "expected a range [from, to] that contains the start value gravity = " << show(body.gravity)
       << " (set by /gravity/value), got [" << show(spec.from) << ", " << show(spec.to) << "]";
    r.fail(p / (std::abs(spec.from - body.gravity) <= std::abs(spec.to - body.gravity) ? "from" : "to"), os.str());
  }
  return spec;
}

void checkBodyAnalyses(const JsonReader& r, const Scene& scene) {
  for (const CaseSpec& c : scene.cases) {
    if (!c.body.any()) continue;
    const auto refuse = [&](const char* key, const char* what) {
      r.fail(Pointer("/analyses") / key, std::string(what) + " do not include the weight and point loads yet; case \"" +
                                             c.label + "\" has /gravity or /point_loads (remove one of them)");
    };
    const AnalysesSpec& a = scene.analyses;
    if (a.criticalForces.enabled) refuse("critical_forces", "critical forces (linear buckling of the unloaded shape)");
    if (a.twoParameter.enabled) refuse("two_parameter", "two-parameter critical curves");
    // one mass model: the frequencies' rods are the weight's rods
    if (a.frequencies.enabled && c.body.haveGravity && c.body.massPerLength != a.frequencies.massPerLength)
      r.fail(Pointer("/analyses/frequencies/mass_per_length"),
             "expected " + show(c.body.massPerLength) + ", the /gravity/mass_per_length of case \"" + c.label +
                 "\" (one mass model for the weight and the vibrations), got " + show(a.frequencies.massPerLength));
  }
}

}  // namespace buckle::scene::detail
