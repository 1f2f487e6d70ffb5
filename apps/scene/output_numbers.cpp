#include "scene/output_numbers.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <system_error>

namespace buckle::scene {

namespace {

// Powers of ten that are exact doubles.
constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                             1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/// |v| rounded to `digits` significant digits as the integer m < 10^digits and the decimal
/// exponent x of its first digit (|v| ≈ m·10^(x − digits + 1)), when that can be told from one
/// scaling: s = |v|·10^k (or |v|/10^-k) is rounded once, so its error is below one ulp of s, and
/// m = round(s) is the rounding of the exact value whenever s is farther than that from a
/// half-integer (and from the ends of the digits' range). False otherwise (near a tie of the
/// decimal rounding, or 10^|k| not exact): the caller formats v itself.
bool scaledDigits(double a, int digits, std::uint64_t& m, int& x) {
  if (!(a > 0.0) || digits > 15) return false;
  // The decade from the binary exponent: a = f·2^e, f in [0.5, 1), so log10(a) lies in
  // [(e − 1)·log10(2), e·log10(2)): x is floor of the lower end or one more, and the loop below
  // moves it up when it is one short (std::log10 was a tenth of a long chain's writing).
  // frexp's exponent read from the bits (a library call per number otherwise); subnormals
  // through frexp itself
  std::uint64_t bits = 0;
  std::memcpy(&bits, &a, sizeof bits);
  int e = int((bits >> 52) & 0x7ff) - 1022;
  if (e == -1022) std::frexp(a, &e);
  x = int(std::floor((e - 1) * 0.30102999566398120));
  for (int attempt = 0; attempt < 3; ++attempt) {
    const int k = digits - 1 - x;
    if (k < -22 || k > 22) return false;
    const double s = k >= 0 ? a * kPow10[k] : a / kPow10[-k];
    const double lo = kPow10[digits - 1], hi = kPow10[digits];
    const double margin = 4.0 * s * 0x1p-52;  // several ulp of s: more than the scaling's error
    if (s < lo - margin) {  // log10 rounded up across a power of ten
      --x;
      continue;
    }
    if (s >= hi + margin) {
      ++x;
      continue;
    }
    if (s < lo + margin || s > hi - margin) return false;  // at a power of ten: undecided
    const double f = std::floor(s);
    const double frac = s - f;  // exact (Sterbenz)
    if (std::abs(frac - 0.5) <= margin) return false;  // a tie of the decimal rounding
    double r = frac > 0.5 ? f + 1.0 : f;
    if (r >= hi) {  // 99…9.6 rounded up: 10…0, one decade higher
      r = lo;
      ++x;
    }
    m = std::uint64_t(r);
    return true;
  }
  return false;
}

/// printf's "%.*g" text of ±m·10^(x − digits + 1), m < 10^digits: fixed notation when
/// -4 <= x < precision, else d.ddde±XX; trailing zeros dropped. Written into a local buffer and
/// appended once.
void appendG(std::string& out, bool negative, std::uint64_t m, int x, int precision) {
  char d[24];
  const std::to_chars_result r = std::to_chars(d, d + sizeof d, m);
  int count = int(r.ptr - d);
  while (count > 1 && d[count - 1] == '0') --count;
  char buf[48];
  char* p = buf;
  if (negative) *p++ = '-';
  if (x < -4 || x >= precision) {
    *p++ = d[0];
    if (count > 1) {
      *p++ = '.';
      for (int i = 1; i < count; ++i) *p++ = d[i];
    }
    *p++ = 'e';
    *p++ = x < 0 ? '-' : '+';
    const int e = std::abs(x);
    if (e < 10) *p++ = '0';
    p = std::to_chars(p, buf + sizeof buf, e).ptr;
  } else if (x >= 0) {
    for (int i = 0; i <= x; ++i) *p++ = i < count ? d[i] : '0';
    if (count > x + 1) {
      *p++ = '.';
      for (int i = x + 1; i < count; ++i) *p++ = d[i];
    }
  } else {
    *p++ = '0';
    *p++ = '.';
    for (int i = 0; i < -x - 1; ++i) *p++ = '0';
    for (int i = 0; i < count; ++i) *p++ = d[i];
  }
  out.append(buf, size_t(p - buf));
}

/// JSON's text of the double nearest ±m·10^(x − digits + 1) (m < 10^digits), as
/// nlohmann::json's dump() writes it (dtoa's format_buffer with min_exp −4, max_exp 15): the
/// shortest digits that read back to that double are m's without trailing zeros (two decimals
/// of at most 15 digits never round to the same double), fixed notation for decimal exponents
/// −4 < n ≤ 15 (an integer gets ".0"), d.ddde±XX otherwise.
void appendJsonDigits(std::string& out, bool negative, std::uint64_t m, int x) {
  char d[24];
  int k = int(std::to_chars(d, d + sizeof d, m).ptr - d);
  while (k > 1 && d[k - 1] == '0') --k;
  const int n = x + 1;  // the value is 0.d₁d₂… · 10^n
  char buf[48];
  char* p = buf;
  if (negative) *p++ = '-';
  if (k <= n && n <= 15) {
    p = std::copy(d, d + k, p);
    p = std::fill_n(p, n - k, '0');
    *p++ = '.';
    *p++ = '0';
  } else if (0 < n && n <= 15) {
    p = std::copy(d, d + n, p);
    *p++ = '.';
    p = std::copy(d + n, d + k, p);
  } else if (-4 < n && n <= 0) {
    *p++ = '0';
    *p++ = '.';
    p = std::fill_n(p, -n, '0');
    p = std::copy(d, d + k, p);
  } else {
    *p++ = d[0];
    if (k > 1) {
      *p++ = '.';
      p = std::copy(d + 1, d + k, p);
    }
    *p++ = 'e';
    const int e = n - 1;
    *p++ = e < 0 ? '-' : '+';
    const int a = std::abs(e);
    if (a < 10) *p++ = '0';
    p = std::to_chars(p, buf + sizeof buf, a).ptr;
  }
  out.append(buf, size_t(p - buf));
}

}  // namespace

void appendRoundedJson(std::string& out, double v, int digits) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  std::uint64_t m = 0;
  int x = 0;
  if (v != 0.0 && digits <= 15 && scaledDigits(std::abs(v), digits, m, x) && x - digits + 1 >= -22 &&
      x - digits + 1 <= 22) {
    appendJsonDigits(out, std::signbit(v), m, x);
    return;
  }
  const double r = roundedSignificant(v, digits);
  if (!std::isfinite(r)) {
    out += "null";
    return;
  }
  char buf[64];
  out.append(buf, size_t(nlohmann::detail::to_chars(buf, buf + sizeof buf, r) - buf));
}

void appendGeneral(std::string& out, double v, int precision) {
  if (!std::isfinite(v)) {
    out += "nan";
    return;
  }
  std::uint64_t m = 0;
  int x = 0;
  if (v != 0.0 && scaledDigits(std::abs(v), precision, m, x)) {
    appendG(out, std::signbit(v), m, x, precision);
    return;
  }
  char buf[40];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, precision);
  out.append(buf, r.ptr);
}

double roundedSignificant(double v, int digits) {
  if (v == 0.0) return v;  // ±0 prints as ±0
  std::uint64_t m = 0;
  int x = 0;
  if (scaledDigits(std::abs(v), digits, m, x)) {
    // m·10^p with m < 2^53 and 10^|p| exact: one correctly rounded operation, the double
    // nearest to the decimal, as strtod reads it
    const int p = x - digits + 1;
    if (p >= -22 && p <= 22) {
      const double r = p >= 0 ? double(m) * kPow10[p] : double(m) / kPow10[-p];
      return std::signbit(v) ? -r : r;
    }
  }
  char buf[40];
  const std::to_chars_result printed = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, digits);
  double r = v;
  // out of range (|v| rounded up past the largest double): strtod's ±HUGE_VAL
  if (std::from_chars(buf, printed.ptr, r).ec != std::errc()) r = std::strtod(std::string(buf, printed.ptr).c_str(), nullptr);
  return r;
}

void appendCsvNumber(std::string& out, double v) {
  if (std::isinf(v)) {
    out += v > 0.0 ? "inf" : "-inf";
    return;
  }
  appendGeneral(out, v, 12);
}

std::string secondsText(double seconds) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", seconds);
  return buf;
}

}  // namespace buckle::scene
