// The shortest decimal text of a double that reads back to it, for numbers
// written into files for people and read back by strtod (map_options,
// reg_covar_gray; spec/format.md 2.3 and 2.4).
#pragma once

#include <charconv>
#include <cstring>
#include <string>

namespace sogmm {

/// Formats a double as the shortest `%g` form that reads back to the same
/// value: `%.1g`, `%.2g`, ... up to `%.17g`, the first whose text parses to
/// the same bits (0.7 is "0.7", not 0.69999999999999996; -0.0 is "-0").
/// 17 digits are needed only for doubles that no shorter decimal identifies.
/// Locale-independent (std::to_chars); NaN and infinities print as "nan" and
/// "inf", the 17-digit form.
inline std::string shortest_decimal(double v) {
  char buf[40];
  char* end = buf;
  for (int digits = 1; digits <= 17; ++digits) {
    end = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, digits).ptr;
    double back = 0.0;
    std::from_chars(buf, end, back);
    if (std::memcmp(&back, &v, sizeof v) == 0) break;
  }
  return std::string(buf, end);
}

}  // namespace sogmm
