#include "regress/baseline.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>
#include <unistd.h>

#include "regress/sampling.h"
#include "scene/json_reader.h"

namespace buckle::regress {

using nlohmann::json;
using nlohmann::ordered_json;
using Pointer = json::json_pointer;
using scene::JsonReader;

namespace {

constexpr const char* kFormat = "buckle-regression/1";
constexpr int kSamplesPerBranch = 3;

Tolerance readTolerance(const JsonReader& r, const json& v, const Pointer& p) {
  r.onlyKeys(v, p, {"absolute", "relative"});
  Tolerance t;
  t.absolute = r.nonNegative(r.required(v, p, "absolute"), p / "absolute");
  t.relative = r.nonNegative(r.required(v, p, "relative"), p / "relative");
  return t;
}

ordered_json toJson(const Tolerance& t) { return ordered_json{{"absolute", t.absolute}, {"relative", t.relative}}; }

// "q3" → 2
int readCoordinate(const JsonReader& r, const std::string& key, const Pointer& p) {
  char* end = nullptr;
  const long k = key.size() > 1 && key[0] == 'q' ? std::strtol(key.c_str() + 1, &end, 10) : 0;
  if (k < 1 || k > 100000 || !end || *end) r.fail(p, "expected a joint angle name q1, q2, ..., got \"" + key + "\"");
  return int(k - 1);
}

TolerancePolicy readPolicy(const JsonReader& r, const json& v, const Pointer& p) {
  r.onlyKeys(v, p, {"lambda_relative", "lambda_absolute", "accuracy_factor", "sample_absolute", "sample_relative",
                    "sample_error_factor"});
  TolerancePolicy t;
  t.lambdaRelative = r.nonNegative(r.required(v, p, "lambda_relative"), p / "lambda_relative");
  t.lambdaAbsolute = r.nonNegative(r.required(v, p, "lambda_absolute"), p / "lambda_absolute");
  t.accuracyFactor = r.nonNegative(r.required(v, p, "accuracy_factor"), p / "accuracy_factor");
  t.sampleAbsolute = r.nonNegative(r.required(v, p, "sample_absolute"), p / "sample_absolute");
  t.sampleRelative = r.nonNegative(r.required(v, p, "sample_relative"), p / "sample_relative");
  t.sampleErrorFactor = r.nonNegative(r.required(v, p, "sample_error_factor"), p / "sample_error_factor");
  return t;
}

ordered_json toJson(const TolerancePolicy& t) {
  return ordered_json{{"lambda_relative", t.lambdaRelative}, {"lambda_absolute", t.lambdaAbsolute},
                      {"accuracy_factor", t.accuracyFactor}, {"sample_absolute", t.sampleAbsolute},
                      {"sample_relative", t.sampleRelative}, {"sample_error_factor", t.sampleErrorFactor}};
}

CaseEntry readCase(const JsonReader& r, const json& v, const Pointer& p) {
  r.onlyKeys(v, p, {"label", "branches", "special_points", "samples"});
  CaseEntry c;
  c.label = r.string(r.required(v, p, "label"), p / "label");
  c.branches = r.integer(r.required(v, p, "branches"), p / "branches", 0, 1000000);
  const json& sps = r.required(v, p, "special_points");
  if (!sps.is_array()) r.expected(p / "special_points", sps, "an array");
  for (size_t i = 0; i < sps.size(); ++i) {
    const Pointer pi = p / "special_points" / i;
    r.onlyKeys(sps[i], pi, {"branch", "type", "order", "lambda", "shape", "post_buckling", "tolerance"});
    SpecialEntry s;
    s.branch = r.integer(r.required(sps[i], pi, "branch"), pi / "branch", -1, 1000000);
    s.type = r.string(r.required(sps[i], pi, "type"), pi / "type");
    s.order = r.integer(r.required(sps[i], pi, "order"), pi / "order", 0, 1000000);
    s.lambda = r.number(r.required(sps[i], pi, "lambda"), pi / "lambda");
    s.shape = r.string(r.required(sps[i], pi, "shape"), pi / "shape");
    if (sps[i].contains("post_buckling")) s.postBuckling = r.string(sps[i]["post_buckling"], pi / "post_buckling");
    s.tolerance = readTolerance(r, r.required(sps[i], pi, "tolerance"), pi / "tolerance");
    c.specials.push_back(s);
  }
  const json& samples = r.required(v, p, "samples");
  if (!samples.is_array()) r.expected(p / "samples", samples, "an array");
  for (size_t i = 0; i < samples.size(); ++i) {
    const Pointer pi = p / "samples" / i;
    r.onlyKeys(samples[i], pi, {"branch", "lambda", "crossing", "values", "tolerance"});
    SampleEntry s;
    s.branch = r.integer(r.required(samples[i], pi, "branch"), pi / "branch", 0, 1000000);
    s.lambda = r.number(r.required(samples[i], pi, "lambda"), pi / "lambda");
    s.crossing = r.integer(r.required(samples[i], pi, "crossing"), pi / "crossing", 0, 1000000);
    const json& values = r.required(samples[i], pi, "values");
    r.requireObject(values, pi / "values");
    if (values.empty()) r.expected(pi / "values", values, "an object of joint angles, e.g. {\"q1\": 0.1}");
    for (auto it = values.begin(); it != values.end(); ++it) {
      s.coordinates.push_back(readCoordinate(r, it.key(), pi / "values" / it.key()));
      s.values.push_back(r.number(it.value(), pi / "values" / it.key()));
    }
    s.tolerance = readTolerance(r, r.required(samples[i], pi, "tolerance"), pi / "tolerance");
    c.samples.push_back(s);
  }
  return c;
}

}  // namespace

double Tolerance::allowed(double baseline) const { return absolute + relative * std::abs(baseline); }

Baseline loadBaseline(const std::string& file) {
  const JsonReader r(file);
  const json doc = scene::loadJsonDocument(file);
  const Pointer root("");
  r.onlyKeys(doc, root, {"format", "name", "source", "ci", "timing", "tolerance_policy", "cases"});
  Baseline b;
  b.file = file;
  const std::string format = r.string(r.required(doc, root, "format"), Pointer("/format"));
  if (format != kFormat) r.fail(Pointer("/format"), std::string("expected \"") + kFormat + "\", got \"" + format + "\"");
  b.name = r.string(r.required(doc, root, "name"), Pointer("/name"));
  if (b.name.empty()) r.fail(Pointer("/name"), "expected a non-empty name");

  const Pointer ps("/source");
  const json& source = r.required(doc, root, "source");
  r.onlyKeys(source, ps, {"scene", "problem", "time_limit"});
  if (source.contains("scene") == source.contains("problem"))
    r.fail(ps, "expected exactly one of \"scene\" (a file in the scenes directory) or \"problem\"");
  if (source.contains("scene")) {
    b.source = {Source::Kind::Scene, r.string(source["scene"], ps / "scene")};
  } else {
    b.source = {Source::Kind::Problem, r.string(source["problem"], ps / "problem")};
    const auto& names = problemNames();
    if (std::find(names.begin(), names.end(), b.source.name) == names.end()) {
      std::string list;
      for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
      r.fail(ps / "problem", "unknown benchmark problem \"" + b.source.name + "\" (known: " + list + ")");
    }
  }
  if (source.contains("time_limit")) {
    if (!source.contains("scene")) r.fail(ps / "time_limit", "a time limit applies to scenes only");
    b.source.timeLimit = r.positive(source["time_limit"], ps / "time_limit");
  }
  if (doc.contains("ci")) b.ci = r.boolean(doc["ci"], Pointer("/ci"));

  const Pointer pt("/timing");
  const json& timing = r.required(doc, root, "timing");
  r.onlyKeys(timing, pt, {"repetitions", "reference_seconds", "machine"});
  b.repetitions = r.integer(r.required(timing, pt, "repetitions"), pt / "repetitions", 1, 100);
  b.referenceSeconds = r.nonNegative(r.required(timing, pt, "reference_seconds"), pt / "reference_seconds");
  if (timing.contains("machine")) b.machine = r.string(timing["machine"], pt / "machine");

  if (doc.contains("tolerance_policy")) b.policy = readPolicy(r, doc["tolerance_policy"], Pointer("/tolerance_policy"));
  const json& cases = r.required(doc, root, "cases");
  if (!cases.is_array()) r.expected(Pointer("/cases"), cases, "an array of case objects");
  for (size_t i = 0; i < cases.size(); ++i) b.cases.push_back(readCase(r, cases[i], Pointer("/cases") / i));
  return b;
}

std::string formatBaseline(const Baseline& b) {
  ordered_json doc;
  doc["format"] = kFormat;
  doc["name"] = b.name;
  doc["source"] = ordered_json{{b.source.kind == Source::Kind::Scene ? "scene" : "problem", b.source.name}};
  if (b.source.timeLimit > 0.0) doc["source"]["time_limit"] = b.source.timeLimit;
  doc["ci"] = b.ci;
  doc["timing"] = ordered_json{{"repetitions", b.repetitions}, {"reference_seconds", b.referenceSeconds}, {"machine", b.machine}};
  doc["tolerance_policy"] = toJson(b.policy);
  ordered_json cases = ordered_json::array();
  for (const CaseEntry& c : b.cases) {
    ordered_json jc;
    jc["label"] = c.label;
    jc["branches"] = c.branches;
    ordered_json sps = ordered_json::array();
    for (const SpecialEntry& s : c.specials) {
      ordered_json e{{"branch", s.branch}, {"type", s.type}, {"order", s.order}, {"lambda", s.lambda}, {"shape", s.shape}};
      if (!s.postBuckling.empty()) e["post_buckling"] = s.postBuckling;
      e["tolerance"] = toJson(s.tolerance);
      sps.push_back(e);
    }
    jc["special_points"] = sps;
    ordered_json samples = ordered_json::array();
    for (const SampleEntry& s : c.samples) {
      ordered_json values = ordered_json::object();
      for (size_t k = 0; k < s.coordinates.size(); ++k) values["q" + std::to_string(s.coordinates[k] + 1)] = s.values[k];
      samples.push_back(ordered_json{{"branch", s.branch}, {"lambda", s.lambda}, {"crossing", s.crossing},
                                     {"values", values}, {"tolerance", toJson(s.tolerance)}});
    }
    jc["samples"] = samples;
    cases.push_back(jc);
  }
  doc["cases"] = cases;
  // nlohmann writes doubles in the shortest form that reads back to the same bits: exact and
  // deterministic, and shorter in diffs than %.17g
  return doc.dump(2) + "\n";
}

std::vector<SpecialEntry> numberSpecials(const MeasuredCase& c, const TolerancePolicy& policy) {
  std::vector<SpecialEntry> out;
  std::map<std::pair<int, std::string>, int> counts;
  for (const MeasuredSpecial& s : c.specials) {
    SpecialEntry e;
    e.branch = s.branch;
    e.type = s.type;
    e.order = counts[{s.branch, s.type}]++;
    e.lambda = s.lambda;
    e.shape = s.shape;
    e.postBuckling = s.postBuckling;
    e.tolerance.relative = policy.lambdaRelative;
    e.tolerance.absolute = std::max(policy.lambdaAbsolute, policy.accuracyFactor * s.accuracy);
    out.push_back(e);
  }
  return out;
}

std::vector<int> sampleCoordinates(int joints) {
  if (joints <= 0) return {};
  if (joints == 1) return {0};
  return {0, joints - 1};
}

Baseline makeBaseline(const Baseline& settings, const Measurement& m, const std::string& machine) {
  Baseline b = settings;
  b.cases.clear();
  b.machine = machine;
  // three significant digits: timings are noisy, more would only churn the diff
  const double t = m.medianSeconds();
  b.referenceSeconds = t > 0 ? std::stod([&] {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", t);
    return std::string(buf);
  }()) : 0.0;
  for (const MeasuredCase& mc : m.cases) {
    CaseEntry c;
    c.label = mc.label;
    c.branches = int(mc.branches.size());
    c.specials = numberSpecials(mc, b.policy);
    for (const MeasuredBranch& br : mc.branches) {
      if (br.q.empty()) continue;
      const std::vector<int> coords = sampleCoordinates(int(br.q.front().size()));
      for (const SampleSite& site : chooseSites(br, kSamplesPerBranch)) {
        const SampleValue v = sampleAt(br, site, coords);
        if (!v.found) continue;
        SampleEntry e;
        e.branch = br.id;
        e.lambda = site.lambda;
        e.crossing = site.crossing;
        e.coordinates = coords;
        e.values = v.values;
        e.tolerance.relative = b.policy.sampleRelative;
        e.tolerance.absolute = std::max(b.policy.sampleAbsolute, b.policy.sampleErrorFactor * v.errorEstimate);
        c.samples.push_back(e);
      }
    }
    b.cases.push_back(c);
  }
  return b;
}

std::string machineDescription() {
  std::string model = "unknown CPU";
  std::ifstream cpu("/proc/cpuinfo");
  for (std::string line; std::getline(cpu, line);)
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      model = line.substr(line.find(':') + 1);
      model.erase(0, model.find_first_not_of(' '));
      break;
    }
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " threads";
}

void writeFileAtomically(const std::string& file, const std::string& text) {
  namespace fs = std::filesystem;
  const fs::path target(file);
  const fs::path tmp = target.parent_path() / ("." + target.filename().string() + ".tmp." + std::to_string(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error("cannot write " + tmp.string());
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot rename " + tmp.string() + " to " + file + ": " + ec.message());
  }
}

}  // namespace buckle::regress
