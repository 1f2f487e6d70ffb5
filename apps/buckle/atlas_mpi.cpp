#include "atlas_mpi.h"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <stdexcept>

#if BUCKLE_WITH_MPI
// The C API only: not the C++ bindings (deprecated since MPI 2.2, removed in MPI 3).
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace buckle::cli {

#if !BUCKLE_WITH_MPI
namespace {

/// The launcher's process count from its environment (1 when not launched by one).
int launcherSize() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
  return 1;
}

}  // namespace
#endif

bool launchedByMpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

MpiWorld::MpiWorld() {
  if (!launchedByMpi()) return;
#if BUCKLE_WITH_MPI
  // FUNNELED: the cells are computed on worker threads, but only this thread calls MPI.
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  initialised_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
  MPI_Comm_size(node, &local_);
  MPI_Comm_free(&node);
#else
  if (launcherSize() > 1)
    throw std::runtime_error("started by mpirun with " + std::to_string(launcherSize()) +
                             " processes, but `buckle` has no MPI: run `mpirun -np N buckle-mpi atlas ...` or "
                             "`mpirun -np N buckle-mpi run ...` (built beside buckle when CMake finds MPI: "
                             "libopenmpi-dev), or buckle without mpirun: it uses all cores on threads");
#endif
}

MpiWorld::~MpiWorld() {
#if BUCKLE_WITH_MPI
  if (initialised_) MPI_Finalize();
#endif
}

int MpiWorld::broadcast(int value) const {
#if BUCKLE_WITH_MPI
  if (initialised_) MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD);
#endif
  return value;
}

std::vector<std::string> MpiWorld::allgather(const std::string& mine) const {
  if (!initialised_) return {mine};
  std::vector<std::string> all;
#if BUCKLE_WITH_MPI
  // Every rank learns every size first, so a total too large for MPI's int counts is refused
  // by all of them alike instead of leaving the others waiting in MPI_Allgatherv.
  unsigned long long size = mine.size();
  std::vector<unsigned long long> sizes(size_t(size_), 0);
  MPI_Allgather(&size, 1, MPI_UNSIGNED_LONG_LONG, sizes.data(), 1, MPI_UNSIGNED_LONG_LONG, MPI_COMM_WORLD);
  unsigned long long total = 0;
  for (unsigned long long s : sizes) total += s;
  if (total > static_cast<unsigned long long>(INT_MAX))
    throw std::runtime_error("the ranks' results (" + std::to_string(total) + " bytes) exceed one MPI message");
  const auto ranks = static_cast<size_t>(size_);
  std::vector<int> counts(ranks, 0), offsets(ranks, 0);
  for (int r = 0, at = 0; r < size_; ++r) {
    counts[size_t(r)] = int(sizes[size_t(r)]);
    offsets[size_t(r)] = at;
    at += counts[size_t(r)];
  }
  std::string received(size_t(total), '\0');
  MPI_Allgatherv(mine.data(), int(mine.size()), MPI_CHAR, received.data(), counts.data(), offsets.data(), MPI_CHAR,
                 MPI_COMM_WORLD);
  for (int r = 0; r < size_; ++r) all.push_back(received.substr(size_t(offsets[size_t(r)]), size_t(counts[size_t(r)])));
#endif
  return all;
}

std::vector<std::string> MpiWorld::gather(const std::string& mine) const {
  std::vector<std::string> all = allgather(mine);
  if (rank_ != 0) all.clear();
  return all;
}

}  // namespace buckle::cli
