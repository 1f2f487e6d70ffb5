// The rows of branches.csv and joint_angles.npy (docs/outputs.md): one point of a branch as text
// and as bytes, written alike whether a run's points are held until the end or streamed as each
// branch is final (branch_stream.h).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "buckle/mechanics/branch_report.h"
#include "scene/runner.h"
#include "scene/scene.h"

namespace buckle::scene {

/// Above this many segments branches.csv carries max_abs_q and sign_changes instead of the joint
/// angles, which go to joint_angles.npy (docs/outputs.md).
constexpr int kBranchesCsvJointColumns = 12;

/// The columns of a scene's branches.csv, fixed once per run.
class BranchRows {
 public:
  explicit BranchRows(const Scene& scene);
  /// The joint angles go to joint_angles.npy (more than kBranchesCsvJointColumns segments).
  bool sideFile() const { return sideFile_; }
  /// The header line, with its newline.
  std::string header() const;
  /// Appends the row of point `p` of case `c` (`cr`: its start pose, its task inputs' names).
  void appendRow(std::string& out, size_t c, const CaseResult& cr, const mechanics::PointReport& p) const;
  /// Appends the point's joint angles as little-endian float64, NaN past its chain's length.
  void appendJointAngles(std::string& out, const mechanics::PointReport& p) const;
  /// The .npy header (format 1.0: magic, a Python-dict header padded to 64 bytes) of `rows` rows.
  std::string jointAnglesHeader(size_t rows) const;
  /// About the bytes of a row (to reserve).
  size_t jointAnglesRowBytes() const { return sizeof(double) * size_t(n_); }
  size_t rowBytes() const { return size_t(20 + 19 * (sideFile_ ? 13 : 11 + n_)); }

 private:
  int n_;
  bool sideFile_;
  bool stiffness_;
  bool self_;        // self contact traced: the self and self_force columns
  int frequencies_;  // count of omega columns (0: none)
  std::vector<std::string> inputs_;
};

}  // namespace buckle::scene
