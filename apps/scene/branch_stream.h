// The rows of branches.csv and joint_angles.npy written while the tree is traced: each branch's
// rows go to spool files as soon as the branch is final (CaseRunner::record), so its points need
// not be held until the end; writing the outputs then copies the rows in the order the in-memory
// writer has them (case by case, each case's continuation branches by id), byte for byte the
// same files.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "buckle/mechanics/branch_report.h"
#include "scene/branch_rows.h"

namespace buckle::scene {

class BranchStream {
 public:
  /// Rows held in memory up to `inMemoryBytes` per file, then in spool files in `directory` (which
  /// exists), unlinked as soon as they are open: nothing is left behind, whatever ends the program.
  BranchStream(const Scene& scene, const std::string& directory, size_t inMemoryBytes = kInMemoryBytes);
  /// A small run's rows stay in memory (no spool file to create, fill and copy: most of a short
  /// run's file-system work); a large one's memory stays bounded by this.
  static constexpr size_t kInMemoryBytes = size_t(4) << 20;
  ~BranchStream();
  BranchStream(const BranchStream&) = delete;
  BranchStream& operator=(const BranchStream&) = delete;

  /// Writes the rows of `points` (one branch's, in order, of case `c`), kept as one piece.
  void add(size_t c, const CaseResult& cr, const std::vector<mechanics::PointReport>& points);
  /// The pieces of case `c` written so far.
  size_t pieces(size_t c) const { return c < cases_.size() ? cases_[c].size() : 0; }
  /// Orders case `c`'s pieces from `first` on by branch id, keeping the order of equal ids (as
  /// the continuation stage orders its points).
  void sortByBranch(size_t c, size_t first);
  /// Rows written, over every case.
  size_t rows() const { return rows_; }
  /// The branch ids of case `c`'s rows, piece by piece (a row's branch is its piece's).
  std::vector<int> branchIds(size_t c) const;
  /// Writes dir/branches.csv (and dir/joint_angles.npy for a long chain).
  void write(const std::string& dir) const;

 private:
  struct Piece {
    int branch = -1;
    size_t rows = 0;
    size_t csvOffset = 0, csvBytes = 0, npyOffset = 0, npyBytes = 0;
  };
  struct Spool {
    int fd = -1;         ///< the spool file, once the rows outgrew `memory`
    size_t size = 0;     ///< bytes written, in memory or in the file
    std::string memory;  ///< the rows while they fit in kInMemoryBytes
  };
  void append(Spool& spool, const std::string& bytes);
  void copy(const Spool& spool, size_t offset, size_t bytes, int to, const std::string& file) const;

  BranchRows layout_;
  std::string directory_;
  size_t inMemoryBytes_;
  Spool csv_, npy_;
  /// One branch's rows before they go to a spool: its capacity kept from branch to branch up to
  /// the in-memory size (no fresh pages to fault in and copy into as it grows, once per branch)
  std::string rowsText_;
  std::vector<std::vector<Piece>> cases_;
  size_t rows_ = 0;
};

}  // namespace buckle::scene
