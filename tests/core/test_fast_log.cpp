// fast_log_ge1 (core/src/fast_log.hpp) against libm's log: exactly 0 at 1,
// within its documented 1e-15 relative elsewhere, over arguments near 1
// (where log x ~ x - 1: the series' small-s end), across the sqrt(2)
// mantissa switch, and seeded ones up to 1e300 (large exponents: the e ln 2
// split). Bounds: the series' truncation is below 3e-17, the division and
// the Horner steps a few 2^-53 each. Mutation tried: the ln2_lo term dropped
// (fails: e ln2_lo is 2.8e-10 of e ln 2).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "fast_log.hpp"
#include "test_util.hpp"

namespace {

TEST(FastLog, MatchesLibmWithinItsBound) {
  using sogmm::detail::fast_log_ge1;
  EXPECT_EQ(fast_log_ge1(1.0), 0.0);
  std::vector<double> xs;
  for (int i = 1; i <= 2000; ++i) xs.push_back(1.0 + 1e-12 * i * i * i);  // 1 + 1e-12 ... 1 + 8
  for (double m : {std::sqrt(2.0), std::nextafter(std::sqrt(2.0), 0.0), std::nextafter(std::sqrt(2.0), 2.0)})
    for (int e = 0; e < 60; ++e) xs.push_back(std::ldexp(m, e));
  sogmm_test::TestRng rng(3);
  for (int i = 0; i < 20000; ++i) xs.push_back(std::pow(10.0, 300.0 * rng.uniform()));
  for (double x : xs) {
    const double want = std::log(x);
    ASSERT_LE(std::abs(fast_log_ge1(x) - want), 1e-15 * want) << "x = " << x;
  }
}

}  // namespace
