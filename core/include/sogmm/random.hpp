// A small, portable, seedable random number generator.
//
// std::mt19937 is portable but the std distributions are not (their output is
// implementation-defined), so results would differ between standard
// libraries. Everything random in SOGMM goes through this header instead.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "sogmm/normal_quantile.hpp"

namespace sogmm {

/// xoshiro256** seeded through splitmix64: fast, 256-bit state, and the same
/// sequence on every platform for the same seed.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) {
    for (auto& s : state_) s = splitmix64(seed);
  }
  /// Next 64 random bits.
  std::uint64_t next() {
    const std::uint64_t result = rotl(state_[1] * 5, 7) * 9;
    const std::uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = rotl(state_[3], 45);
    return result;
  }
  /// Uniform double in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Standard normal (Box-Muller on two uniforms; one value per call).
  double normal() {
    double u1;
    do u1 = uniform(); while (u1 <= 0.0);
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586476925 * u2);
  }
 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix64(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::uint64_t state_[4];
};

/// The standard normal truncated to (-bound, bound), drawn exactly by
/// inverting its CDF: one Rng::next() per value, whatever the bound. (Redrawing
/// until |z| < bound would cost 1 / P(|Z| < bound) draws: 1.3e8 per value at
/// bound 1e-8.) bound > 0; +infinity is allowed and gives the plain normal.
class TruncatedNormal {
 public:
  explicit TruncatedNormal(double bound)
      : below_bound_(std::nextafter(bound, 0.0)),
        half_mass_(0.5 * std::erf(bound * 0.70710678118654752440)),
        tail_(0.5 * std::erfc(bound * 0.70710678118654752440)) {}

  /// One value. The top 53 bits of a draw give u in [0, 1), its lowest bit
  /// the sign; |z| is the quantile with P(0 <= Z < |z|) = u P(0 <= Z < bound).
  double operator()(Rng& rng) const {
    const std::uint64_t bits = rng.next();
    const double u = static_cast<double>(bits >> 11) * 0x1.0p-53;
    const double c = u * half_mass_;
    // Far from the median, the quantile is read from the upper-tail
    // probability 1/2 - c, formed without cancellation (1 - u is exact).
    double z = c <= kNormalCentralLimit ? normal_quantile_central(c)
                                        : normal_quantile_upper_tail(0.5 * (1.0 - u) + u * tail_);
    z = std::min(z, below_bound_);  // rounding never leaves the interval
    return (bits & 1) ? -z : z;
  }

 private:
  double below_bound_;  // largest double below bound
  double half_mass_;    // P(0 <= Z < bound)
  double tail_;         // P(Z >= bound)
};

}  // namespace sogmm
