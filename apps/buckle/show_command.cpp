#include "show_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/escape.h"
#include "scene/output_target.h"

namespace buckle::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// What makes `show` give up: printed as "buckle show: <message>", exit 2.
struct NotAnOutput {
  std::string message;
};

json readJson(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw NotAnOutput{file.string() + ": cannot be read"};
  const json doc = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) throw NotAnOutput{file.string() + ": not a JSON object (the file is damaged)"};
  return doc;
}

// The writers put null for NaN (JSON has none).
std::string number(const json& v, const char* format = "%.10g") {
  if (!v.is_number()) return v.is_null() ? "nan" : "-";
  char buf[48];
  std::snprintf(buf, sizeof buf, format, v.get<double>());
  return buf;
}

std::string text(const json& v) {
  // text from the scene reaches a terminal: one line, no control characters (escape sequences)
  if (v.is_string()) return v.get<std::string>().empty() ? "-" : scene::escape::commentText(v.get<std::string>());
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_number_integer()) return std::to_string(v.get<long long>());
  if (v.is_number()) return number(v);
  return "-";
}

const json& field(const json& o, const char* key) {
  static const json kNull;
  return o.is_object() && o.contains(key) ? o[key] : kNull;
}

/// An array member, or an empty array when it is missing or not an array.
const json& list(const json& o, const char* key) {
  static const json kEmpty = json::array();
  const json& v = field(o, key);
  return v.is_array() ? v : kEmpty;
}

/// Columns padded to their widest cell; numbers right-aligned, words left-aligned.
void printTable(std::ostream& os, const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
                const std::vector<bool>& right) {
  std::vector<size_t> width(header.size());
  auto len = [](const std::string& s) {  // code points, for the UTF-8 in the headers
    size_t n = 0;
    for (unsigned char c : s) n += (c & 0xC0) != 0x80;
    return n;
  };
  for (size_t i = 0; i < header.size(); ++i) width[i] = len(header[i]);
  for (const auto& r : rows)
    for (size_t i = 0; i < r.size(); ++i) width[i] = std::max(width[i], len(r[i]));
  auto line = [&](const std::vector<std::string>& r) {
    std::string out = " ";
    for (size_t i = 0; i < r.size(); ++i) {
      const std::string pad(width[i] - len(r[i]), ' ');
      const bool last = i + 1 == r.size();
      out += " " + (right[i] ? pad + r[i] : r[i] + (last ? "" : pad));
    }
    os << out << "\n";
  };
  line(header);
  for (const auto& r : rows) line(r);
}

/// The run's scene, completeness, units, problems, what it computed, its accuracy and cases.
void showHeader(const std::string& dirName, const json& summary, std::ostream& os) {
  os << dirName << ": buckle run of " << text(field(summary, "scene")) << "\n";
  const std::string description = text(field(summary, "description"));
  if (description != "-") os << "  " << description.substr(0, 200) << (description.size() > 200 ? "…" : "") << "\n";
  os << "  complete: " << text(field(summary, "complete")) << "\n";
  // the unit names as the scene gave them (summary.json `units`, docs/outputs.md)
  if (const json& u = field(summary, "units"); u.is_object()) {
    const std::string system = text(field(u, "system"));
    os << "  units: "
       << (system == "consistent" ? "the scene's own consistent units (unnamed): "
                                  : system == "nondimensional" ? "nondimensional: " : "")
       << "lengths " << text(field(u, "length")) << ", forces " << text(field(u, "force")) << ", moments "
       << text(field(u, "moment")) << ", stiffness " << text(field(u, "stiffness")) << ", angles rad\n";
  }
  for (const json& p : list(summary, "problems")) os << "    problem: " << text(p) << "\n";
  std::string computed;
  for (const json& c : list(summary, "computed")) computed += (computed.empty() ? "" : "; ") + text(c);
  os << "  computed: " << (computed.empty() ? "-" : computed) << "\n";
  const json& acc = field(summary, "accuracy");
  os << "  accuracy: largest corrector residual " << number(field(acc, "max_corrector_residual"), "%.2e")
     << ", largest special-point parameter error " << number(field(acc, "max_special_point_parameter_error"), "%.2e")
     << "\n";
  const json& cases = list(summary, "cases");
  if (cases.size() > 1) {
    os << "  cases:";
    for (size_t c = 0; c < cases.size(); ++c) os << (c ? ";" : "") << " " << c << " = " << text(field(cases[c], "label"));
    os << "\n";
  }
}

/// special_points.json's points as a table.
void showSpecialPoints(const json& sp, std::ostream& os) {
  const json& points = list(sp, "special_points");
  if (points.empty()) {
    os << "\nspecial points: none\n";
  } else {
    os << "\nspecial points (" << points.size() << ", special_points.json):\n";
    std::vector<std::vector<std::string>> rows;
    bool notes = false;
    for (const json& p : points) {
      const json& loads = field(p, "loads");
      const json& accuracy = field(p, "accuracy");
      std::string jump = "-";
      if (const json& j = field(p, "jump_to"); j.is_object()) {
        jump = field(j, "success").is_boolean() && field(j, "success").get<bool>()
                   ? text(field(j, "landing")) + (text(field(j, "shape")) != "-" ? " " + text(field(j, "shape")) : "")
                   : "failed";
      }
      const std::string note = text(field(p, "note"));
      notes = notes || note != "-";
      rows.push_back({text(field(p, "case")), text(field(p, "type")), text(field(p, "field")), text(field(p, "branch")),
                      number(field(p, "parameter")), number(field(loads, "Fx"), "%.6g"), number(field(loads, "Fy"), "%.6g"),
                      number(field(loads, "Me"), "%.6g"), text(field(p, "shape")),
                      text(field(p, "stability_before")) + " -> " + text(field(p, "stability_after")),
                      number(field(accuracy, "parameter"), "%.1e"), number(field(accuracy, "residual"), "%.1e"),
                      text(field(accuracy, "refined")), jump, note});
    }
    std::vector<std::string> header = {"case", "type", "field", "branch", "parameter", "Fx", "Fy", "Me", "shape",
                                       "stability before -> after", "|Δλ|", "residual", "refined", "jump to", "note"};
    std::vector<bool> right = {true, false, false, true, true, true, true, true, false, false, true, true, false, false, false};
    if (!notes) {
      header.pop_back();
      right.pop_back();
      for (auto& r : rows) r.pop_back();
    }
    printTable(os, header, rows, right);
  }
}

/// The analyses' results other than branches: critical loads, energy-curve equilibria, every
/// equilibrium at one state, torque zeros, sudden load.
void showAnalyses(const json& sp, std::ostream& os) {
  if (const json& critical = list(sp, "critical_loads"); !critical.empty()) {
    std::vector<std::vector<std::string>> crit;
    for (const json& m : critical)
      crit.push_back({text(field(m, "case")), number(field(m, "load_factor")), text(field(m, "shape"))});
    os << "\ncritical loads (" << crit.size() << ", linear buckling of the unloaded shape):\n";
    printTable(os, {"case", "load factor", "shape"}, crit, {true, true, false});
  }
  if (const json& eq = list(sp, "energy_equilibria"); !eq.empty()) {
    std::vector<std::vector<std::string>> t;
    for (const json& e : eq)
      t.push_back({text(field(e, "case")), text(field(e, "ik_branch")), number(field(e, "q1")),
                   number(field(e, "energy")), number(field(e, "d2E_dq1"), "%.6g"),
                   field(e, "stable").is_boolean() ? (field(e, "stable").get<bool>() ? "stable" : "unstable") : "-",
                   text(field(e, "shape"))});
    os << "\nequilibria on the energy curves (" << t.size() << ", special_points.json energy_equilibria):\n";
    printTable(os, {"case", "ik_branch", "q1", "E", "d2E/dq1^2", "stability", "shape"}, t,
               {true, true, true, true, true, false, false});
  }
  if (const json& all = list(sp, "equilibria"); !all.empty()) {
    // with "branches": the branch through each (its id in branches.csv)
    bool branches = false;
    for (const json& c : all)
      for (const json& e : list(c, "equilibria")) branches = branches || (e.is_object() && e.contains("branch"));
    std::vector<std::vector<std::string>> t;
    for (const json& c : all)
      for (const json& e : list(c, "equilibria")) {
        t.push_back({text(field(c, "case")), number(field(c, "at")), number(field(e, "potential")), text(field(e, "index")),
                     field(e, "stable").is_boolean() ? (field(e, "stable").get<bool>() ? "stable" : "unstable") : "-",
                     text(field(e, "shape")), number(field(e, "accuracy"), "%.1e")});
        if (branches) t.back().push_back(text(field(e, "branch")));
      }
    os << "\nevery equilibrium at one state (" << t.size() << ", special_points.json equilibria; method, starts and "
       << "guarantee there):\n";
    std::vector<std::string> header{"case", "at", "potential", "index", "stability", "shape", "accuracy"};
    std::vector<bool> right{true, true, true, true, false, false, true};
    if (branches) {
      header.push_back("branch");
      right.push_back(true);
    }
    printTable(os, header, t, right);
  }
  if (const json& zeros = list(sp, "torque_zeros"); !zeros.empty()) {
    std::vector<std::vector<std::string>> t;
    for (const json& z : zeros)
      t.push_back({text(field(z, "case")), number(field(z, "q")),
                   field(z, "stable").is_boolean() ? (field(z, "stable").get<bool>() ? "stable" : "unstable") : "-"});
    os << "\nzeros of the torque-angle curves (" << t.size() << ", special_points.json torque_zeros):\n";
    printTable(os, {"case", "q", "stability"}, t, {true, true, false});
  }
  if (const json& sudden = list(sp, "sudden_load"); !sudden.empty()) {
    std::vector<std::vector<std::string>> t;
    for (const json& r : sudden) {
      const json& qs = field(r, "quasi_static");
      t.push_back({text(field(r, "case")), number(field(r, "value")), text(field(r, "model")),
                   text(field(r, "success")), text(field(r, "stable")),
                   qs.is_object() ? text(field(qs, "differs")) : "-", qs.is_object() ? text(field(qs, "lower")) : "-",
                   text(field(r, "message"))});
    }
    os << "\nsudden load (" << t.size() << ", special_points.json sudden_load; trajectory in sudden_load.csv):\n";
    printTable(os, {"case", "value", "model", "at rest", "stable", "differs from quasi-static", "lower in Π", "message"},
               t, {true, true, false, false, false, false, false, false});
  }
}

void show(const std::string& dirName, std::ostream& os) {
  const fs::path dir(dirName);
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw NotAnOutput{dirName + " does not exist"};
  if (!fs::is_directory(dir, ec)) throw NotAnOutput{dirName + " is not a directory (give the output directory of buckle run)"};
  const std::string generator = scene::outputGenerator(dirName);
  if (generator.empty())
    throw NotAnOutput{dirName + " is not a buckle output: it has no summary.json written by buckle run"};
  if (generator != scene::kRunGenerator)
    throw NotAnOutput{dirName + " is a `" + generator + "` output, not a `buckle run` one; its table is " +
                      (dir / "atlas.csv").string() + " (columns: docs/outputs.md)"};
  const json summary = readJson(dir / "summary.json");
  const json sp = readJson(dir / "special_points.json");

  showHeader(dirName, summary, os);
  showSpecialPoints(sp, os);

  const json& cases = list(summary, "cases");
  std::vector<std::vector<std::string>> rows;
  for (size_t c = 0; c < cases.size(); ++c)
    for (const json& b : list(cases[c], "branches"))
      rows.push_back({std::to_string(c), text(field(b, "id")), text(field(b, "parent")), text(field(b, "origin")),
                      text(field(b, "points")), text(field(b, "stop")), text(field(b, "finished")),
                      text(field(b, "stop_message"))});
  if (rows.empty()) {
    os << "\nbranches: none\n";
  } else {
    os << "\nbranches (" << rows.size() << ", summary.json; points in branches.csv):\n";
    printTable(os, {"case", "id", "parent", "origin", "points", "stop", "finished", "message"}, rows,
               {true, true, true, false, true, false, false, false});
  }

  showAnalyses(sp, os);
  std::vector<std::string> csv;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec))
    if (e.path().extension() == ".csv") csv.push_back(e.path().filename().string());
  std::sort(csv.begin(), csv.end());
  std::string files;
  for (const std::string& f : csv) files += " " + f;
  const json& plots = list(field(summary, "plots"), "files");
  os << "files:" << files << (plots.empty() ? "" : ", " + std::to_string(plots.size()) + " plot images in plots/")
     << " (columns: docs/outputs.md)\n";
}

}  // namespace

void addShowCommand(CLI::App& app, Outcome& outcome, const char* name) {
  auto dir = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      name, "Print the results of a `buckle run` (special points, branches, critical loads) as tables");
  cmd->footer(
      "Reads DIR/summary.json and DIR/special_points.json of a `buckle run` output. Exit status: 0, 2 when DIR is "
      "not the output directory of a `buckle run`.");
  cmd->add_option("dir", *dir, "Output directory of `buckle run`, e.g. out/default")->required();
  cmd->callback([dir, &outcome]() {
    try {
      show(*dir, std::cout);
    } catch (const NotAnOutput& e) {
      std::cerr << "buckle show: " << e.message << "\n";
      outcome.code = kBadInput;
    }
  });
}

}  // namespace buckle::cli
