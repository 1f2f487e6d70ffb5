// A task path from the chain's loaded pose along a straight line, as the task-path tests follow it.
#pragma once

#include <Eigen/Core>

#include "buckle/mechanics/task_path.h"
#include "buckle/mechanics/task_path_trace.h"

namespace buckle::test {

/// The straight task path from the start pose by (dx, dy)·L, corrector tolerance 1e-12, at most
/// 2000 points.
inline mechanics::TaskPathResult followTaskPath(mechanics::TaskPathProblem& p, const Eigen::VectorXd& q0, double dx,
                                                double dy, double L = 1.0) {
  const mechanics::Pose pose = mechanics::endPose(p.chain(), q0);
  Eigen::VectorXd to(2);
  to << pose[0] + dx * L, pose[1] + dy * L;
  mechanics::TaskPathOptions opt;
  opt.tracer.corrector.tolerance = 1e-12;
  opt.tracer.maxPoints = 2000;
  return mechanics::traceTaskPath(p, q0, {to}, p.chain().length(), opt);
}

}  // namespace buckle::test
