#include "scene/runner.h"

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "scene/analyses.h"
#include "scene/branch_stream.h"
#include "scene/case_runner.h"

// Stage dispatch: the analyses a scene asks for (the registry, analyses.h) run case by case in
// the registry's order under the run's time limit; each stage of a case is one CaseRunner call.
namespace buckle::scene {

namespace mech = buckle::mechanics;

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

RunResult runScene(const Scene& scene, const RunControl& given) {
  RunResult run;
  const Clock::time_point start = Clock::now();
  RunControl control = given;
  if (!control.interrupt.hasDeadline()) {
    // The limit bounds the whole run, writing the results included: the computation stops a
    // fifth of the limit (at most 1 s) before it, room for writing a long chain's points and
    // plots (a 50-segment tree stopped at 4.5 s writes its 19 000 points in 0.45 s on an idle
    // machine, twice that on a loaded one).
    const double limit = std::min(scene.solver.timeLimit, 1e9);
    const double compute = limit - std::min(0.2 * limit, 1.0);
    control.interrupt.setDeadline(
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(compute)), limit);
  }
  if (!control.streamTo.empty()) run.stream = std::make_shared<BranchStream>(scene, control.streamTo);
  std::vector<const Analysis*> stages;  // the registry's stages the scene asks for, in its order
  for (const Analysis& x : analyses()) {
    if (!x.asked(scene.analyses)) continue;
    // a process that does not write runs only the work shared among the processes (shared_work.h)
    if (!control.shared.writer() && !x.shared) continue;
    run.computed.push_back(x.computed(scene));
    if (x.stage) stages.push_back(&x);
  }
  std::vector<double> stageSeconds(stages.size(), 0.0);

  std::vector<std::string> skipped;
  run.cases.reserve(scene.cases.size());
  for (const CaseSpec& spec : scene.cases) {
    mech::Chain chain(spec.chain.segments);
    CaseResult& out = run.cases.emplace_back(chain);
    out.label = spec.label;
    out.q0 = spec.chain.q0;
    out.pose0 = mech::endPose(chain, out.q0);
    out.startValue = spec.startValue();
    out.qStart = out.q0;
    CaseRunner runner(scene, spec, out, run, control);
    // recorded in run.problems
    if ((spec.path.control || spec.path.task) && !runner.actuationStart()) continue;
    for (size_t s = 0; s < stages.size(); ++s) {
      if (runner.interrupted()) {
        skipped.push_back(std::string(stages[s]->stage) + (scene.cases.size() > 1 ? " (case \"" + spec.label + "\")" : ""));
        continue;
      }
      if (control.progress)
        control.progress->stage(stages[s]->stage, spec.label, int(&spec - scene.cases.data()), int(scene.cases.size()));
      const Clock::time_point t0 = Clock::now();
      stages[s]->run(runner);
      stageSeconds[s] += secondsSince(t0);
    }
  }
  if (!skipped.empty()) {
    std::string list;
    for (const std::string& k : skipped) list += (list.empty() ? "" : ", ") + k;
    run.problems.push_back("not run after the stop: " + list);
  }
  for (size_t s = 0; s < stages.size(); ++s) run.timings.emplace_back(stages[s]->stage, stageSeconds[s]);
  run.totalSeconds = secondsSince(start);
  return run;
}

}  // namespace buckle::scene
