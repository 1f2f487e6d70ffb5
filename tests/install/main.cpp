// Install check: compile and link against an installed buckle through find_package(buckle),
// and call into the library: the inertia of small symmetric matrices on ker C.
#include <buckle/continuation/problem.h>

#include <cmath>
#include <cstdio>

namespace {
int failures = 0;

void check(bool ok, const char* what) {
  std::printf("%s: %s\n", ok ? "ok  " : "FAIL", what);
  if (!ok) ++failures;
}
}  // namespace

int main() {
  using buckle::continuation::Matrix;
  using buckle::continuation::projectedInertia;

  Matrix H(2, 2);
  H << 2.0, 0.0,
       0.0, -1.0;
  const Matrix none(0, 2);  // no constraint rows
  const auto full = projectedInertia(H, none);
  check(full.valid() && full.negative == 1 && full.zero == 0, "diag(2, -1): one negative eigenvalue");
  check(std::abs(full.smallest + 1.0) < 1e-12, "diag(2, -1): smallest eigenvalue is -1");
  check(!full.stable(), "diag(2, -1): unstable");

  Matrix C(1, 2);  // hold the second coordinate: ker C = span(e1), where H is 2
  C << 0.0, 1.0;
  const auto held = projectedInertia(H, C);
  check(held.valid() && held.negative == 0 && held.stable(), "diag(2, -1) on ker [0 1]: stable");
  check(std::abs(held.smallest - 2.0) < 1e-12, "diag(2, -1) on ker [0 1]: eigenvalue 2");

  std::printf("install check: %s\n", failures == 0 ? "passed" : "FAILED");
  return failures == 0 ? 0 : 1;
}
