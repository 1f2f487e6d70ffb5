// Which way a chain goes after its first buckling: the first compressive critical load of the
// start configuration (linear_buckling.h) and the stability of the branch born there, traced a
// few steps by the core's tree driver (equilibrium_branches.h). Supercritical: the bifurcated
// branch is stable under force control (benign buckling); subcritical: it is not (the chain
// jumps at the critical load).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/end_condition.h"

namespace buckle::mechanics {

enum class PostBuckling { Supercritical, Subcritical, UnstableStart, None, Failed };

/// "supercritical", "subcritical", "unstable start", "none", "failed".
const char* toString(PostBuckling kind);

struct FirstBuckling {
  bool startStable = false;     ///< K_q positive definite on ker J_h at zero load
  double critical = std::numeric_limits<double>::quiet_NaN();  ///< first compressive λ (NaN: none)
  std::string shape;            ///< name of its mode
  PostBuckling kind = PostBuckling::None;
  /// d|λ| along the bifurcated branch over its first steps (> 0: the load keeps rising).
  double slope = 0.0;
  std::string message;          ///< why kind == Failed
};

/// The first buckling of the chain at q0 under the load direction d (λ < 0: compression along
/// d). Never throws: failures are reported in `error`.
FirstBuckling firstBuckling(const Chain& chain, const EndCondition& end, const Eigen::Vector3d& direction,
                            const Eigen::VectorXd& q0);

}  // namespace buckle::mechanics
