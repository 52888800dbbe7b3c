#include "hairlut/physics/gaussian_detector.hpp"

#include <cmath>
#include <numbers>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {

double gaussian_detector(double beta, double phi) {
  require_positive("beta", beta);
  if (!std::isfinite(phi)) throw_domain_error("phi", "must be finite", phi);
  const double x = std::abs(wrap_azimuth(phi));  // in [0, π]; |·| makes D exactly even
  constexpr double kCut = 45.0;                   // terms below e^{−45} ≈ 2.9e−20 of the largest
  if (beta < 2.5) {
    // Image k lies at distance |x − 2πk| ≥ 2π|k| − π; relative to the nearest image it is below
    // exp(−2π²K(K−1)/β²), so K(K−1) ≥ 45β²/(2π²) images per side suffice.
    const double need = kCut * beta * beta / (2.0 * std::numbers::pi * std::numbers::pi);
    const int K = 1 + static_cast<int>(std::ceil(0.5 * (-1.0 + std::sqrt(1.0 + 4.0 * need))));
    const double inv_two_var = 1.0 / (2.0 * beta * beta);
    double sum = 0.0;
    // Far images first so that the largest terms are added last.
    for (int k = K; k >= 1; --k) {
      const double a = x - kTwoPi * k;
      const double b = x + kTwoPi * k;
      sum += std::exp(-a * a * inv_two_var) + std::exp(-b * b * inv_two_var);
    }
    sum += std::exp(-x * x * inv_two_var);
    return sum / (std::sqrt(kTwoPi) * beta);
  }
  const int N = static_cast<int>(std::ceil(std::sqrt(2.0 * kCut) / beta));
  double sum = 0.0;
  for (int n = N; n >= 1; --n) sum += std::exp(-0.5 * n * n * beta * beta) * std::cos(n * x);
  return std::max(0.0, (1.0 + 2.0 * sum) / kTwoPi);
}

}  // namespace hairlut
