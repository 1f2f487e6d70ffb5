// `buckle atlas` and `buckle run` across processes. Started by mpirun (or another MPI launcher), every rank
// computes its share of the cells (scene::AtlasShare) on its own threads and rank 0 gathers
// them and writes the output; started without one, MPI is never initialised and the atlas runs
// on threads alone, as on any machine without MPI. The only unit that includes <mpi.h>, and only
// in `buckle-mpi` (BUCKLE_WITH_MPI=1); `buckle` compiles it without MPI, so that no command pays
// for loading the MPI libraries. The libraries and the other subcommands know nothing of MPI.
#pragma once

#include <string>
#include <vector>

namespace buckle::cli {

/// True when the environment is an MPI launcher's: Open MPI's OMPI_COMM_WORLD_SIZE, PMIx's
/// PMIX_RANK, MPICH/Hydra's PMI_SIZE.
bool launchedByMpi();

/// The processes of an MPI launch for the life of the object (MPI_Init ... MPI_Finalize), or a
/// world of this one process, without MPI, when not launched by MPI.
class MpiWorld {
 public:
  /// Throws std::runtime_error when launched by MPI with more than one process but compiled
  /// without MPI (`buckle`): every process would compute the whole atlas and write the same
  /// output; the message names `buckle-mpi`.
  MpiWorld();
  ~MpiWorld();
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;

  /// MPI was initialised (launched by mpirun, even with one process).
  bool distributed() const { return initialised_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  /// Processes of this launch on this machine (they share its cores).
  int ranksOnThisNode() const { return local_; }

  /// Rank 0's value, on every rank.
  int broadcast(int value) const;
  /// Every rank's bytes on every rank, in rank order. Collective: every rank calls it. Throws
  /// std::runtime_error on every rank alike when the total exceeds what one MPI message can
  /// count (2^31 − 1 bytes).
  std::vector<std::string> allgather(const std::string& mine) const;
  /// allgather's result on rank 0, empty on the others.
  std::vector<std::string> gather(const std::string& mine) const;

 private:
  bool initialised_ = false;
  int rank_ = 0, size_ = 1, local_ = 1;
};

}  // namespace buckle::cli
