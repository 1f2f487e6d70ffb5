// buckle: command-line front end of the dual-triangle chain mechanics.
// Subcommands are registered here, each implemented in its own <name>_command.cpp.
// Compiled twice: `buckle` (every subcommand, no MPI) and, with BUCKLE_MPI_PROGRAM, `buckle-mpi`
// (the atlas and the scene runner, for mpirun): only the program that needs MPI loads its libraries at start-up.
#include <CLI/CLI.hpp>
#include <cstring>
#include <iostream>
#if defined(__GLIBC__)
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#endif

#include "command.h"
#include "critical_command.h"
#include "atlas_command.h"
#include "regress_command.h"
#include "run_command.h"
#include "show_command.h"

#if defined(__GLIBC__)
namespace {
// Each 4 kB page the heap touches first costs a page fault, and under a hypervisor a costly one
// (a tree of a few thousand points touches thousands: benchmarks/RESULTS.md). Grow the heap by its
// top pad now and ask for transparent huge pages on it (honoured where the kernel's THP mode is
// `madvise` or `always`), as glibc's own tunable glibc.malloc.hugetlb=1 does.
void adviseHugePagesForHeap() {
  const auto low = reinterpret_cast<std::uintptr_t>(sbrk(0));
  void* volatile grow = std::malloc(1 << 20);  // volatile: a malloc/free pair may be elided
  std::free(grow);
  const auto high = reinterpret_cast<std::uintptr_t>(sbrk(0));
  constexpr std::uintptr_t kHuge = std::uintptr_t(2) << 20;
  const std::uintptr_t from = (low + kHuge - 1) & ~(kHuge - 1), to = high & ~(kHuge - 1);
  if (high > low && to > from) madvise(reinterpret_cast<void*>(from), to - from, MADV_HUGEPAGE);
}
}  // namespace
#endif

int main(int argc, char** argv) {
#if defined(__GLIBC__)
  // Outside the tracer's preallocated hot loop, a tree allocates and frees large blocks again and
  // again (dense location systems, branch reports, the outputs' strings of megabytes). With glibc's adaptive defaults the freed heap top is
  // returned to the kernel (brk trims, TLB flushes) and faulted back in, blocks above 128 kB are
  // mapped and unmapped each time: ~10 % of a 50-segment tree's CPU went to page faults
  // (benchmarks/RESULTS.md, issue 13). Keep up to 64 MB of freed heap; map only blocks of 32 MB
  // and more.
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
  mallopt(M_TOP_PAD, 16 << 20);
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  // One heap for every thread: the tree's workers (TreeOptions::threads) allocate a child's
  // points and report and the main thread frees them, so per-thread arenas would each keep
  // their own freed 64 MB above (benchmarks/RESULTS.md, issue 27). The workers' allocations
  // are per branch, not per point (the tracer's loop allocates nothing): no contention.
  mallopt(M_ARENA_MAX, 1);
  adviseHugePagesForHeap();
#endif
#if BUCKLE_MPI_PROGRAM
  CLI::App app{"buckle-mpi: `buckle atlas` and `buckle run` shared among the processes of mpirun (mpirun -np N "
               "buckle-mpi atlas|run ...)"};
  app.set_version_flag("--version", std::string("buckle-mpi ") + BUCKLE_VERSION);
#else
  CLI::App app{"buckle: mechanics of compliant serial manipulators made of dual-triangle segments"};
  app.set_version_flag("--version", std::string("buckle ") + BUCKLE_VERSION);
#endif
  app.require_subcommand(1);
  buckle::cli::Outcome outcome;
  struct Subcommand {
    const char* name;
    void (*add)(CLI::App&, buckle::cli::Outcome&, const char*);
  };
  static const Subcommand kSubcommands[] = {
#if !BUCKLE_MPI_PROGRAM
      {"critical", buckle::cli::addCriticalCommand},
#endif
      {"run", buckle::cli::addRunCommand},
      {"atlas", buckle::cli::addAtlasCommand},
#if !BUCKLE_MPI_PROGRAM
      {"regress", buckle::cli::addRegressCommand},
      {"show", buckle::cli::addShowCommand},
#endif
  };
  // A named subcommand: only its options are set up (the others' would cost a run's start-up
  // for nothing); the program's own --help and --version list them all. CLI11 would only say "A
  // subcommand is required" for a mistyped one: name it.
  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    const Subcommand* chosen = nullptr;
    for (const Subcommand& sub : kSubcommands) {
      if (std::strcmp(sub.name, argv[1]) == 0) chosen = &sub;
      names += (names.empty() ? "" : ", ") + std::string(sub.name);
    }
    if (!chosen) {
      std::cerr << "error: unknown subcommand \"" << argv[1] << "\" (one of: " << names << "; see buckle --help)\n";
      return buckle::cli::kBadInput;
    }
    chosen->add(app, outcome, chosen->name);
  } else {
    for (const Subcommand& sub : kSubcommands) sub.add(app, outcome, sub.name);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help / version (code 0) or the error message
    return code == 0 ? buckle::cli::kSuccess : buckle::cli::kBadInput;
  } catch (const buckle::cli::BadArgument& e) {
    std::cerr << "error: " << e.message << "\n";
    return buckle::cli::kBadInput;
  }
  return outcome.code;
}
