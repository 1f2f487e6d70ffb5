#include "scene/column_values.h"

#include <cmath>
#include <cstdlib>
#include <limits>
#include <vector>

#include "scene/columns.h"

namespace buckle::scene {

namespace {

double commonColumn(const std::string& c, double parameter, const mechanics::Wrench& F, const mechanics::Pose& pose,
                    const Eigen::VectorXd& q, const mechanics::Pose& pose0, bool& found) {
  found = true;
  if (c == "parameter") return parameter;
  if (c == "Fx") return F[0];
  if (c == "Fy") return F[1];
  if (c == "Me") return F[2];
  if (c == "x") return pose[0];
  if (c == "y") return pose[1];
  if (c == "phi") return pose[2];
  if (c == "dx") return pose0[0] - pose[0];
  if (c == "dy") return pose[1] - pose0[1];
  if (c.size() >= 2 && c[0] == 'q') {
    const int i = std::atoi(c.c_str() + 1);
    return (i >= 1 && i <= q.size()) ? q[i - 1] : kNaN;
  }
  found = false;
  return kNaN;
}

// A task path's input by column name (NaN for a record without it).
double inputValue(const std::string& column, const Eigen::VectorXd& inputs, const std::vector<std::string>* names) {
  if (!names) return kNaN;
  for (size_t j = 0; j < names->size() && Eigen::Index(j) < inputs.size(); ++j)
    if ((*names)[j] == column) return inputs[Eigen::Index(j)];
  return kNaN;
}

}  // namespace

double columnValue(const std::string& column, const mechanics::PointReport& p, const CaseResult& cr) {
  bool found = false;
  const double v = commonColumn(column, p.parameter, p.F, p.pose, p.q, cr.pose0, found);
  if (found) return v;
  if (column == "min_eig") return p.minEigenvalue;
  if (const int i = frequencyIndex(column); i >= 0) return i < p.omega.size() ? p.omega[i] : kNaN;
  if (!cr.inputNames.empty()) {
    const double v = inputValue(column, p.inputs, &cr.inputNames);
    if (!std::isnan(v)) return v;
  }
  return stiffnessColumnValue(column, p.K, p.C, p.rotationalStiffness);
}

double columnValue(const std::string& column, const mechanics::SpecialPointReport& s, const CaseResult& cr) {
  bool found = false;
  const double v = commonColumn(column, s.parameter, s.F, s.pose, s.q, cr.pose0, found);
  if (found) return v;
  if (const int i = frequencyIndex(column); i >= 0) return i < s.omega.size() ? s.omega[i] : kNaN;
  if (!cr.inputNames.empty()) {
    const double v = inputValue(column, s.inputs, &cr.inputNames);
    if (!std::isnan(v)) return v;
  }
  // NaN unless the point carries its own K_F (KMIN)
  return stiffnessColumnValue(column, s.K, Eigen::Matrix2d::Constant(kNaN));
}

}  // namespace buckle::scene
