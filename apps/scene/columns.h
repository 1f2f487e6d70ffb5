// The column dictionary of branches.csv and the plots: each column's label with the scene's unit
// (scene/units.h), and the stiffness quantities derived from K_F and C_F (docs/outputs.md).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "scene/units.h"

namespace buckle::scene {

/// A value not computed or not defined: the CSV writers print "nan", JSON null.
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// How a label is written: gnuplot's enhanced text ("K_{xx}") or plain Unicode ("Kxx").
enum class LabelStyle { Gnuplot, Plain };
/// Axis label of a column with the scene's unit: "F_x (N)", "F_x (units of k b)",
/// "F_x (force, in the scene's units)"; the column's own name when it has none.
std::string columnLabel(const std::string& column, const UnitSystem& units, LabelStyle style = LabelStyle::Gnuplot);

/// The dimension of a column's values (None for counts and unknown names).
Dimension columnDimension(const std::string& column);

/// The stiffness columns of branches.csv with `stiffness` (docs/outputs.md): K_F, C_F, the
/// directional stiffnesses with the other direction free, the principal stiffnesses K1 ≤ K2 and
/// the direction θ1 of K1, and the end's rotational stiffness Kφ where φ is free.
const std::vector<std::string>& stiffnessColumns();
/// The natural-frequency columns of branches.csv with `frequencies` (vibration.h): omega1 …
/// omega<count>, the signed frequencies (negative: an unstable mode, minus its growth rate).
std::vector<std::string> frequencyColumns(int count);
/// Index (0-based) of a frequency column "omega<i>", −1 for any other column.
int frequencyIndex(const std::string& column);

/// One of those columns from K_F and C_F (either may be NaN: a rigid or a singular direction)
/// and K_φ (NaN: the rotation held, or not computed).
double stiffnessColumnValue(const std::string& column, const Eigen::Matrix2d& K, const Eigen::Matrix2d& C,
                            double rotationalStiffness = std::numeric_limits<double>::quiet_NaN());

}  // namespace buckle::scene
