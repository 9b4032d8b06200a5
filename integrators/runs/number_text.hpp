// Numbers as text for the tables and CSV files written by compare and study (one definition, so both
// print the same digits): num() 6 significant digits, sci() 3 in exponent form, full() round-trip
// precision (17 digits, what the CSV files hold). NaN prints as "nan", or "n/a" in sci() (tables).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace shelldyn::number_text {

inline std::string format(const char* fmt, double x, const char* nan_text) {
  if (std::isnan(x)) return nan_text;
  char b[40];
  std::snprintf(b, sizeof b, fmt, x);
  return b;
}
inline std::string num(double x) { return format("%.6g", x, "nan"); }
inline std::string sci(double x) { return format("%.2e", x, "n/a"); }
inline std::string full(double x) { return format("%.17g", x, "nan"); }

}  // namespace shelldyn::number_text
