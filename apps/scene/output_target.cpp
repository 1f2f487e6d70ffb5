#include "scene/output_target.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sys/stat.h>
#include <unistd.h>

namespace buckle::scene {

namespace fs = std::filesystem;

namespace {

// What the writers put into an output directory (output.cpp, plot.cpp, atlas.cpp,
// atlas_command.cpp). A new output file must be added here, or a previous output holding it is
// no longer recognised (tests/apps/test_scene_all.cpp checks every scene's output).
const std::set<std::string> kTopLevelFiles = {"summary.json",       "special_points.json", "branches.csv",
                                              "energy_curves.csv",  "torque_angle.csv",    "sudden_load.csv",
                                              "atlas.csv",          "report.html", "joint_angles.npy",
                                              "critical_curves.csv", "equilibria.csv",
                                              "workspace_map.csv",  "workspace_curves.csv"};
const std::set<std::string> kPlotExtensions = {".png", ".svg", ".gp", ".dat", ".log"};

/// `a` equals `b` or is one of its ancestors (both absolute and canonical).
bool sameOrAncestor(const fs::path& a, const fs::path& b) {
  auto ai = a.begin(), bi = b.begin();
  for (; ai != a.end(); ++ai, ++bi) {
    if (ai->empty()) continue;  // trailing separator
    if (bi == b.end() || *ai != *bi) return false;
  }
  return true;
}

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

/// The summary.json in `dir` parsed (discarded when it is no JSON or cannot be read): read whole
/// and parsed from memory, once for both questions below.
nlohmann::json readSummary(const fs::path& dir) {
  const fs::path summary = dir / "summary.json";
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(summary, ec))) return nlohmann::json(nlohmann::json::value_t::discarded);
  std::ifstream in(summary, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
}

/// The generator marker of a parsed summary.json (outputGenerator).
std::string generatorOf(const nlohmann::json& doc) {
  if (!doc.is_object()) return "";
  if (doc.contains("generator")) {
    const std::string g = doc["generator"].is_string() ? doc["generator"].get<std::string>() : "";
    return g == kRunGenerator || g == kAtlasGenerator ? g : "";
  }
  // Written before the marker existed (schema 0): recognised by the summary's own layout, so
  // that an existing out/ of an earlier version is still replaced without --force.
  auto has = [&doc](std::initializer_list<const char*> keys) {
    for (const char* k : keys)
      if (!doc.contains(k)) return false;
    return true;
  };
  if (has({"scene", "complete", "computed", "solver", "cases", "timings_seconds"})) return kRunGenerator;
  if (has({"x", "y", "fixed", "cells", "failed_cells", "plots"})) return kAtlasGenerator;
  return "";
}

/// summary.json `plots.written` of a parsed summary: every file the run wrote into plots/
/// (none when the summary has no such list).
std::optional<std::set<std::string>> plotsWritten(const nlohmann::json& doc) {
  if (!doc.is_object() || !doc.contains("plots") || !doc["plots"].is_object() || !doc["plots"].contains("written") ||
      !doc["plots"]["written"].is_array())
    return std::nullopt;
  std::set<std::string> files;
  for (const nlohmann::json& f : doc["plots"]["written"])
    if (f.is_string()) files.insert(f.get<std::string>());
  return files;
}

}  // namespace

std::string outputGenerator(const std::string& dirName) { return generatorOf(readSummary(dirName)); }

bool isBuckleOutput(const std::string& dirName, std::string* why) {
  auto no = [why](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  const fs::path dir(dirName);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return no("it is not a directory");
  const nlohmann::json summary = readSummary(dir);
  if (generatorOf(summary).empty())
    return no("it has no summary.json with the \"generator\" marker buckle writes");
  const std::optional<std::set<std::string>> written = plotsWritten(summary);
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    const fs::file_status st = e.symlink_status(ec);
    if (name == "plots" && fs::is_directory(st)) {
      for (const fs::directory_entry& p : fs::directory_iterator(e.path(), ec)) {
        const std::string file = p.path().filename().string();
        // summary.json lists what the run wrote there; an output written before that list
        // existed is recognised by the kinds of files buckle writes
        const bool ours = written ? written->count("plots/" + file) > 0 : kPlotExtensions.count(p.path().extension().string()) > 0;
        if (!fs::is_regular_file(p.symlink_status(ec)) || !ours)
          return no("it contains plots/" + file + ", which buckle did not write");
      }
      continue;
    }
    if (!fs::is_regular_file(st) || !kTopLevelFiles.count(name))
      return no("it contains " + name + ", which buckle does not write");
  }
  if (ec) return no("it cannot be read: " + ec.message());
  return true;
}

std::string checkOutputTarget(const std::string& target, const std::vector<std::string>& inputs, bool force,
                              const std::string& option) {
  const std::string what = option + " " + quoted(target);
  if (target.empty()) throw OutputTargetError(option + " is empty: give the output directory");
  fs::path resolved;
  fs::path cwd;
  try {
    cwd = fs::canonical(fs::current_path());
    // Resolved physically (symbolic links, then "..") as the system will when writing.
    resolved = fs::weakly_canonical(fs::absolute(target));
  } catch (const fs::filesystem_error& e) {
    throw OutputTargetError("cannot resolve " + what + ": " + e.code().message());
  }
  if (resolved.filename().empty() && resolved != resolved.root_path()) resolved = resolved.parent_path();

  // Never, whatever --force says: replacing these destroys what the user is working in or from.
  if (resolved == resolved.root_path()) throw OutputTargetError(what + " is the root directory; refusing to replace it");
  if (resolved == cwd)
    throw OutputTargetError(what + " is the current directory; it would be replaced as a whole. Give a new "
                            "directory, e.g. " + option + " out/NAME");
  if (sameOrAncestor(resolved, cwd))
    throw OutputTargetError(what + " (" + resolved.string() + ") contains the current directory; it would be "
                            "replaced as a whole. Give a new directory, e.g. " + option + " out/NAME");
  std::error_code ec;
  for (const std::string& input : inputs) {
    const fs::path in = fs::weakly_canonical(fs::absolute(input), ec);
    if (ec) continue;
    if (resolved == in || fs::equivalent(resolved, in, ec))
      throw OutputTargetError(what + " is the scene file " + input + "; give an output directory instead");
    if (sameOrAncestor(resolved, in))
      throw OutputTargetError(what + " contains the scene file " + input +
                              ", which would be deleted with it; give another output directory");
  }

  const fs::file_status st = fs::symlink_status(resolved, ec);
  if (fs::is_symlink(st))  // weakly_canonical follows every link that leads somewhere
    throw OutputTargetError(what + " is a symbolic link that leads nowhere (" + resolved.string() + ")");
  if (fs::exists(st)) {
    if (fs::is_directory(st)) {
      struct stat self {}, parent {};
      if (::stat(resolved.c_str(), &self) == 0 && ::stat(resolved.parent_path().c_str(), &parent) == 0 &&
          self.st_dev != parent.st_dev)
        throw OutputTargetError(what + " is a mount point; it cannot be replaced. Give a directory inside it");
      std::string why;
      if (!fs::is_empty(resolved, ec) && !isBuckleOutput(resolved.string(), &why) && !force)
        throw OutputTargetError(what + " is an existing directory that is not a buckle output (" + why +
                                "); nothing was written. Give a new directory, or add --force to replace it and "
                                "everything in it");
    } else if (fs::is_regular_file(st)) {
      if (!force)
        throw OutputTargetError(what + " is an existing file, not an output directory; nothing was written. Give "
                                "a directory, or add --force to replace the file by the output directory");
    } else {
      throw OutputTargetError(what + " exists and is neither a directory nor a regular file; refusing to "
                              "replace it");
    }
  }

  // The staging directory is created beside the target: its parent must be (or become) a
  // writable directory. Probed now so that an unwritable place is bad input, not a failure
  // after the computation.
  fs::path existing = resolved.parent_path();
  while (!fs::exists(fs::symlink_status(existing, ec)) && existing != existing.root_path())
    existing = existing.parent_path();
  if (!fs::is_directory(existing, ec))
    throw OutputTargetError("cannot create " + what + ": " + existing.string() + " is not a directory");
  // The probe is an empty file, not a directory: it holds no disk block, so removing it frees
  // none (a directory holds one, and on a file system mounted with `discard` freeing a block
  // waits for the device's discard).
  std::string probe = (existing / ".buckle-probe-XXXXXX").string();
  const int fd = ::mkstemp(probe.data());
  if (fd < 0)
    throw OutputTargetError("cannot create " + what + ": cannot write in " + existing.string() + ": " +
                            std::strerror(errno));
  ::close(fd);
  ::unlink(probe.c_str());
  return resolved.string();
}

}  // namespace buckle::scene
