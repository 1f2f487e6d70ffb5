// The one registry of a scene's analyses (docs/scenes.md, "How to add an analysis"): for each,
// the key of its block under /analyses and how that block is read, whether a scene asks for it,
// what the run says it computed, and the stage that runs it on every case. The scene parser
// (scene_analyses.cpp) and the runner (runner.cpp) know the analyses only through this table.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/json_reader.h"
#include "scene/scene.h"

namespace buckle::scene {

class CaseRunner;

struct Analysis {
  /// Its block under /analyses; null: it is part of another analysis's block (the branches
  /// through the equilibria, `equilibria` "branches").
  const char* key;
  /// Reads the block at /analyses/key into the scene's analyses (null when key is null). Called in
  /// the registry's order, so a block may check the analyses listed before it.
  void (*parse)(const JsonReader& r, const nlohmann::json& block, const nlohmann::json::json_pointer& at,
                AnalysesSpec& into);
  /// Whether a scene with these analyses asks for it.
  bool (*asked)(const AnalysesSpec& analyses);
  /// What the run says it computed (summary.json `computed`, `buckle show`).
  std::string (*computed)(const Scene& scene);
  /// The stage that runs it on each case, in the registry's order (progress lines, summary.json
  /// `timings_seconds`); null for what is computed within another analysis's stage (stiffness,
  /// frequencies and jumps along the continuation's branches).
  const char* stage;
  void (*run)(CaseRunner& runner);
  /// It may be a scene's only analysis (false: it needs the branches of another).
  bool standalone;
  /// Its work is shared among the processes of a shared run (shared_work.h): the processes that
  /// do not write run this stage alone.
  bool shared = false;
};

/// Every analysis, in the order the stages run.
const std::vector<Analysis>& analyses();

}  // namespace buckle::scene
