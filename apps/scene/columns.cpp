#include "scene/columns.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

namespace buckle::scene {

namespace {

struct Entry {
  const char* column;
  const char* gnuplot;  // enhanced text
  const char* plain;    // Unicode, for HTML and terminals
  Dimension dimension;
};

const Entry kColumns[] = {
      {"Fx", "F_x", "Fx", Dimension::Force},
      {"Fy", "F_y", "Fy", Dimension::Force},
      {"Me", "M_e", "Me", Dimension::Moment},
      {"x", "x", "x", Dimension::Length},
      {"y", "y", "y", Dimension::Length},
      {"dx", "{/Symbol d}_x = x_0 - x", "δx = x₀ − x", Dimension::Length},
      {"dy", "{/Symbol d}_y = y - y_0", "δy = y − y₀", Dimension::Length},
      {"phi", "{/Symbol f}", "φ", Dimension::Angle},
      // control inputs (the path parameter of a control path, control_path.h)
      {"L1_0", "L_1^0", "L1⁰", Dimension::Length},
      {"L2_0", "L_2^0", "L2⁰", Dimension::Length},
      {"L0", "L^0 = (L_1^0 + L_2^0)/2", "L⁰ = (L1⁰ + L2⁰)/2", Dimension::Length},
      {"dL0", "{/Symbol D}L^0 = L_1^0 - L_2^0", "ΔL⁰ = L1⁰ − L2⁰", Dimension::Length},
      // the gravity magnitude (the path parameter of a gravity path, /gravity)
      {"gravity", "g", "g", Dimension::Acceleration},
      {"min_eig", "smallest eigenvalue of the stability operator", "smallest eigenvalue of the stability operator",
       Dimension::Moment},
      {"Kxx", "K_{xx}", "Kxx", Dimension::Stiffness},
      {"Kyy", "K_{yy}", "Kyy", Dimension::Stiffness},
      {"Kxy", "K_{xy}", "Kxy", Dimension::Stiffness},
      {"Cxx", "C_{xx}", "Cxx", Dimension::Compliance},
      {"Cyy", "C_{yy}", "Cyy", Dimension::Compliance},
      {"Cxy", "C_{xy}", "Cxy", Dimension::Compliance},
      {"Kx_yfree", "1/C_{xx} (y free)", "1/Cxx (y free)", Dimension::Stiffness},
      {"Ky_xfree", "1/C_{yy} (x free)", "1/Cyy (x free)", Dimension::Stiffness},
      {"K1", "K_1 (softest principal)", "K1 (softest principal)", Dimension::Stiffness},
      {"K2", "K_2 (stiffest principal)", "K2 (stiffest principal)", Dimension::Stiffness},
      {"theta1", "{/Symbol q}_1 (direction of K_1)", "θ1 (direction of K1)", Dimension::Angle},
      {"Kphi", "K_{/Symbol f} (end rotation, forces unchanged)", "Kφ (end rotation, forces unchanged)",
       Dimension::RotationalStiffness},
};

}  // namespace

std::vector<std::string> frequencyColumns(int count) {
  std::vector<std::string> out;
  for (int i = 1; i <= count; ++i) out.push_back("omega" + std::to_string(i));
  return out;
}

int frequencyIndex(const std::string& column) {
  constexpr size_t prefix = 5;  // "omega"
  if (column.size() <= prefix || column.size() > prefix + 3 || column.compare(0, prefix, "omega") != 0) return -1;
  int i = 0;
  for (size_t k = prefix; k < column.size(); ++k) {
    if (column[k] < '0' || column[k] > '9') return -1;
    i = 10 * i + (column[k] - '0');
  }
  return column[prefix] == '0' ? -1 : i - 1;
}

// A task path's input of one segment, "dL0[3]": the input's name and the segment ("" if not that form).
static std::string segmentInput(const std::string& c, std::string& segment) {
  const size_t open = c.find('[');
  if (open == std::string::npos || c.empty() || c.back() != ']') return "";
  segment = c.substr(open + 1, c.size() - open - 2);
  return c.substr(0, open);
}

Dimension columnDimension(const std::string& c) {
  std::string segment;
  const std::string input = segmentInput(c, segment);
  if (!input.empty()) return columnDimension(input);
  for (const Entry& e : kColumns)
    if (c == e.column) return e.dimension;
  if (frequencyIndex(c) >= 0) return Dimension::AngularFrequency;
  return c.size() >= 2 && c[0] == 'q' ? Dimension::Angle : Dimension::None;
}

std::string columnLabel(const std::string& c, const UnitSystem& units, LabelStyle style) {
  const bool gnuplot = style == LabelStyle::Gnuplot;
  std::string segment;
  if (const std::string input = segmentInput(c, segment); !input.empty())
    for (const Entry& e : kColumns)
      if (input == e.column)
        return std::string(gnuplot ? e.gnuplot : e.plain) + " of segment " + segment + units.suffix(e.dimension);
  for (const Entry& e : kColumns)
    if (c == e.column) return (gnuplot ? e.gnuplot : e.plain) + units.suffix(e.dimension);
  if (c.size() >= 2 && c[0] == 'q') return (gnuplot ? "q_{" + c.substr(1) + "}" : c) + units.suffix(Dimension::Angle);
  if (frequencyIndex(c) >= 0)
    return (gnuplot ? "{/Symbol w}_{" + c.substr(5) + "}" : "ω" + c.substr(5)) + units.suffix(Dimension::AngularFrequency);
  return c;
}

const std::vector<std::string>& stiffnessColumns() {
  static const std::vector<std::string> kColumns = {"Kxx", "Kyy", "Kxy", "Cxx",      "Cyy",      "Cxy",
                                                    "Kx_yfree", "Ky_xfree", "K1", "K2", "theta1", "Kphi"};
  return kColumns;
}

double stiffnessColumnValue(const std::string& column, const Eigen::Matrix2d& K, const Eigen::Matrix2d& C,
                            double rotationalStiffness) {
  if (column == "Kphi") return rotationalStiffness;
  if (column.size() == 3 && (column[0] == 'K' || column[0] == 'C') && column[1] != '1' && column[1] != '2') {
    const Eigen::Matrix2d& M = column[0] == 'K' ? K : C;
    const int i = column[1] == 'y', j = column[2] == 'y';
    // a point that carries only K_F (KMIN) has C_F = K_F⁻¹ where K_F is regular
    if (column[0] == 'C' && !C.allFinite() && K.allFinite() && K.determinant() != 0.0) return K.inverse()(i, j);
    return M(i, j);
  }
  const Eigen::Matrix2d Cf = C.allFinite() || !K.allFinite() || K.determinant() == 0.0 ? C : Eigen::Matrix2d(K.inverse());
  // K_F undefined where C_F is finite: C_F is singular (the library's `rigid`), and what rounding
  // left of its zero eigenvalue (C_xx of the straight chain is 1e-17 of C_yy, of either sign) is
  // an infinite stiffness, not a huge one
  const bool rigid = !K.allFinite() && Cf.allFinite();
  const double zero = rigid ? 64.0 * std::numeric_limits<double>::epsilon() * Cf.norm() : 0.0;
  auto reciprocal = [zero](double c) { return std::abs(c) <= zero ? std::numeric_limits<double>::infinity() : 1.0 / c; };
  // along x with y free (Fy unchanged): δx = Cxx δFx, so 1/Cxx; a rigid direction (Cxx = 0) is +inf
  if (column == "Kx_yfree") return reciprocal(Cf(0, 0));
  if (column == "Ky_xfree") return reciprocal(Cf(1, 1));
  if (column != "K1" && column != "K2" && column != "theta1") return kNaN;
  // principal stiffnesses: K_F = C_F⁻¹ shares C_F's eigenvectors, with reciprocal eigenvalues; from
  // C_F they stay defined where K_F has a rigid (infinite) direction
  if (!Cf.allFinite()) {
    if (!K.allFinite()) return kNaN;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig;
    eig.computeDirect(K);
    if (column == "theta1") return std::atan(eig.eigenvectors()(1, 0) / eig.eigenvectors()(0, 0));
    return eig.eigenvalues()[column == "K1" ? 0 : 1];
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig;
  eig.computeDirect(Cf);
  // eigenvalues of C ascending; stiffness = 1/c, ordered ascending: a positive definite C gives
  // K1 = 1/c_max, K2 = 1/c_min; with c ≤ 0 the order of the reciprocals decides
  const Eigen::Vector2d c = eig.eigenvalues();
  const Eigen::Vector2d k(reciprocal(c[0]), reciprocal(c[1]));
  const int soft = k[0] <= k[1] ? 0 : 1;
  if (column == "theta1") return std::atan(eig.eigenvectors()(1, soft) / eig.eigenvectors()(0, soft));
  return column == "K1" ? k[soft] : k[1 - soft];
}

}  // namespace buckle::scene
