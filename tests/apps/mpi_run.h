// Programs under mpirun for the tests of buckle-mpi (test_cli_atlas_mpi.cpp, test_cli_run_mpi.cpp);
// included only where CMake found MPI and mpiexec (BUCKLE_MPIEXEC).
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include "build_paths.h"

namespace buckle::test {

inline const std::string kBuckleMpi = std::string(BUCKLE_BINARY_DIR) + "/bin/buckle-mpi";

// `mpirun -np RANKS PROGRAM ARGS` (PROGRAM: buckle-mpi unless given), output into `capture`. CI runs as root in a container:
// Open MPI then wants its two permissions, --oversubscribe (more ranks than cores),
// --bind-to none, and no single-copy shared-memory transport (CMA needs ptrace rights that
// containers often lack). Under the sanitizers, complete allocation stacks and the
// suppressions of Open MPI's own leaks (mpi_lsan.supp); ignored in other builds.
inline int mpiExitCode(int ranks, const std::string& args, const std::filesystem::path& capture,
                const std::string& program = kBuckleMpi) {
  const std::string cmd =
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none "
      "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}fast_unwind_on_malloc=0\" "
      "LSAN_OPTIONS=\"${LSAN_OPTIONS:+$LSAN_OPTIONS:}suppressions=" + std::string(BUCKLE_SOURCE_DIR) +
      "/tests/apps/mpi_lsan.supp\" '" BUCKLE_MPIEXEC "' --oversubscribe --bind-to none -np " +
      std::to_string(ranks) + " '" + program + "' " + args + " > '" + capture.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// Occurrences of `what` in `text`.
inline int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace buckle::test
