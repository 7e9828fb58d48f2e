// Quantiles of the standard normal distribution (the inverse of its CDF Phi),
// by Wichura's algorithm AS 241 (PPND16: Applied Statistics 37(3), 477-484,
// 1988), accurate to about 1e-16 relative. Portable: plain arithmetic plus
// std::log and std::sqrt, so the same inputs give the same values everywhere.
//
// The argument is split in two functions so that no precision is lost in
// 1/2 + c or 1 - p: the central one takes the offset from the median, the tail
// one the upper-tail probability itself.
#pragma once

#include <cmath>

namespace sogmm {

namespace detail {
// a[0] + a[1] x + ... + a[7] x^7 (Horner).
inline double polynomial7(const double (&a)[8], double x) {
  double v = a[7];
  for (int i = 6; i >= 0; --i) v = v * x + a[i];
  return v;
}
}  // namespace detail

/// Largest |c| that normal_quantile_central accepts.
inline constexpr double kNormalCentralLimit = 0.425;

/// Phi^-1(1/2 + c) for |c| <= 0.425 (probabilities 0.075 to 0.925); exact to
/// the last few bits however small c is (for tiny c it is c sqrt(2 pi)).
inline double normal_quantile_central(double c) {
  static constexpr double a[8] = {3.3871328727963666080e0, 1.3314166789178437745e+2, 1.9715909503065514427e+3,
                                  1.3731693765509461125e+4, 4.5921953931549871457e+4, 6.7265770927008700853e+4,
                                  3.3430575583588128105e+4, 2.5090809287301226727e+3};
  static constexpr double b[8] = {1.0,
                                  4.2313330701600911252e+1, 6.8718700749205790830e+2, 5.3941960214247511077e+3,
                                  2.1213794301586595867e+4, 3.9307895800092710610e+4, 2.8729085735721942674e+4,
                                  5.2264952788528545610e+3};
  const double r = 0.180625 - c * c;
  return c * detail::polynomial7(a, r) / detail::polynomial7(b, r);
}

/// The z > 0 with P(Z > z) = t, for 0 < t <= 0.075 (the upper tail; the
/// lower tail is its mirror image); accurate for t down to about 1e-300.
inline double normal_quantile_upper_tail(double t) {
  static constexpr double c[8] = {1.42343711074968357734e0,  4.63033784615654529590e0,  5.76949722146069140550e0,
                                  3.64784832476320460504e0,  1.27045825245236838258e0,  2.41780725177450611770e-1,
                                  2.27238449892691845833e-2, 7.74545014278341407640e-4};
  static constexpr double d[8] = {1.0,
                                  2.05319162663775882187e0,  1.67638483018380384940e0,  6.89767334985100004550e-1,
                                  1.48103976427480074590e-1, 1.51986665636164571966e-2, 5.47593808499534494600e-4,
                                  1.05075007164441684324e-9};
  static constexpr double e[8] = {6.65790464350110377720e0,  5.46378491116411436990e0,  1.78482653991729133580e0,
                                  2.96560571828504891230e-1, 2.65321895265761230930e-2, 1.24266094738807843860e-3,
                                  2.71155556874348757815e-5, 2.01033439929228813265e-7};
  static constexpr double f[8] = {1.0,
                                  5.99832206555887937690e-1, 1.36929880922735805310e-1, 1.48753612908506148525e-2,
                                  7.86869131145613259100e-4, 1.84631831751005468180e-5, 1.42151175831644588870e-7,
                                  2.04426310338993978564e-15};
  const double r = std::sqrt(-std::log(t));
  if (r <= 5.0) return detail::polynomial7(c, r - 1.6) / detail::polynomial7(d, r - 1.6);
  return detail::polynomial7(e, r - 5.0) / detail::polynomial7(f, r - 5.0);
}

}  // namespace sogmm
