#include "hairlut/physics/longitudinal_mp.hpp"

#include <cfloat>
#include <cmath>
#include <numbers>

#include "hairlut/util/angles.hpp"
#include "hairlut/physics/bessel.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

void check_v(double v) {
  if (!(v >= DBL_MIN) || !std::isfinite(v)) throw_domain_error("v", "must be a finite number >= 2.2e-308 (v = beta^2 > 0)", v);
}

// M(v, θi, θr) for already validated arguments.
double deon_unchecked(double v, double theta_i, double theta_r) {
  const double s = std::sin(0.5 * (theta_i + theta_r));
  const double e = std::exp(-2.0 * s * s / v);  // exp((cos(θi+θr) − 1)/v), 0 when it underflows
  if (e == 0.0) return 0.0;
  const double c = std::max(0.0, std::cos(theta_i) * std::cos(theta_r));
  // v · (−expm1(−2/v)) → 2 as v → ∞; its series keeps full precision where 2/v would be tiny.
  if (v > 1e6) {
    const double y = 1.0 / v;
    const double denom = 2.0 - 2.0 * y + (4.0 / 3.0) * y * y - (2.0 / 3.0) * y * y * y;
    return e * bessel_i0e(c / v) / denom;
  }
  return e * bessel_i0e_over_v(c, v) / (-std::expm1(-2.0 / v));
}

}  // namespace

double fold_inclination(double theta) {
  if (theta > kHalfPi) return kPi - theta;
  if (theta < -kHalfPi) return -kPi - theta;
  return theta;
}

double longitudinal_deon(double v, double theta_i, double theta_r) {
  check_v(v);
  theta_i = checked_inclination("theta_i", theta_i);
  theta_r = checked_inclination("theta_r", theta_r);
  return deon_unchecked(v, theta_i, theta_r);
}

double longitudinal_deon_tilted(double v, double alpha, double theta_i, double theta_r) {
  check_v(v);
  alpha = checked_inclination("alpha", alpha);
  theta_i = checked_inclination("theta_i", theta_i);
  theta_r = checked_inclination("theta_r", theta_r);
  return deon_unchecked(v, theta_i, fold_inclination(theta_r - alpha));
}

double longitudinal_gaussian(double beta, double alpha, double theta_i, double theta_r, GaussianArgument argument) {
  if (!(beta >= 1e-12) || !std::isfinite(beta)) throw_domain_error("beta", "must be a finite number >= 1e-12 radians", beta);
  alpha = checked_inclination("alpha", alpha);
  theta_i = checked_inclination("theta_i", theta_i);
  theta_r = checked_inclination("theta_r", theta_r);
  const double theta_h = 0.5 * (theta_i + theta_r);
  const double cos_d = std::cos(0.5 * (theta_r - theta_i));
  double x = theta_h - alpha;
  if (argument == GaussianArgument::two_theta_h) x *= 2.0;
  const double g = std::exp(-x * x / (2.0 * beta * beta)) / (std::sqrt(2.0 * std::numbers::pi) * beta);
  return g / (cos_d * cos_d);
}

}  // namespace hairlut
