#include "buckle/continuation/symmetry.h"

#include <algorithm>
#include <cmath>

namespace buckle::continuation {

bool Reflection::IsValid(int n, std::string *why) const {
  if (!enabled()) return true;
  if (signs.size() != n) {
    if (why) *why = "reflection signs must have one entry per unknown";
    return false;
  }
  for (Eigen::Index i = 0; i < signs.size(); ++i)
    if (signs[i] != 1.0 && signs[i] != -1.0) {
      if (why) *why = "reflection signs must be +1 or -1";
      return false;
    }
  if (!(tolerance > 0.0 && tolerance < 1.0)) {
    if (why) *why = "reflection tolerance must lie in (0, 1)";
    return false;
  }
  return true;
}

void Reflection::apply(VectorRef x) const {
  const Eigen::Index n = signs.size();
  if (n == 0 || (x.size() != n && x.size() != n + 1)) return;
  x.head(n).array() *= signs.array();  // λ (entry n of a state) is fixed
}

bool Reflection::maps(ConstVectorRef x, int sign) const {
  const Eigen::Index n = signs.size();
  if (n == 0 || x.size() != n + 1) return false;
  // diag(S, 1)x − sign·x: for sign +1 twice the odd part, for −1 twice the even part (λ included)
  double d2 = 0.0;
  for (Eigen::Index i = 0; i <= n; ++i) {
    const double s = i < n ? signs[i] : 1.0;
    const double d = (s - sign) * x[i];
    d2 += d * d;
  }
  return std::sqrt(d2) <= tolerance * std::max(1.0, x.norm());
}

void reflect(const Reflection &r, ContinuationPoint &p) {
  r.apply(p.u);
  r.apply(p.tangent);
  // λ, arclength, stability, t_λ, the determinant (det(S)² = 1) and the spectrum are invariant
}

void reflect(const Reflection &r, SpecialPoint &p) {
  r.apply(p.u);
  r.apply(p.tangent);
  for (Eigen::Index c = 0; c < p.nullVectors.cols(); ++c) {
    Vector column = p.nullVectors.col(c);
    r.apply(column);
    p.nullVectors.col(c) = column;
  }
  r.apply(p.leftNullVector);
  p.boundaryName = r.mapText(p.boundaryName);
  p.note = r.mapText(p.note);
}

Branch reflected(const Reflection &r, const Branch &branch) {
  Branch image = branch;
  for (ContinuationPoint &p : image.points) reflect(r, p);
  for (SpecialPoint &sp : image.specialPoints) reflect(r, sp);
  image.stopMessage = r.mapText(image.stopMessage);
  return image;
}

}  // namespace buckle::continuation
