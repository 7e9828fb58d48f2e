// sogmm::shortest_decimal: the shortest `%g` text that reads back to the same
// double (map_options, reg_covar_gray). Independent truth: hand-checked
// strings for edge values, and the C library's own printf/strtod pair on
// seeded random bit patterns. No arithmetic on the values, so nothing here
// depends on the SIMD kernel.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "sogmm/shortest_decimal.hpp"

namespace {

std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// The same rule through printf("%.*g") and strtod, digit count by digit count.
std::string printf_shortest(double v) {
  char buf[40];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (bits(std::strtod(buf, nullptr)) == bits(v)) break;
  }
  return buf;
}

TEST(ShortestDecimal, EdgeValuesReadBackBitwiseInTheFewestDigits) {
  const struct {
    double v;
    const char* text;
  } cases[] = {
      {0.1, "0.1"},
      {0.7, "0.7"},  // map_options printed it 0.69999999999999996
      {0.1 + 0.2, "0.30000000000000004"},
      {1.0 / 3.0, "0.3333333333333333"},
      {DBL_MAX, "1.7976931348623157e+308"},
      {DBL_MIN, "2.2250738585072014e-308"},
      {std::numeric_limits<double>::denorm_min(), "5e-324"},
      {3 * std::numeric_limits<double>::denorm_min(), "1.5e-323"},
      {0.0, "0"},
      {-0.0, "-0"},
      {1e-6, "1e-06"},
      {12288.0, "12288"},
      {1e21, "1e+21"},
      {-2.5, "-2.5"},
  };
  for (const auto& c : cases) {
    const std::string s = sogmm::shortest_decimal(c.v);
    EXPECT_EQ(s, c.text);
    EXPECT_EQ(bits(std::strtod(s.c_str(), nullptr)), bits(c.v)) << s;
  }
  EXPECT_EQ(sogmm::shortest_decimal(std::numeric_limits<double>::infinity()), "inf");
}

TEST(ShortestDecimal, AgreesWithPrintfOnRandomDoubles) {
  std::mt19937_64 rng(31);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    std::uint64_t b = rng();
    double v;
    std::memcpy(&v, &b, sizeof v);
    if (!std::isfinite(v)) continue;
    const std::string s = sogmm::shortest_decimal(v);
    ASSERT_EQ(bits(std::strtod(s.c_str(), nullptr)), bits(v)) << s;
    ASSERT_EQ(s, printf_shortest(v));
    ++checked;
  }
  EXPECT_GT(checked, 19000);
  // Values a user types (three significant digits) print as typed.
  for (int k = 1; k < 1000; ++k) {
    const double v = std::strtod(("0." + std::to_string(1000 + k).substr(1)).c_str(), nullptr);
    char typed[16];
    std::snprintf(typed, sizeof typed, "%.3g", v);
    EXPECT_EQ(sogmm::shortest_decimal(v), typed);
  }
}

}  // namespace
