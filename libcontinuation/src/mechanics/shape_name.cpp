#include "buckle/mechanics/shape_name.h"

#include <cmath>

namespace buckle::mechanics {

int signChanges(const Eigen::Ref<const Eigen::VectorXd>& v, double tolerance) {
  int changes = 0, last = 0;
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (!(std::abs(v[i]) > tolerance)) continue;
    const int s = v[i] > 0 ? 1 : -1;
    if (last != 0 && s != last) ++changes;
    last = s;
  }
  return changes;
}

std::string shapeName(const Eigen::Ref<const Eigen::VectorXd>& q, double straightTolerance) {
  if (q.size() == 0 || q.cwiseAbs().maxCoeff() <= straightTolerance) return "straight";
  if (q.size() == 3) {
    int s[3];
    for (int i = 0; i < 3; ++i) {
      if (!(std::abs(q[i]) > straightTolerance)) return "other";
      s[i] = q[i] > 0 ? 1 : -1;
    }
    if (s[1] == -s[0] && s[2] == s[1]) return "U";  // (−,+,+) or (+,−,−)
    if (s[1] == -s[0] && s[2] == s[0]) return "Z";  // (−,+,−) or (+,−,+)
    return "other";
  }
  Eigen::VectorXd theta(q.size());
  double t = 0.0;
  for (Eigen::Index i = 0; i < q.size(); ++i) theta[i] = (t += q[i]);
  return "mode " + std::to_string(signChanges(theta, straightTolerance));
}

std::string modeShapeName(const Eigen::Ref<const Eigen::VectorXd>& z, double relativeTolerance) {
  if (z.size() == 0) return "straight";
  const double scale = z.cwiseAbs().maxCoeff();
  if (!(scale > 0.0)) return "straight";
  return shapeName(z / scale, relativeTolerance);
}

}  // namespace buckle::mechanics
