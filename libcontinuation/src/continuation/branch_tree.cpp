// The bifurcation tree (traceTree, branch_switching.h): the start branches, then breadth first
// the switches at their branch points, on the calling thread or on a pool of workers.
//
// One switch is a job: scheduled on the calling thread, where the guards decide (in the order
// of the branch points, as one thread would), run on a worker (the switch and the children's own
// work, TreeOptions::childWork), and joined to the tree on the calling thread in the order the
// jobs were scheduled. So the tree, its ids and notes do not depend on the number of threads.
#include "buckle/continuation/branch_switching.h"

#include "buckle/continuation/multiplicity_switching.h"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

namespace buckle::continuation {

namespace {

// What is wrong with a tree's options for a problem of dimension n (the symmetry's size too).
std::string treeProblem(const TreeOptions &tree, int n) {
  std::string why = tree.validate();
  if (why.empty() && !tree.symmetry.IsValid(n, &why)) why = "symmetry: " + why;
  return why;
}

// Whether the scaled point x is the start of the child `b`: closer to it than a millionth of
// the child's first step (the distance its own scale sets, in any units).
bool startsAt(const Branch &b, const Vector &x, const UnitScaling &units) {
  if (b.points.size() < 2) return true;
  auto scaled = [&](const ContinuationPoint &p) {
    Vector y(p.u.size() + 1);
    y << p.u, p.lambda;
    for (Eigen::Index j = 0; j < y.size(); ++j) y[j] /= units.state(int(j));
    return y;
  };
  const Vector x0 = scaled(b.points[0]);
  return (x - x0).norm() <= 1e-6 * (scaled(b.points[1]) - x0).norm();
}

// Whether the scaled point x (λ accuracy `accuracy`) is one of those switched at already.
bool switchedBefore(const std::vector<Vector> &switchedAt, const std::vector<double> &switchedAccuracy, const Vector &x,
                    double accuracy) {
  const Eigen::Index n = x.size() - 1;
  for (size_t j = 0; j < switchedAt.size(); ++j) {
    const Vector &y = switchedAt[j];
    const double dl = std::abs(y[n] - x[n]);
    if ((y - x).norm() <= 1e-7 * std::max(1.0, x.norm()) &&
        dl <= std::max({1e3 * (accuracy + switchedAccuracy[j]), 1e-6 * std::max(std::abs(y[n]), std::abs(x[n])),
                        4.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(x[n]))}))
      return true;
  }
  return false;
}

// One switch at branch point k of branch `parent`.
struct SwitchJob {
  std::size_t parent = 0, k = 0;
  SpecialPoint bp;
  std::shared_ptr<Tracer> own;  // TreeOptions::switchTracer's, or null: a new one (runSwitch)
  TreeOptions::ChildWork work;
  std::vector<Branch> sides;
  std::string how;
  std::exception_ptr error;  // what the worker threw, rethrown where the job joins the tree
  enum class State { Queued, Running, Done, Dropped } state = State::Queued;
};

// The switch itself and the children's own work, on the job's own tracer or else on a new one
// for `problem` with `options`: on a workspace of its own, so that no warm start carries over from
// another switch and the children are the same on any thread, in any order.
void runSwitch(SwitchJob &job, const BoundProblem &problem, const TracerOptions &options, const TreeOptions &tree) {
  std::optional<Tracer> fresh;
  if (!job.own) fresh.emplace(BoundProblem(problem.problem()), options);
  Tracer &t = job.own ? *job.own : *fresh;
  if (job.bp.multiplicity > 1) {
    // every solution direction of the m-dimensional reduced equation, both sides
    job.sides = switchMultiple(t, job.bp, tree.switching, &job.how);
  } else {
    // both sides even after a stop (the − side then ends at its first point): a switch that
    // lost a side would shift the ids of every child joined after it, and a stopped run's
    // branch b would not be the complete run's branch b
    job.sides = switchBothSides(t, job.bp, tree.switching, &job.how, nullptr, job.own ? Reflection() : tree.symmetry);
  }
  for (Branch &child : job.sides) {
    child.parentId = static_cast<int>(job.parent);
    child.parentSpecialPoint = static_cast<int>(job.k);
  }
  if (job.work && !job.sides.empty()) job.work(job.sides);
}

// Workers that run the scheduled jobs first in, first out. Jobs are held in a deque, so a
// reference to one stays valid while later ones are added.
class SwitchPool {
 public:
  SwitchPool(const BoundProblem &problem, const TracerOptions &childOptions, const TreeOptions &tree, int threads)
      : problem_(problem), options_(childOptions), tree_(tree) {
    options_.onStep = nullptr;  // not on the caller's thread (TreeOptions::threads)
    options_.onLocated = nullptr;
    for (int w = 0; w < threads; ++w) workers_.emplace_back([this] { work(); });
  }
  ~SwitchPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread &w : workers_) w.join();
  }
  SwitchPool(const SwitchPool &) = delete;
  SwitchPool &operator=(const SwitchPool &) = delete;

  void schedule(SwitchJob &&job) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      jobs_.push_back(std::move(job));
    }
    wake_.notify_one();
  }
  /// Jobs scheduled and not taken by oldest() yet.
  std::size_t pending() {
    std::lock_guard<std::mutex> lock(mutex_);
    return jobs_.size();
  }
  /// The oldest job once it is done (false: none scheduled); `drop` first drops the queued ones.
  bool oldest(SwitchJob &out, bool drop) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (drop)
      for (SwitchJob &j : jobs_)
        if (j.state == SwitchJob::State::Queued) j.state = SwitchJob::State::Dropped;
    if (jobs_.empty()) return false;
    done_.wait(lock, [&] { return jobs_.front().state >= SwitchJob::State::Done; });
    out = std::move(jobs_.front());
    jobs_.pop_front();
    return true;
  }
  /// Whether the oldest job is done (it can be joined without waiting).
  bool oldestDone() {
    std::lock_guard<std::mutex> lock(mutex_);
    return !jobs_.empty() && jobs_.front().state >= SwitchJob::State::Done;
  }

 private:
  void work() {
    for (;;) {
      SwitchJob *job = nullptr;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stopping_ || next() != nullptr; });
        job = next();
        if (stopping_ || !job) return;  // the tree ended (or threw): what is queued is not run
        job->state = SwitchJob::State::Running;
      }
      try {
        runSwitch(*job, problem_, options_, tree_);
      } catch (...) {
        job->error = std::current_exception();
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        job->state = SwitchJob::State::Done;
      }
      done_.notify_all();
    }
  }
  SwitchJob *next() {
    for (SwitchJob &j : jobs_)
      if (j.state == SwitchJob::State::Queued) return &j;
    return nullptr;
  }

  const BoundProblem &problem_;
  TracerOptions options_;
  const TreeOptions &tree_;
  std::vector<std::thread> workers_;
  std::deque<SwitchJob> jobs_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  bool stopping_ = false;
};

class TreeTracer {
 public:
  TreeTracer(const BoundProblem &problem, const TracerOptions &options, const TreeOptions &treeOptions)
      : problem_(problem), options_(options), to_(treeOptions), tracer_(problem, options) {}

  BranchTree run(ConstVectorRef u0, double lambda0, const std::vector<InitialDirection> &starts);

 private:
  // A branch is final once (TreeOptions::onFinal); at the end every branch is.
  void finalize(std::size_t i) {
    if (isFinal_[i]) return;
    isFinal_[i] = 1;
    if (to_.onFinal) to_.onFinal(tree_, i);
  }
  // A branch joins the tree (add) and is extended once its trace has ended (settle).
  void settle(std::size_t i) {
    Branch &b = tree_.branches[i];
    if (to_.extend && b.stopReason != StopReason::InvalidOptions) to_.extend(tree_, b);
    if (tree_.branches[i].stopReason == StopReason::Interrupted) {
      tree_.interrupted = true;
      tree_.message = tree_.branches[i].stopMessage;
    }
  }
  void add(Branch &&b, int generation) {
    b.id = static_cast<int>(tree_.branches.size());
    tree_.branches.push_back(std::move(b));
    depth_.push_back(generation);
    isFinal_.push_back(0);
    if (tree_.branches.back().stopReason != StopReason::Paused) settle(tree_.branches.size() - 1);
    if (to_.onBranch) to_.onBranch(tree_, tree_.branches.back());
  }
  BranchTree &finish() {
    for (std::size_t i = 0; i < tree_.branches.size(); ++i) {
      if (tree_.branches[i].stopReason == StopReason::Paused) {  // stopped early: the tree is interrupted
        Tracer::endPaused(tree_.branches[i], tree_.message.empty() ? "interrupted" : tree_.message);
        settle(i);
      }
      finalize(i);
    }
    return tree_;
  }
  bool interrupted() {
    if (tree_.interrupted) return true;
    if (!options_.interrupt.requested()) return false;
    tree_.interrupted = true;
    tree_.message = options_.interrupt.describe();
    return true;
  }
  // A paused root goes on to its next branch point or end; an interrupt ends it where it stands.
  bool resume(std::size_t i) {
    if (tree_.branches[i].stopReason != StopReason::Paused) return false;
    if (interrupted()) {
      Tracer::endPaused(tree_.branches[i], tree_.message);
    } else {
      tracer_.pauseAtBranchPoints(true);
      tracer_.continueBranch(tree_.branches[i]);
      tracer_.pauseAtBranchPoints(false);
    }
    if (tree_.branches[i].stopReason != StopReason::Paused) settle(i);
    if (to_.onBranch) to_.onBranch(tree_, tree_.branches[i]);
    return true;
  }
  // The guards at branch point k of branch i, one switchAt allows (the notes they write); false:
  // not switched there.
  bool guardsPass(std::size_t i, std::size_t k);
  // Schedules the switch at branch point k of branch i (runs it here without a pool).
  void schedule(std::size_t i, std::size_t k);
  // The children of a done job join the tree, the notes on its branch point say so.
  void join(SwitchJob &job);
  // Joins the jobs done so far in order (all of them, waiting, with `wait`).
  void joinDone(bool wait) {
    if (!pool_) return;
    SwitchJob job;
    while ((wait || pool_->oldestDone()) && pool_->oldest(job, wait && interrupted())) join(job);
  }

  const BoundProblem &problem_;
  const TracerOptions &options_;
  const TreeOptions &to_;
  BranchTree tree_;
  Tracer tracer_;  // the roots'
  std::unique_ptr<SwitchPool> pool_;
  std::vector<int> depth_;
  std::vector<char> isFinal_;
  std::vector<Vector> switchedAt_;
  std::vector<double> switchedAccuracy_;  // |Δλ| of each, scaled
};

bool TreeTracer::guardsPass(std::size_t i, std::size_t k) {
  const SpecialPoint &bp = tree_.branches[i].specialPoints[k];
  const int n = problem_.dimension();
  Vector xBP(n + 1);
  xBP << bp.u, bp.lambda;
  for (int j = 0; j <= n; ++j) xBP[j] /= tracer_.units().state(j);  // compared in the scaled variables
  // The BP a child starts from is the parent's; never switch back at it. Only a child starts
  // at a branch point, and the same point is the one within a millionth of the child's first
  // step from its start: a root's branch points are switched however close to its start they
  // lie (at κ → 0 they crowd at λ ~ κ, 1e-10 of the path's range).
  if (tree_.branches[i].parentId >= 0 && startsAt(tree_.branches[i], xBP, tracer_.units())) return false;
  // The same point located from another branch: near in the state, and in λ within the two
  // locations' accuracy or a millionth of λ itself (distinct points of a cluster at λ ~ 1e-10
  // lie far closer than 1e-7 in the state, but their λ differ by far more than that).
  const double accuracy = bp.lambdaAccuracy / tracer_.units().parameter();
  if (switchedBefore(switchedAt_, switchedAccuracy_, xBP, accuracy)) {
    std::string &note = tree_.branches[i].specialPoints[k].note;
    note += (note.empty() ? "" : "; ") + std::string("already switched from another branch");
    return false;
  }
  switchedAt_.push_back(xBP);
  switchedAccuracy_.push_back(std::isfinite(accuracy) ? accuracy : 0.0);
  return true;
}

void TreeTracer::schedule(std::size_t i, std::size_t k) {
  SwitchJob job;
  job.parent = i;
  job.k = k;
  job.bp = tree_.branches[i].specialPoints[k];
  job.own = to_.switchTracer ? to_.switchTracer(tree_, i, job.bp) : nullptr;
  if (to_.childWork) job.work = to_.childWork(tree_, i, job.bp);
  if (!pool_) {
    runSwitch(job, problem_, to_.childTracer ? *to_.childTracer : options_, to_);
    join(job);
    return;
  }
  // at most threads + 2 switches scheduled and not joined (TreeOptions::threads): a worker that
  // finished is not kept waiting, and memory holds that many switches' children at most
  for (SwitchJob oldest; pool_->pending() >= std::size_t(to_.threads) + 2 && pool_->oldest(oldest, false);)
    join(oldest);
  pool_->schedule(std::move(job));
  joinDone(false);
}

void TreeTracer::join(SwitchJob &job) {
  if (job.state == SwitchJob::State::Dropped) return;  // interrupted before it started
  if (job.error) std::rethrow_exception(job.error);
  const std::size_t i = job.parent, k = job.k;
  if (job.bp.multiplicity > 1) {
    tree_.branches[i].specialPoints[k].branchesPredicted = job.bp.branchesPredicted;
    tree_.branches[i].specialPoints[k].branchesFound = job.bp.branchesFound;
  }
  if (job.sides.empty()) {
    std::string &note = tree_.branches[i].specialPoints[k].note;
    note += (note.empty() ? "" : "; ") + std::string("not switched: ") + job.how;
    return;
  }
  std::string children;
  const std::size_t firstChild = tree_.branches.size();
  for (Branch &child : job.sides) {
    if (child.mirrorOf >= 0) child.mirrorOf += static_cast<int>(firstChild);  // an index into `sides` → a branch id
    children += (children.empty() ? "" : ", ") + std::to_string(tree_.branches.size());
    add(std::move(child), depth_[i] + 1);
  }
  std::string &note = tree_.branches[i].specialPoints[k].note;
  note += (note.empty() ? "" : "; ") + ("switched (" + job.how + "): branches " + children);
  // the children that will not be switched at are final now, after a mirror image joined its source
  for (std::size_t c = firstChild; c < tree_.branches.size(); ++c)
    if (depth_[c] >= to_.branchSwitching) finalize(c);
}

BranchTree TreeTracer::run(ConstVectorRef u0, double lambda0, const std::vector<InitialDirection> &starts) {
  if (const std::string why = treeProblem(to_, problem_.dimension()); !why.empty()) {
    Branch invalid;
    invalid.stopReason = StopReason::InvalidOptions;
    invalid.stopMessage = "TreeOptions: " + why;
    add(std::move(invalid), 0);
    return finish();
  }
  // With switching the roots are traced lazily (header): here up to their first branch point.
  tracer_.pauseAtBranchPoints(to_.branchSwitching > 0);
  for (const InitialDirection &direction : starts) {
    if (interrupted()) return finish();
    add(tracer_.trace(u0, lambda0, direction), 0);
    if (to_.branchSwitching <= 0) finalize(tree_.branches.size() - 1);
  }
  tracer_.pauseAtBranchPoints(false);
  if (to_.threads > 1 && to_.branchSwitching > 0)
    pool_ = std::make_unique<SwitchPool>(problem_, to_.childTracer ? *to_.childTracer : options_, to_, to_.threads);

  for (std::size_t i = 0; i < tree_.branches.size(); ++i) {
    if (depth_[i] >= to_.branchSwitching) continue;
    for (std::size_t k = 0;; ++k) {
      // past the last special point: a paused root goes on (and gains a branch point or its end)
      if (k >= tree_.branches[i].specialPoints.size() && !(resume(i) && k < tree_.branches[i].specialPoints.size()))
        break;
      if (tree_.branches[i].specialPoints[k].type != SpecialPointType::BranchPoint) continue;
      if (to_.switchAt && !to_.switchAt(tree_.branches[i], tree_.branches[i].specialPoints[k])) continue;
      if (interrupted()) {
        joinDone(true);
        return finish();
      }
      if (guardsPass(i, k)) schedule(i, k);
    }
    joinDone(true);  // the children of branch i, before the branches after it
    finalize(i);
  }
  return finish();
}

}  // namespace

BranchTree traceTree(const BoundProblem &problem, ConstVectorRef u0, double lambda0,
                     const std::vector<InitialDirection> &starts, const TracerOptions &options, const TreeOptions &treeOptions) {
  return TreeTracer(problem, options, treeOptions).run(u0, lambda0, starts);
}

BranchTree traceTree(const BoundProblem &problem, ConstVectorRef u0, double lambda0, const InitialDirection &direction,
                     const TracerOptions &options, int maxDepth, const BranchSwitchingOptions &switching) {
  TreeOptions tree;
  tree.branchSwitching = maxDepth;
  tree.switching = switching;
  return traceTree(problem, u0, lambda0, std::vector<InitialDirection>{direction}, options, tree);
}

}  // namespace buckle::continuation
