#include "hairlut/physics/bessel.hpp"

#include <boost/math/special_functions/bessel.hpp>
#include <cmath>
#include <numbers>

namespace hairlut {
namespace {

// Beyond this argument the asymptotic series below reaches full double precision in at most
// 13 terms; below it Boost's I0 is used (it is finite up to x ≈ 713).
constexpr double kAsymptoticFrom = 64.0;

// Σ_k a_k y^k with y = 1/x, a_0 = 1, a_k = a_{k−1} (2k − 1)² / (8k): the asymptotic expansion
// I0e(x) ~ Σ_k a_k x^{−k} / √(2πx) (Abramowitz & Stegun 9.7.1). For x ≥ 64 the terms fall below
// 2^−56 of the sum before they start to grow again.
double asymptotic_sum(double y) {
  double term = 1.0;
  double sum = 1.0;
  for (int k = 1; k < 40; ++k) {
    const double m = 2.0 * k - 1.0;
    term *= m * m * y / (8.0 * k);
    sum += term;
    if (term < 1e-17 * sum) break;
  }
  return sum;
}

}  // namespace

double bessel_i0e(double x) {
  x = std::abs(x);
  if (std::isinf(x)) return 0.0;
  if (x < kAsymptoticFrom) return std::exp(-x) * boost::math::cyl_bessel_i(0, x);
  return asymptotic_sum(1.0 / x) / std::sqrt(2.0 * std::numbers::pi * x);
}

double bessel_i0e_over_v(double c, double v) {
  // c/v < kAsymptoticFrom ⇔ c < kAsymptoticFrom·v; then 1/v ≤ 1/DBL_MIN is finite.
  if (c < kAsymptoticFrom * v) return bessel_i0e(c / v) / v;
  return asymptotic_sum(v / c) / (std::sqrt(2.0 * std::numbers::pi) * std::sqrt(c) * std::sqrt(v));
}

}  // namespace hairlut
