#include "critical_command.h"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/critical_loading.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/linear_buckling.h"
#include "scene/units.h"

namespace buckle::cli {

namespace {

constexpr int kMaxCriticalSegments = 5000;

struct CriticalOptions {
  int segments = 3;
  double a = 0.5, b = 1.0, k = 1.0, L0 = 2.25;
  std::string end = "pinned";
  int count = 3;
  bool json = false;
  std::string lengthUnit, forceUnit;  ///< names for the printed units (scene/units.h); empty: k and b's units
};

// The units the numbers are printed in: the names given, else said through k and b.
scene::UnitSystem units(const CriticalOptions& o) {
  scene::UnitSystem u;
  if (o.lengthUnit.empty()) return u;
  u.kind = scene::UnitSystem::Kind::Named;
  u.length = o.lengthUnit;
  u.force = o.forceUnit;
  return u;
}

std::string unitOf(const CriticalOptions& o, scene::Dimension d) {
  if (!o.lengthUnit.empty()) return " " + units(o).unit(d);
  switch (d) {
    case scene::Dimension::Force: return " (in k's force unit times b's length unit: k b = 1 when k = b = 1)";
    case scene::Dimension::Moment: return " (in k's force unit times b's length unit squared)";
    case scene::Dimension::Length: return " (in b's length unit)";
    default: return "";
  }
}

std::string str(double v) {
  std::ostringstream os;
  os << std::setprecision(17) << v;
  return os.str();
}

void requireNumber(const std::string& name, double v, bool allowZero) {
  if (!std::isfinite(v)) throw BadArgument{name + " must be a finite number (got " + str(v) + ")"};
  if (allowZero ? v < 0.0 : !(v > 0.0))
    throw BadArgument{name + (allowZero ? " must be >= 0" : " must be > 0") + " (got " + str(v) + ")"};
}

void validate(const CriticalOptions& o) {
  // the eigenproblem is dense: n² doubles and 4/3 n³ operations (5000: 200 MB, about a minute)
  if (o.segments < 1 || o.segments > kMaxCriticalSegments)
    throw BadArgument{"--segments must be an integer in [1, " + std::to_string(kMaxCriticalSegments) + "] (got " +
                      std::to_string(o.segments) + ")"};
  requireNumber("--a", o.a, true);
  requireNumber("--b", o.b, false);
  requireNumber("--k", o.k, false);
  requireNumber("--L0", o.L0, false);
  // eq 1: the triangles' angles 2 atan(a/b) must stay below π or the joint cannot move
  if (!(2.0 * std::atan(o.a / o.b) < M_PI))
    throw BadArgument{(std::abs(std::log10(o.a)) > std::abs(std::log10(o.b)) ? "--a" : "--b") + std::string(" out of range: a/b = ") + str(o.a / o.b) +
                      " leaves the joint no range of motion (2 atan(a/b) reaches pi)"};
  if (o.count < 1) throw BadArgument{"--count must be >= 1 (got " + std::to_string(o.count) + ")"};
  if (o.end != "pinned" && o.end != "free") throw BadArgument{"--end must be pinned or free (got " + o.end + ")"};
  if (o.lengthUnit.empty() != o.forceUnit.empty())
    throw BadArgument{"--length-unit and --force-unit go together (got only " +
                      std::string(o.lengthUnit.empty() ? "--force-unit" : "--length-unit") + ")"};
  for (const auto& [name, value] : {std::pair<const char*, const std::string&>{"--length-unit", o.lengthUnit},
                                    {"--force-unit", o.forceUnit}})
    if (!value.empty() && !scene::validUnitName(value))
      throw BadArgument{std::string(name) + " must be a unit name of 1 to 16 bytes (letters, digits, inner spaces, " +
                        ". / ^ * - µ μ · ² ³), e.g. m, mm, N (got \"" + value + "\")"};
}

// The option farthest from the chain's units (b for lengths, k for stiffness) by orders of
// magnitude: the one to name when the numbers leave the floating-point range. A half-height
// below b cannot cause that.
std::string mostExtremeOption(const CriticalOptions& o) {
  const std::pair<const char*, double> options[] = {{"--a", o.a}, {"--b", o.b}, {"--k", o.k}, {"--L0", o.L0}};
  std::string worst = "--L0";
  double worstOrders = -1.0;
  for (const auto& [name, v] : options) {
    if (name == std::string("--a") && v <= o.b) continue;
    const double orders = std::abs(std::log10(v));
    if (orders > worstOrders) {
      worstOrders = orders;
      worst = name;
    }
  }
  return worst;
}

[[noreturn]] void outOfRange(const CriticalOptions& o, const std::string& what) {
  const std::string name = mostExtremeOption(o);
  const double v = name == "--a" ? o.a : name == "--b" ? o.b : name == "--k" ? o.k : o.L0;
  throw BadArgument{name + " = " + str(v) + " is out of the range this computation can represent (" + what +
                    "); the loads scale as k b and kappa as k b^2: compute with values nearer 1 and rescale"};
}

int run(const CriticalOptions& o) {
  validate(o);
  using namespace buckle::mechanics;
  nlohmann::json out;
  out["command"] = "critical";
  out["parameters"] = {{"segments", o.segments}, {"a", o.a}, {"b", o.b}, {"k", o.k},
                       {"L0", o.L0},             {"end", o.end}, {"count", o.count}};
  out["units"] = units(o).toJson();
  try {
    // The straight uniform chain is scale-free: with lengths in units of b and stiffness in k the
    // critical loads are Fx = k b · Fx(a/b, 1, 1, L0/b), the modes and μ do not change and the
    // shortening scales with b (eq 14-18). So the eigenproblem is solved on that unit chain and
    // every k and b the doubles hold are handled; only results that are not doubles are refused.
    const double aUnit = o.a / o.b, L0Unit = o.L0 / o.b, loadScale = o.k * o.b;
    if (!std::isfinite(L0Unit) || !std::isnormal(loadScale) || !std::isnormal(loadScale * o.b))
      outOfRange(o, "L0/b = " + str(L0Unit) + ", k b = " + str(loadScale) + ", k b^2 = " + str(loadScale * o.b));
    const Chain chain = Chain::uniform(o.segments, SegmentParameters::symmetric(aUnit, 1.0, 1.0, L0Unit));
    const int n = chain.size();
    const double kappaUnit = chain.segment(0).straightStiffness();
    const double kappaClosedUnit = L0Unit - 2.0 * (1.0 - aUnit * aUnit);
    const EndCondition end = o.end == "pinned" ? EndCondition::clampedPinned(0.0) : EndCondition::freeEnd();
    LinearBucklingOptions lbo;
    lbo.count = o.count;
    const LinearBucklingResult lb = linearBuckling(chain, Vector::Zero(n), end, lbo);
    const bool analytic = clampedPinned3Applies(chain, Vector::Zero(n), criticalLoading(end, 0, Eigen::Vector3d::UnitX()));
    const AnalyticBuckling3 an = analytic ? analyticClampedPinned3(aUnit, 1.0, 1.0, L0Unit) : AnalyticBuckling3{};

    // eq 4: the straight chain is stable exactly when κ > 0; a unit chain that says otherwise was
    // computed past the double range (L0/b = 1e308: loads ≈ 1.9 κ/b overflow).
    const double kappa = kappaUnit * loadScale * o.b;
    if (!std::isfinite(kappa) || (!lb.degenerate && lb.unloadedStable != (kappaClosedUnit > 0.0)))
      outOfRange(o, "kappa = k (b L0 - 2 (b^2 - a^2)) = " + str(kappa) +
                        (std::isfinite(kappa) ? ", but the stiffness eigenvalues overflow" : ""));
    out["kappa"] = kappa;
    out["kappa_closed_form"] = kappaClosedUnit * loadScale * o.b;
    out["straight_stable"] = lb.unloadedStable;
    out["degenerate"] = lb.degenerate;
    out["chain_length"] = chain.length() * o.b;
    out["critical"] = nlohmann::json::array();
    int index = 1;
    for (const BucklingMode& m : lb.modes) {
      nlohmann::json c;
      const double Fx = m.lambda * loadScale;
      if (!std::isfinite(Fx) || (m.lambda != 0.0 && Fx == 0.0) || !std::isfinite(m.shortening * o.b))
        outOfRange(o, "critical load " + std::to_string(index) + ": Fx = " + str(m.lambda) + " k b = " + str(Fx) +
                          (index > 1 ? "; --count " + std::to_string(index - 1) + " keeps the smaller ones" : ""));
      ++index;
      c["Fx"] = Fx;
      c["shape"] = m.shape;
      c["mode"] = std::vector<double>(m.mode.data(), m.mode.data() + m.mode.size());
      c["shortening"] = m.shortening * o.b;
      if (analytic) {
        c["mu"] = m.mu;
        if (m.shape == "U" || m.shape == "Z") {
          const bool U = m.shape == "U";
          const double exact = U ? an.FxU : an.FxZ;
          c["analytic_Fx"] = exact * loadScale;
          c["error"] = (m.lambda - exact) * loadScale;
          c["analytic_mu"] = U ? an.muU : an.muZ;
        }
      }
      out["critical"].push_back(c);
    }
    if (static_cast<int>(lb.modes.size()) < o.count)
      out["note"] = "--count " + std::to_string(o.count) + " asked for " + std::to_string(o.count) +
                    " critical loads; this chain has " + std::to_string(lb.modes.size()) +
                    " finite compressive ones (" + std::to_string(n) + " joints" +
                    (o.end == "pinned" ? ", one degree of freedom taken by the held y" : "") + ")";
  } catch (const std::invalid_argument& e) {
    throw BadArgument{e.what()};
  } catch (const std::exception& e) {
    std::cerr << "error: computation failed: " << e.what() << "\n";
    return kComputationFailure;
  }

  if (o.json) {
    std::cout << out.dump(2) << "\n";
    return kSuccess;
  }
  std::cout << std::setprecision(10);
  const std::string L = o.lengthUnit.empty() ? "" : " " + o.lengthUnit;
  std::cout << "buckle critical: " << o.segments << " segments, a = " << o.a << L << ", b = " << o.b << L
            << ", k = " << o.k << (o.lengthUnit.empty() ? "" : " " + units(o).unit(scene::Dimension::Stiffness))
            << ", L0 = " << o.L0 << L << ", end "
            << (o.end == "pinned" ? "clamped-pinned (y held)" : "free (cantilever)") << "\n";
  std::cout << "kappa = k (b L0 - 2 (b^2 - a^2)) = " << out["kappa"].get<double>()
            << unitOf(o, scene::Dimension::Moment) << " (the straight joint stiffness, eq 4)\n";
  std::cout << "straight configuration: " << (out["straight_stable"].get<bool>() ? "stable" : "unstable")
            << " (eq 4: L0 > 2b (1 - (a/b)^2))\n";
  if (out["degenerate"].get<bool>()) std::cout << "kappa = 0: every critical load is 0\n";
  const auto& crit = out["critical"];
  if (crit.empty()) std::cout << "no finite critical load\n";
  std::cout << "Fx < 0 compresses; forces" << unitOf(o, scene::Dimension::Force) << "\n";
  int idx = 1;
  for (const auto& c : crit) {
    std::cout << "critical load " << idx++ << ": Fx = " << c["Fx"].get<double>() << "  mode shape "
              << c["shape"].get<std::string>();
    if (c.contains("analytic_Fx"))
      std::cout << "  (eq 17: " << c["analytic_Fx"].get<double>() << ", difference " << c["error"].get<double>()
                << "; mu = " << c["mu"].get<double>() << ", eq 18: " << c["analytic_mu"].get<double>() << ")";
    std::cout << "\n  mode (joint angles, unit norm):";
    for (const auto& v : c["mode"]) std::cout << " " << v.get<double>();
    std::cout << "\n";
  }
  if (out.contains("note")) std::cout << "note: " << out["note"].get<std::string>() << "\n";
  return kSuccess;
}

}  // namespace

void addCriticalCommand(CLI::App& app, Outcome& outcome, const char* name) {
  auto options = std::make_shared<CriticalOptions>();
  CLI::App* sub = app.add_subcommand(
      name, "Stability of the straight chain and its critical end forces Fx (linear buckling, eq 14-18)");
  sub->add_option("--segments", options->segments, "number of segments n (1 to 5000)")->capture_default_str();
  sub->add_option("--a", options->a, "triangle half-height a (a length)")->capture_default_str();
  sub->add_option("--b", options->b, "triangle half-length b (a length)")->capture_default_str();
  sub->add_option("--k", options->k, "spring stiffness k (force per length)")->capture_default_str();
  sub->add_option("--L0", options->L0, "spring free length L0 (equal preloads; a length)")->capture_default_str();
  sub->add_option("--end", options->end, "end condition: pinned (clamped-pinned, y held) or free (cantilever)")
      ->capture_default_str();
  sub->add_option("--count", options->count, "number of critical loads to report (fewer exist when n is small: a note says so)")->capture_default_str();
  sub->add_option("--length-unit", options->lengthUnit, "name of the length unit of a, b, L0 (e.g. m), for the printout");
  sub->add_option("--force-unit", options->forceUnit, "name of the force unit of k (e.g. N), for the printout");
  sub->add_flag("--json", options->json, "print one JSON object");
  sub->footer(
      "Printed per critical load: Fx, the compressive end force at which the straight chain buckles (Fx < 0;\n"
      "forces in k's force unit times b's length unit, or as named by --force-unit); 'mode shape': the buckling\n"
      "mode's name, 'mode k' when its joint angles change sign k times (U and Z for three segments); 'mode':\n"
      "the joint angles of the mode, unit norm. For three clamped-pinned segments also eq 17's closed form and\n"
      "mu, the end shortening per squared middle-joint angle of the mode, dx = mu b q2^2 (eq 18).\n"
      "kappa: the straight joint stiffness k (b L0 - 2 (b^2 - a^2)), a moment (eq 4).");
  sub->callback([options, &outcome] { outcome.code = run(*options); });
}

}  // namespace buckle::cli
