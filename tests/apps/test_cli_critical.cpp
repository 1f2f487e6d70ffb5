// `buckle critical` end to end: runs the built program, checks its JSON against the closed forms
// of the paper (eq 4, 15, 17, 18) and the exit codes of bad input.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>
#include <vector>
#include <nlohmann/json.hpp>
#include <string>
#include "build_paths.h"

namespace {

struct Run {
  int status = -1;
  std::string out;
};

// Runs `buckle <args>`; `withStderr` merges stderr into the captured output.
Run runBuckle(const std::string& args, bool withStderr = false) {
  const std::string cmd = std::string(BUCKLE_BINARY_DIR) + "/bin/buckle " + args + (withStderr ? " 2>&1" : " 2>/dev/null");
  Run r;
  FILE* pipe = popen(cmd.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::array<char, 4096> buf{};
  size_t got = 0;
  while ((got = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.out.append(buf.data(), got);
  const int st = pclose(pipe);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

nlohmann::json critical(const std::string& args) {
  const Run r = runBuckle("critical --json " + args);
  INFO("buckle critical --json " << args << "\n" << r.out);
  REQUIRE(r.status == 0);
  return nlohmann::json::parse(r.out);
}

const double r21 = std::sqrt(21.0);

}  // namespace

TEST_CASE("buckle --version prints the project version", "[cli]") {
  const Run r = runBuckle("--version");
  CHECK(r.status == 0);
  CHECK_THAT(r.out, Catch::Contains(BUCKLE_VERSION));
}

TEST_CASE("buckle critical --json: n = 3 clamped-pinned against eq 15, 17, 18", "[cli]") {
  struct P {
    double a, b, k, L0;
  };
  for (const P p : {P{0.5, 1.0, 1.0, 2.25}, P{0.75, 2.0, 3.0, 4.5}, P{0.2, 1.0, 1.0, 1.2}}) {
    std::ostringstream args;
    args << std::setprecision(17) << "--a " << p.a << " --b " << p.b << " --k " << p.k << " --L0 " << p.L0;
    const nlohmann::json j = critical(args.str());
    INFO(j.dump());
    const double kappa = p.k * (p.b * p.L0 - 2 * (p.b * p.b - p.a * p.a));
    CHECK(j["kappa"].get<double>() == Approx(kappa).epsilon(1e-12));
    CHECK(j["straight_stable"].get<bool>() == (kappa > 0));                       // eq 4
    CHECK(j["straight_stable"].get<bool>() == (p.L0 > 2 * p.b * (1 - (p.a / p.b) * (p.a / p.b))));
    CHECK(j["parameters"]["segments"].get<int>() == 3);
    CHECK(j["parameters"]["end"].get<std::string>() == "pinned");
    const auto& c = j["critical"];
    REQUIRE(c.size() == 2);  // n − 1 modes with y held
    const double FxU = (r21 - 14) / 10 * kappa / p.b, FxZ = -(r21 + 14) / 10 * kappa / p.b;
    CHECK(c[0]["shape"].get<std::string>() == "U");
    CHECK(c[1]["shape"].get<std::string>() == "Z");
    CHECK(c[0]["Fx"].get<double>() == Approx(FxU).epsilon(1e-12));
    CHECK(c[1]["Fx"].get<double>() == Approx(FxZ).epsilon(1e-12));
    CHECK(c[0]["analytic_Fx"].get<double>() == Approx(FxU).epsilon(1e-14));
    CHECK(std::abs(c[0]["error"].get<double>()) < 1e-12 * std::abs(FxU));
    CHECK(std::abs(c[1]["error"].get<double>()) < 1e-12 * std::abs(FxZ));
    CHECK(c[0]["mu"].get<double>() == Approx((21 + r21) / 20).epsilon(1e-12));
    CHECK(c[1]["mu"].get<double>() == Approx((21 - r21) / 20).epsilon(1e-12));
    const auto mU = c[0]["mode"].get<std::vector<double>>(), mZ = c[1]["mode"].get<std::vector<double>>();
    REQUIRE(mU.size() == 3);
    CHECK(mU[0] / mU[1] == Approx(-(r21 + 11) / 20).epsilon(1e-12));
    CHECK(mU[2] / mU[1] == Approx((r21 - 1) / 4).epsilon(1e-12));
    CHECK(mZ[0] / mZ[1] == Approx(-(-r21 + 11) / 20).epsilon(1e-12));
    CHECK(mZ[2] / mZ[1] == Approx((-r21 - 1) / 4).epsilon(1e-12));
    CHECK(std::hypot(mU[0], mU[1], mU[2]) == Approx(1.0).epsilon(1e-12));
  }
}

TEST_CASE("buckle critical: count, free end, many segments, text output", "[cli]") {
  CHECK(critical("--count 1")["critical"].size() == 1);
  const nlohmann::json f = critical("--end free --count 5");
  REQUIRE(f["critical"].size() == 3);  // n modes, no analytic values for the cantilever
  double prev = 0.0;
  for (const auto& c : f["critical"]) {
    CHECK_FALSE(c.contains("analytic_Fx"));
    CHECK(std::abs(c["Fx"].get<double>()) >= prev);
    prev = std::abs(c["Fx"].get<double>());
  }
  // the cantilever buckles at a much smaller load than the clamped-pinned chain
  CHECK(std::abs(f["critical"][0]["Fx"].get<double>()) < 0.5 * std::abs(critical("")["critical"][0]["Fx"].get<double>()));
  // n = 40 clamped-pinned against the Euler load 20.19 EI / L² (EI = 2bκ, L = 2nb), error ~1.5/n²
  const nlohmann::json e = critical("--segments 40 --count 1");
  const double kappa = 2.25 - 2 * 0.75, EI = 2 * kappa, L = 80.0, beta = 4.493409457909064;
  CHECK(e["critical"][0]["Fx"].get<double>() == Approx(-beta * beta * EI / (L * L)).epsilon(2.0 / 1600));
  CHECK(e["critical"][0]["shape"].get<std::string>() == "mode 1");
  CHECK(e["critical"][0]["mode"].size() == 40);
  // unstable straight chain (κ < 0): tension is critical
  const nlohmann::json u = critical("--a 0.2 --L0 1.2");
  CHECK_FALSE(u["straight_stable"].get<bool>());
  CHECK(u["critical"][0]["Fx"].get<double>() > 0.0);
  // human-readable output
  const Run t = runBuckle("critical");
  CHECK(t.status == 0);
  CHECK_THAT(t.out, Catch::Contains("stable") && Catch::Contains("U") && Catch::Contains("eq 17"));
}

TEST_CASE("buckle critical: bad arguments exit with 2 and name the argument", "[cli]") {
  struct Bad {
    std::string args, name;
  };
  for (const Bad& b : {Bad{"--segments 0", "--segments"}, Bad{"--b -1", "--b"}, Bad{"--k nan", "--k"},
                       Bad{"--end bogus", "--end"}, Bad{"--L0 0", "--L0"}, Bad{"--a -0.5", "--a"},
                       Bad{"--count 0", "--count"}, Bad{"--segments three", "--segments"}, Bad{"--k inf", "--k"},
                       Bad{"--bogus 1", "--bogus"}, Bad{"--segments 1000000000", "--segments must be an integer in [1, 5000]"}}) {
    const Run r = runBuckle("critical " + b.args, true);
    INFO("buckle critical " << b.args << " → " << r.out);
    CHECK(r.status == 2);
    CHECK_THAT(r.out, Catch::Contains(b.name));
  }
  CHECK(runBuckle("").status == 2);  // a subcommand is required
  CHECK(runBuckle("critical --help").status == 0);
}

TEST_CASE("buckle critical: the whole double range, or a refusal naming the option", "[cli]") {
  // The critical loads scale exactly as k b (κ/b · f(n), eq 17): k and b anywhere in the double
  // range give the unit chain's loads times k b.
  const nlohmann::json unit = critical("");
  const double FxU = unit["critical"][0]["Fx"].get<double>(), FxZ = unit["critical"][1]["Fx"].get<double>();
  for (const char* k : {"1e-300", "1e-100", "1e100", "1e300", "1e308"}) {
    const nlohmann::json j = critical(std::string("--k ") + k);
    INFO("--k " << k);
    CHECK(j["straight_stable"].get<bool>());
    CHECK(j["critical"][0]["Fx"].get<double>() == Approx(FxU * std::stod(k)).epsilon(1e-12));
    CHECK(j["critical"][1]["Fx"].get<double>() == Approx(FxZ * std::stod(k)).epsilon(1e-12));
    CHECK(j["kappa"].get<double>() == Approx(0.75 * std::stod(k)).epsilon(1e-12));
  }
  // b = 1e100 with a, L0 scaled along: loads × b, shortening × b, modes unchanged
  const nlohmann::json big = critical("--a 0.5e100 --b 1e100 --L0 2.25e100");
  CHECK(big["critical"][0]["Fx"].get<double>() == Approx(FxU * 1e100).epsilon(1e-12));
  CHECK(big["critical"][0]["shortening"].get<double>() ==
        Approx(unit["critical"][0]["shortening"].get<double>() * 1e100).epsilon(1e-12));
  CHECK(big["critical"][0]["mode"][0].get<double>() ==
        Approx(unit["critical"][0]["mode"][0].get<double>()).epsilon(1e-12));
  // L0 = 1e300: κ > 0 and the chain is stable (the old answer at 1e308 was "unstable")
  const nlohmann::json longSprings = critical("--L0 1e300");
  CHECK(longSprings["straight_stable"].get<bool>());
  CHECK(longSprings["critical"][0]["Fx"].get<double>() < 0.0);

  struct Bad {
    std::string args, name;
  };
  for (const Bad& b : {Bad{"--L0 1e308", "--L0"}, Bad{"--a 1e308", "--a"}, Bad{"--a 1e20", "--a"},
                       Bad{"--b 1e-320", "--b"}, Bad{"--b 1e200", "--b"}, Bad{"--k 1e-320", "--k"},
                       Bad{"--k 1e308 --b 1e10 --L0 2.25e10 --a 0.5e10", "--k"}, Bad{"--L0 nan", "--L0"},
                       Bad{"--a inf", "--a"}, Bad{"--b -inf", "--b"}, Bad{"--L0 1e999", "--L0"}, Bad{"--k -0", "--k"},
                       Bad{"--segments 99999999999", "--segments"}, Bad{"--segments 1e3", "--segments"},
                       Bad{"--count -1", "--count"}, Bad{"--count nan", "--count"}}) {
    const Run r = runBuckle("critical " + b.args, true);
    INFO("buckle critical " << b.args << " → " << r.out);
    CHECK(r.status == 2);
    CHECK_THAT(r.out, Catch::Contains(b.name));
    CHECK_THAT(r.out, !Catch::Contains("unstable"));
  }
}

TEST_CASE("buckle critical says how many critical loads exist and in which units", "[cli]") {
  // a clamped-pinned chain of n segments has n − 1 buckling modes (the held y takes one degree of
  // freedom), a free one n: --count above that is answered with what exists and a note
  for (int n : {2, 3, 4}) {
    const nlohmann::json pinned = critical("--segments " + std::to_string(n) + " --count 9");
    CHECK(pinned["critical"].size() == size_t(n - 1));
    REQUIRE(pinned.contains("note"));
    CHECK_THAT(pinned["note"].get<std::string>(), Catch::Contains("has " + std::to_string(n - 1)));
    const nlohmann::json free = critical("--segments " + std::to_string(n) + " --count 9 --end free");
    CHECK(free["critical"].size() == size_t(n));
    CHECK_THAT(free["note"].get<std::string>(), Catch::Contains("has " + std::to_string(n)));
    CHECK_FALSE(critical("--segments " + std::to_string(n) + " --count " + std::to_string(n - 1)).contains("note"));
  }
  const Run text = runBuckle("critical --segments 2 --count 3");
  CHECK_THAT(text.out, Catch::Contains("note: --count 3"));

  // named units: the first critical load of the SI chain of the README's example is the unit
  // chain's times k b = 40 N, printed with N
  const Run si = runBuckle("critical --segments 10 --a 0.01 --b 0.02 --k 2000 --L0 0.045 --length-unit m --force-unit N");
  REQUIRE(si.status == 0);
  CHECK_THAT(si.out, Catch::Contains("k = 2000 N/m"));
  CHECK_THAT(si.out, Catch::Contains("forces N"));
  CHECK_THAT(si.out, Catch::Contains("N·m (the straight joint stiffness"));
  const nlohmann::json siJson =
      critical("--segments 10 --a 0.01 --b 0.02 --k 2000 --L0 0.045 --length-unit m --force-unit N");
  const nlohmann::json unit = critical("--segments 10");
  CHECK(siJson["units"]["stiffness"] == "N/m");
  CHECK(siJson["critical"][0]["Fx"].get<double>() ==
        Approx(40.0 * unit["critical"][0]["Fx"].get<double>()).epsilon(1e-13));
  // without names the printout says which units the numbers are in, never "units of k b"
  const Run plain = runBuckle("critical --b 0.02 --k 2000 --a 0.01 --L0 0.045");
  CHECK_THAT(plain.out, Catch::Contains("k's force unit times b's length unit"));
  for (const char* bad : {"--length-unit m", "--length-unit 'm\"' --force-unit N", "--length-unit m --force-unit '<N>'"}) {
    const Run r = runBuckle(std::string("critical ") + bad, true);
    INFO(bad << " → " << r.out);
    CHECK(r.status == 2);
    CHECK_THAT(r.out, Catch::Contains("unit"));
  }
  // every printed column is explained by --help
  const Run help = runBuckle("critical --help");
  for (const char* word : {"mode shape", "mu", "kappa", "Fx"}) CHECK_THAT(help.out, Catch::Contains(word));
}
