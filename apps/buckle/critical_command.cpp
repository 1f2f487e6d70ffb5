#include "critical_command.h"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/linear_buckling.h"

namespace buckle::cli {

namespace {

struct CriticalOptions {
  int segments = 3;
  double a = 0.5, b = 1.0, k = 1.0, L0 = 2.25;
  std::string end = "pinned";
  int count = 3;
  bool json = false;
};

// Dense eigen-decompositions: beyond this the command would take minutes and gigabytes.
constexpr int kMaxSegments = 5000;

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
  if (o.segments < 1 || o.segments > kMaxSegments)
    throw BadArgument{"--segments must be between 1 and " + std::to_string(kMaxSegments) + " (got " +
                      std::to_string(o.segments) + ")"};
  requireNumber("--a", o.a, true);
  requireNumber("--b", o.b, false);
  requireNumber("--k", o.k, false);
  requireNumber("--L0", o.L0, false);
  if (o.count < 1) throw BadArgument{"--count must be >= 1 (got " + std::to_string(o.count) + ")"};
  if (o.end != "pinned" && o.end != "free") throw BadArgument{"--end must be pinned or free (got " + o.end + ")"};
}

int run(const CriticalOptions& o) {
  validate(o);
  using namespace buckle::mechanics;
  nlohmann::json out;
  out["command"] = "critical";
  out["parameters"] = {{"segments", o.segments}, {"a", o.a}, {"b", o.b}, {"k", o.k},
                       {"L0", o.L0},             {"end", o.end}, {"count", o.count}};
  try {
    const Chain chain = Chain::uniform(o.segments, SegmentParameters::symmetric(o.a, o.b, o.k, o.L0));
    const int n = chain.size();
    const double kappa = chain.segment(0).straightStiffness();
    const EndCondition end = o.end == "pinned" ? EndCondition::clampedPinned(0.0) : EndCondition::freeEnd();
    LinearBucklingOptions lbo;
    lbo.count = o.count;
    const LinearBucklingResult lb = linearBuckling(chain, Vector::Zero(n), end, lbo);
    const bool analytic = n == 3 && o.end == "pinned";
    const AnalyticBuckling3 an = analytic ? analyticClampedPinned3(o.a, o.b, o.k, o.L0) : AnalyticBuckling3{};

    out["kappa"] = kappa;
    out["kappa_closed_form"] = o.k * (o.b * o.L0 - 2.0 * (o.b * o.b - o.a * o.a));
    out["straight_stable"] = lb.unloadedStable;
    out["degenerate"] = lb.degenerate;
    out["chain_length"] = chain.length();
    out["critical"] = nlohmann::json::array();
    for (const BucklingMode& m : lb.modes) {
      nlohmann::json c;
      c["Fx"] = m.lambda;
      c["shape"] = m.shape;
      c["mode"] = std::vector<double>(m.mode.data(), m.mode.data() + m.mode.size());
      c["shortening"] = m.shortening;
      if (analytic) {
        c["mu"] = m.mu;
        if (m.shape == "U" || m.shape == "Z") {
          const bool U = m.shape == "U";
          c["analytic_Fx"] = U ? an.FxU : an.FxZ;
          c["error"] = m.lambda - (U ? an.FxU : an.FxZ);
          c["analytic_mu"] = U ? an.muU : an.muZ;
        }
      }
      out["critical"].push_back(c);
    }
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
  std::cout << "buckle critical: " << o.segments << " segments, a = " << o.a << ", b = " << o.b << ", k = " << o.k
            << ", L0 = " << o.L0 << ", end " << (o.end == "pinned" ? "clamped-pinned (y held)" : "free (cantilever)")
            << "\n";
  std::cout << "kappa = k (b L0 - 2 (b^2 - a^2)) = " << out["kappa"].get<double>() << "\n";
  std::cout << "straight configuration: " << (out["straight_stable"].get<bool>() ? "stable" : "unstable")
            << " (eq 4: L0 > 2b (1 - (a/b)^2))\n";
  if (out["degenerate"].get<bool>()) std::cout << "kappa = 0: every critical load is 0\n";
  const auto& crit = out["critical"];
  if (crit.empty()) std::cout << "no finite critical load\n";
  int idx = 1;
  for (const auto& c : crit) {
    std::cout << "critical " << idx++ << ": Fx = " << c["Fx"].get<double>() << "  shape " << c["shape"].get<std::string>();
    if (c.contains("analytic_Fx"))
      std::cout << "  (eq 17: " << c["analytic_Fx"].get<double>() << ", difference " << c["error"].get<double>()
                << "; mu = " << c["mu"].get<double>() << ", eq 18: " << c["analytic_mu"].get<double>() << ")";
    std::cout << "\n  mode:";
    for (const auto& v : c["mode"]) std::cout << " " << v.get<double>();
    std::cout << "\n";
  }
  return kSuccess;
}

}  // namespace

void addCriticalCommand(CLI::App& app, Outcome& outcome) {
  auto options = std::make_shared<CriticalOptions>();
  CLI::App* sub = app.add_subcommand(
      "critical", "Stability of the straight chain and its critical end forces Fx (linear buckling, eq 14-18)");
  sub->add_option("--segments", options->segments, "number of segments n")->capture_default_str();
  sub->add_option("--a", options->a, "triangle half-height a")->capture_default_str();
  sub->add_option("--b", options->b, "triangle half-length b")->capture_default_str();
  sub->add_option("--k", options->k, "spring stiffness k")->capture_default_str();
  sub->add_option("--L0", options->L0, "spring free length L0 (equal preloads)")->capture_default_str();
  sub->add_option("--end", options->end, "end condition: pinned (clamped-pinned, y held) or free (cantilever)")
      ->capture_default_str();
  sub->add_option("--count", options->count, "number of critical loads to report")->capture_default_str();
  sub->add_flag("--json", options->json, "print one JSON object");
  sub->callback([options, &outcome] { outcome.code = run(*options); });
}

}  // namespace buckle::cli
