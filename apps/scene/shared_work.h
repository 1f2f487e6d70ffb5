// The processes that share one scene run (`mpirun -np N buckle-mpi run SCENE`): part 0 runs the
// whole scene and writes it; the others run only the stages whose work is shared (a workspace
// map's rows, mechanics::WorkspaceShare) and write nothing. How the bytes travel is the caller's
// (MPI in apps/buckle/atlas_mpi.cpp); the scene layer knows nothing of MPI.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace buckle::scene {

struct SharedWork {
  int part = 0, parts = 1;
  /// Worker threads per process where the scene leaves them to the machine (0: all cores): the
  /// processes on one machine share its cores.
  int threads = 0;
  /// Collective over the parts: every part's `mine` in part order, for the parts that called it
  /// with the same `tag`, and "" for a part at another exchange (it skipped this one, interrupted,
  /// or has finished), whose share the caller then computes itself.
  std::function<std::vector<std::string>(const std::string& tag, const std::string& mine)> exchange;
  bool shared() const { return parts > 1 && exchange != nullptr; }
  /// The part that runs the whole scene and writes its output (a process alone always does).
  bool writer() const { return !shared() || part == 0; }
};

}  // namespace buckle::scene
