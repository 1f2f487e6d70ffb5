#include "regress/command.h"

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <set>

#include "regress/baseline.h"
#include "regress/compare.h"
#include "regress/measurement.h"
#include "scene/json_reader.h"

namespace buckle::regress {

namespace fs = std::filesystem;

namespace {

std::string scenesDirectory(const RegressOptions& o) {
  if (!o.scenes.empty()) return o.scenes;
  fs::path dir = fs::path(o.baselines).lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();  // "data/regression/"
  return (dir.parent_path() / "scenes").string();
}

const char* sourceKey(const Source& s) { return s.kind == Source::Kind::Scene ? "/source/scene" : "/source/problem"; }

/// Every baseline file of the directory, sorted by name; the errors of all bad ones at once.
bool loadAll(const std::string& dir, std::vector<Baseline>& out, std::ostream& err) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".json" && it->path().filename().string()[0] != '.') files.push_back(it->path());
  if (ec) {
    err << "buckle regress: cannot read the baselines directory " << dir << ": " << ec.message() << "\n";
    return false;
  }
  std::sort(files.begin(), files.end());
  bool ok = true;
  std::set<std::string> names;
  for (const fs::path& f : files) {
    try {
      out.push_back(loadBaseline(f.string()));
      if (!names.insert(out.back().name).second)
        throw scene::JsonInputError(f.string(), "/name", "the name \"" + out.back().name + "\" is used by another baseline");
    } catch (const scene::JsonInputError& e) {
      err << "buckle regress: bad baseline: " << e.what() << "\n";
      ok = false;
    }
  }
  return ok;
}

bool selected(const RegressOptions& o, const std::string& name) {
  return o.only.empty() || std::find(o.only.begin(), o.only.end(), name) != o.only.end();
}

/// --only names that match nothing are a typo, not an empty run.
bool checkOnly(const RegressOptions& o, const std::vector<std::string>& names, std::ostream& err) {
  bool ok = true;
  for (const std::string& n : o.only)
    if (std::find(names.begin(), names.end(), n) == names.end()) {
      err << "buckle regress: --only " << n << ": no such baseline";
      if (!names.empty()) err << " (known: " << names.front() << (names.size() > 1 ? ", ..." : "") << ")";
      err << "\n";
      ok = false;
    }
  return ok;
}

void printTable(const std::vector<Row>& rows, std::ostream& out) {
  const char* head[7] = {"case", "quantity", "baseline", "now", "drift", "tolerance", "status"};
  size_t w[6];
  for (int k = 0; k < 6; ++k) w[k] = std::char_traits<char>::length(head[k]);
  for (const Row& r : rows) {
    const std::string* cells[6] = {&r.name, &r.quantity, &r.baseline, &r.now, &r.drift, &r.tolerance};
    for (int k = 0; k < 6; ++k) w[k] = std::max(w[k], std::min<size_t>(cells[k]->size(), 60));
  }
  auto line = [&](const std::string* cells[6], const char* status) {
    for (int k = 0; k < 6; ++k) out << std::left << std::setw(int(w[k])) << *cells[k] << "  ";
    out << status << "\n";
  };
  std::string hs[6];
  const std::string* hp[6];
  for (int k = 0; k < 6; ++k) hp[k] = &(hs[k] = head[k]);
  line(hp, head[6]);
  for (const Row& r : rows) {
    const std::string* cells[6] = {&r.name, &r.quantity, &r.baseline, &r.now, &r.drift, &r.tolerance};
    line(cells, toString(r.status));
  }
}

int update(const RegressOptions& o, std::ostream& out, std::ostream& err) {
  std::vector<Baseline> existing;
  if (fs::exists(o.baselines) && !loadAll(o.baselines, existing, err)) return kBadInput;  // never overwrite a bad file blindly
  // the default set: every scene and every benchmark problem; existing files keep their settings
  const std::string scenes = scenesDirectory(o);
  std::vector<Baseline> todo = existing;
  auto known = [&](const Source& s) {
    return std::any_of(todo.begin(), todo.end(), [&](const Baseline& b) { return b.source.kind == s.kind && b.source.name == s.name && b.source.timeLimit == s.timeLimit; });
  };
  // the scenes and those of its galleries one folder down (hard/x.json: baseline hard_x)
  std::vector<fs::path> sceneFiles;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(scenes, ec), end; !ec && it != end; it.increment(ec)) {
    if (it.depth() > 1 || it->path().extension() != ".json" || !it->is_regular_file()) continue;
    sceneFiles.push_back(fs::relative(it->path(), scenes));
  }
  std::sort(sceneFiles.begin(), sceneFiles.end());
  for (const fs::path& f : sceneFiles) {
    Baseline b;
    b.source = {Source::Kind::Scene, f.generic_string()};
    b.name = f.has_parent_path() ? f.parent_path().generic_string() + "_" + f.stem().string() : f.stem().string();
    if (!known(b.source)) todo.push_back(b);
  }
  for (const std::string& p : problemNames()) {
    Baseline b;
    b.source = {Source::Kind::Problem, p};
    b.name = "auto_" + p;
    if (!known(b.source)) todo.push_back(b);
  }
  std::vector<std::string> names;
  for (const Baseline& b : todo) names.push_back(b.name);
  if (!checkOnly(o, names, err)) return kBadInput;
  std::error_code mk;
  fs::create_directories(o.baselines, mk);
  if (mk) {
    err << "buckle regress: cannot create " << o.baselines << ": " << mk.message() << "\n";
    return kBadInput;
  }
  const std::string machine = machineDescription();
  int code = kAllPass;
  for (const Baseline& settings : todo) {
    if (!selected(o, settings.name)) continue;
    const std::string file = settings.file.empty() ? (fs::path(o.baselines) / (settings.name + ".json")).string() : settings.file;
    Measurement m;
    try {
      // a time-limited baseline stores the complete run's values: a stopped run must agree with them
      m = measure(settings.source, scenes, o.repetitions > 0 ? o.repetitions : settings.repetitions, false);
    } catch (const SourceError& e) {
      err << "buckle regress: " << file << ": " << sourceKey(settings.source) << ": " << e.message << "\n";
      return kBadInput;
    }
    if (!m.complete) {
      // a baseline of a failed computation would pin the failure: leave the old file alone
      err << "buckle regress: " << settings.name << ": the computation did not finish, baseline not written:\n";
      for (const std::string& p : m.problems) err << "  " << p << "\n";
      code = kDrift;
      continue;
    }
    Baseline b = makeBaseline(settings, m, machine);
    if (o.keepTiming && !settings.file.empty()) {
      b.referenceSeconds = settings.referenceSeconds;
      b.machine = settings.machine;
    }
    try {
      writeFileAtomically(file, formatBaseline(b));
    } catch (const std::exception& e) {
      err << "buckle regress: " << e.what() << "\n";
      return kBadInput;
    }
    size_t specials = 0, samples = 0;
    for (const CaseEntry& c : b.cases) {
      specials += c.specials.size();
      samples += c.samples.size();
    }
    out << "wrote " << file << ": " << specials << " special points, " << samples << " branch samples, "
        << b.referenceSeconds << " s\n";
  }
  return code;
}

void writeJson(const std::string& file, const std::vector<Row>& rows, int code) {
  nlohmann::ordered_json doc;
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  size_t failed = 0;
  for (const Row& r : rows) {
    failed += r.status == Status::Fail;
    list.push_back({{"case", r.name}, {"quantity", r.quantity}, {"baseline", r.baseline}, {"now", r.now},
                    {"drift", r.drift}, {"tolerance", r.tolerance}, {"status", toString(r.status)}});
  }
  doc["exit"] = code;
  doc["failed"] = failed;
  doc["rows"] = list;
  writeFileAtomically(file, doc.dump(2) + "\n");
}

}  // namespace

int runRegressCommand(const RegressOptions& o, std::ostream& out, std::ostream& err) {
  if (o.update) return update(o, out, err);
  std::vector<Baseline> baselines;
  if (!loadAll(o.baselines, baselines, err)) return kBadInput;
  if (baselines.empty()) {
    err << "buckle regress: no baselines (*.json) in " << o.baselines << " (write them with --update)\n";
    return kBadInput;
  }
  std::vector<std::string> names;
  for (const Baseline& b : baselines) names.push_back(b.name);
  if (!checkOnly(o, names, err)) return kBadInput;

  const std::string scenes = scenesDirectory(o);
  TimingCheck timing;
  timing.factor = o.timeTolerance;
  std::vector<Row> rows;
  for (const Baseline& b : baselines) {
    if (!selected(o, b.name)) continue;
    if (o.ci && !b.ci) {
      rows.push_back({b.name, "skipped (\"ci\": false)", "-", "-", "-", "-", Status::Info});
      continue;
    }
    try {
      const Measurement m = measure(b.source, scenes, o.repetitions > 0 ? o.repetitions : b.repetitions);
      const std::vector<Row> r = compare(b, m, timing);
      rows.insert(rows.end(), r.begin(), r.end());
    } catch (const SourceError& e) {
      err << "buckle regress: bad baseline: " << b.file << ": " << sourceKey(b.source) << ": " << e.message << "\n";
      return kBadInput;
    }
  }
  printTable(rows, out);
  const size_t failed = size_t(std::count_if(rows.begin(), rows.end(), [](const Row& r) { return r.status == Status::Fail; }));
  const size_t checked = size_t(std::count_if(rows.begin(), rows.end(), [](const Row& r) { return r.status != Status::Info; }));
  const int code = failed ? kDrift : kAllPass;
  out << (failed ? "FAIL: " : "PASS: ") << failed << " of " << checked << " checked quantities drifted beyond tolerance\n";
  if (!o.json.empty()) {
    try {
      writeJson(o.json, rows, code);
    } catch (const std::exception& e) {
      err << "buckle regress: --json: " << e.what() << "\n";
      return kBadInput;
    }
  }
  return code;
}

}  // namespace buckle::regress
