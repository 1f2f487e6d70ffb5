// Numbers as the output files print them, to the byte and fast: branches.csv's printf "%.12g"
// and report.html's values rounded to a few significant digits. A long chain's outputs hold
// millions of numbers, and printf-style conversion with a precision (snprintf, std::to_chars with
// a precision) costs several hundred instructions each; here the decimal digits come from one
// scaling by an exact power of ten and a rounding to an integer, checked to be the rounding of
// the exact value, with std::to_chars as the fallback where the check cannot tell
// (output_numbers.cpp).
#pragma once

#include <string>

namespace buckle::scene {

/// Appends v as printf's "%.*g" with `precision` significant digits (1 <= precision <= 17), the
/// same characters; "nan" when v is not finite (branches.csv's convention).
void appendGeneral(std::string& out, double v, int precision);

/// Appends v as branches.csv and the other CSV files write it: "%.12g", "nan" for NaN and
/// "inf" / "-inf" for infinities (a rigid direction's stiffness).
void appendCsvNumber(std::string& out, double v);

/// The double nearest to printf's "%.*g" of a finite v (1 <= digits <= 17): v rounded to
/// `digits` significant decimal digits, bit for bit what snprintf + strtod give.
double roundedSignificant(double v, int digits);

/// Appends roundedSignificant(v, digits) as nlohmann::json's dump() writes that double (its
/// shortest round-trip digits; "null" when v or the rounding is not finite), without the
/// shortest-digits search: the rounding's own digits are those (1 <= digits <= 17).
void appendRoundedJson(std::string& out, double v, int digits);

/// A duration as the run's last line and report.html print it: printf's "%.3g" seconds, one text
/// for the one number (summary.json's timings_seconds.total), so the two read the same.
std::string secondsText(double seconds);

}  // namespace buckle::scene
