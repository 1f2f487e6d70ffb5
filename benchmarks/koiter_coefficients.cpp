// koiter_coefficients: CPU time of Koiter's post-buckling coefficients at the first branch point
// of the straight clamped–pinned chain of the paper's segments (a = 0.5, b = 1, k = 1, L0 = 2.25),
// n segments (N = n + 1 unknowns), with the dense algebra (N×N second derivatives, dense LU;
// up to n = 1000) and the structured one (the chain's O(n) second-derivative products and
// bordered solver), issue 15. The branch point comes from linear_buckling (λc to rounding), its
// null vectors are the buckling mode and e_λ; the coefficients refine them. Best of `reps` runs
// (CPU time of this process), and |b_dense − b_structured| / |b|.
//
//   koiter_coefficients [--reps R]
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <string>

#include "buckle/mechanics/koiter.h"
#include "buckle/mechanics/linear_buckling.h"
#include "common.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {
double cpuSeconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

/// The best CPU time of `reps` evaluations of the coefficients, and the last result.
double timeCoefficients(EquilibriumProblem& p, const cont::SpecialPoint& bp, cont::CoefficientAlgebra algebra,
                        int reps, KoiterCoefficients& k) {
  double t = std::numeric_limits<double>::infinity();
  for (int r = 0; r < reps; ++r) {
    const double t0 = cpuSeconds();
    k = koiterCoefficients(p, bp, algebra);
    t = std::min(t, cpuSeconds() - t0);
  }
  return t;
}
}  // namespace

int main(int argc, char** argv) {
  int reps = 3;
  if (argc == 3 && std::string(argv[1]) == "--reps") reps = std::max(1, std::atoi(argv[2]));
  else if (argc != 1) {
    std::fprintf(stderr, "usage: koiter_coefficients [--reps R]\n");
    return 2;
  }
  std::printf("%6s %14s %14s %14s %12s %s\n", "n", "lambda_c", "b", "dense_s", "structured_s", "rel_diff_b");
  for (int n : {40, 100, 300, 1000, 10000}) {
    EquilibriumProblem p = buckle::bench::clampedPinned(n);
    LinearBucklingOptions lo;
    lo.count = 8;  // O(n) per mode above kStructuredBucklingFrom segments
    const LinearBucklingResult lb =
        linearBuckling(p.chain(), Eigen::VectorXd::Zero(n), EndCondition::clampedPinned(0.0), lo);
    double lambda = -std::numeric_limits<double>::infinity();
    Eigen::VectorXd mode;
    for (const BucklingMode& m : lb.modes)
      if (m.lambda < 0.0 && m.lambda > lambda) {
        lambda = m.lambda;
        mode = m.mode;
      }
    const int N = p.dimension();
    cont::SpecialPoint bp;
    bp.type = cont::SpecialPointType::BranchPoint;
    bp.u = Eigen::VectorXd::Zero(N);
    bp.lambda = lambda;
    bp.tangent = Eigen::VectorXd::Unit(N + 1, N);
    bp.nullVectors = Eigen::MatrixXd::Zero(N + 1, 2);
    bp.nullVectors(N, 0) = 1.0;
    bp.nullVectors.col(1).head(n) = mode;
    KoiterCoefficients dense, fast;
    const double td = n <= 1000 ? timeCoefficients(p, bp, cont::CoefficientAlgebra::Dense, n <= 300 ? reps : 1, dense)
                                : std::numeric_limits<double>::quiet_NaN();
    const double ts = timeCoefficients(p, bp, cont::CoefficientAlgebra::Structured, reps, fast);
    if (!fast.valid) {
      std::fprintf(stderr, "n = %d: %s\n", n, fast.message.c_str());
      return 1;
    }
    std::printf("%6d %14.8e %14.8e %14.6g %12.6g %.2e\n", n, lambda, fast.b, td, ts,
                dense.valid ? std::abs(dense.b - fast.b) / std::abs(fast.b) : std::numeric_limits<double>::quiet_NaN());
    std::fflush(stdout);
  }
  return 0;
}
