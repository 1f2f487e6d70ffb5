// Running a scene given as text through `buckle run`'s entry point, in a scratch directory: what
// the scene tests that feed the program hand-written (often bad) scenes share.
#pragma once

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "scene/command.h"
#include "temp_dir.h"

namespace buckle::test {

struct SceneOutcome {
  int rc;
  std::string err;                  ///< what the program wrote to stderr
  std::filesystem::path file, out;  ///< the scene file and the output directory asked for
};

/// Writes `text` to scratchDirectory(tag)/name/scene.json (the directory emptied first) and runs
/// it with the output directory name/out beside it.
inline SceneOutcome runSceneText(const std::string& tag, const std::string& name, const std::string& text) {
  const std::filesystem::path dir = scratchDirectory(tag) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "scene.json";
  std::ofstream(file) << text;
  buckle::scene::RunCommandOptions opt;
  opt.scene = file.string();
  opt.out = (dir / "out").string();
  std::ostringstream log, err;
  const int rc = buckle::scene::runSceneCommand(opt, log, err);
  return {rc, err.str(), file, dir / "out"};
}

/// `s` with the first `from` replaced by `to` (the test fails if there is none): a scene text
/// edited into a bad one.
inline std::string replaceOnce(std::string s, const std::string& from, const std::string& to) {
  const size_t pos = s.find(from);
  REQUIRE(pos != std::string::npos);
  return s.replace(pos, from.size(), to);
}

}  // namespace buckle::test
