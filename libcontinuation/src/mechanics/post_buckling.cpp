#include "buckle/mechanics/post_buckling.h"

#include <algorithm>
#include <cmath>
#include <exception>

#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/linear_buckling.h"

namespace buckle::mechanics {

namespace cont = buckle::continuation;

const char* toString(PostBuckling kind) {
  switch (kind) {
    case PostBuckling::Supercritical: return "supercritical";
    case PostBuckling::Subcritical: return "subcritical";
    case PostBuckling::UnstableStart: return "unstable start";
    case PostBuckling::None: return "none";
    case PostBuckling::Failed: return "failed";
  }
  return "failed";
}

FirstBuckling firstBuckling(const Chain& chain, const EndCondition& end, const Eigen::Vector3d& direction,
                            const Eigen::VectorXd& q0) {
  FirstBuckling r;
  try {
    LinearBucklingOptions lbo;
    lbo.direction = direction;
    const LinearBucklingResult lb = linearBuckling(chain, q0, end, lbo);
    r.startStable = lb.unloadedStable;
    const BucklingMode* first = nullptr;
    for (const auto& m : lb.modes)
      if (m.lambda < 0.0 && (!first || std::abs(m.lambda) < std::abs(first->lambda))) first = &m;
    if (first) {
      r.critical = first->lambda;
      r.shape = first->shape;
    }
    if (!r.startStable) {
      r.kind = PostBuckling::UnstableStart;
      return r;
    }
    if (!first) {
      r.kind = PostBuckling::None;
      return r;
    }
    // The straight branch past the first critical load, then a few steps along the branch born
    // at its first branch point (the + side of the bifurcating direction).
    const double lc = first->lambda;
    EquilibriumProblem problem(chain, end, direction);
    EquilibriumBranchOptions opt;
    opt.tracer.step.initialStep = std::min(0.05, 0.2 * std::abs(lc));
    opt.tracer.step.maxStep = 0.1;
    opt.tracer.lambdaMin = 1.3 * lc;
    opt.tracer.lambdaMax = -lc;
    opt.tracer.maxPoints = 400;
    cont::TracerOptions child = opt.tracer;
    child.maxPoints = 8;
    child.step.initialStep = 0.02;
    child.step.maxStep = 0.02;
    opt.tree.childTracer = child;
    opt.tree.branchSwitching = 1;
    opt.contact = false;  // the classification only looks at the branches near the first BP
    opt.tree.switchAt = [lc](const cont::Branch& b, const cont::SpecialPoint& bp) {
      return b.parentId < 0 && std::abs(bp.lambda - lc) <= 1e-6 * std::abs(lc);
    };
    const EquilibriumBranches tree = traceEquilibria(problem, q0, 0.0, cont::InitialDirection::decreasingLambda(), opt);
    const cont::Branch* bifurcated = nullptr;
    for (const cont::Branch& b : tree.tree.branches)
      if (b.parentId == 0 && b.direction > 0) {
        bifurcated = &b;
        break;
      }
    if (!bifurcated) {
      bool located = false;
      for (const cont::SpecialPoint& sp : tree.tree.branches.front().specialPoints)
        located = located || (sp.type == cont::SpecialPointType::BranchPoint && opt.tree.switchAt(tree.tree.branches.front(), sp));
      r.kind = PostBuckling::Failed;
      r.message = located ? "no bifurcating direction" : "first branch point not located on the straight branch";
      return r;
    }
    if (bifurcated->points.size() < 3) {
      r.kind = PostBuckling::Failed;
      r.message = "the new branch could not be followed";
      return r;
    }
    int stable = 0, checked = 0;
    for (size_t i = 1; i < bifurcated->points.size(); ++i) {
      if (!bifurcated->points[i].stability.valid()) continue;
      ++checked;
      if (bifurcated->points[i].stability.stable()) ++stable;
    }
    r.slope = std::abs(bifurcated->points.back().lambda) - std::abs(bifurcated->points.front().lambda);
    r.kind = checked > 0 && stable == checked ? PostBuckling::Supercritical : PostBuckling::Subcritical;
  } catch (const std::exception& e) {
    r.kind = PostBuckling::Failed;
    r.message = e.what();
  }
  return r;
}

}  // namespace buckle::mechanics
