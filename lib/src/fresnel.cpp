#include "hairlut/fresnel.hpp"

#include <algorithm>

#include "hairlut/angles.hpp"
#include "hairlut/error.hpp"

namespace hairlut {
namespace {

void check_fresnel_args(double eta, double cos_theta_i) {
  require_positive("eta", eta);
  require_in_range("cos_theta_i", cos_theta_i, 0.0, 1.0, "must lie in [0, 1]");
}

// cos θt from Snell's law, or a negative value for total internal reflection.
double cos_transmitted(double eta, double cos_i) {
  const double sin2_t = (1.0 - cos_i) * (1.0 + cos_i) / (eta * eta);
  return sin2_t >= 1.0 ? -1.0 : std::sqrt(1.0 - sin2_t);
}

}  // namespace

double fresnel_reflectance(double eta, double cos_theta_i) {
  check_fresnel_args(eta, cos_theta_i);
  const double ci = cos_theta_i;
  const double ct = cos_transmitted(eta, ci);
  if (ct < 0.0) return 1.0;
  const double rs = (ci - eta * ct) / (ci + eta * ct);
  const double rp = (eta * ci - ct) / (eta * ci + ct);
  return std::min(1.0, 0.5 * (rs * rs + rp * rp));
}

double fresnel_transmittance(double eta, double cos_theta_i) {
  check_fresnel_args(eta, cos_theta_i);
  const double ci = cos_theta_i;
  const double ct = cos_transmitted(eta, ci);
  if (ct < 0.0) return 0.0;
  const double num = 4.0 * eta * ci * ct;
  const double ds = ci + eta * ct;
  const double dp = eta * ci + ct;
  return std::min(1.0, 0.5 * (num / (ds * ds) + num / (dp * dp)));
}

double bravais_eta_prime(double eta, double theta_d) {
  require_greater("eta", eta, 1.0, "must be a finite number > 1");
  theta_d = checked_inclination("theta_d", theta_d);
  const double c = std::cos(theta_d);
  return std::sqrt(eta_squared_minus_sin2(eta, c)) / c;
}

double inverse_bravais_eta_prime(double eta, double theta_d) {
  require_greater("eta", eta, 1.0, "must be a finite number > 1");
  theta_d = checked_inclination("theta_d", theta_d);
  const double c = std::cos(theta_d);
  return c / std::sqrt(eta_squared_minus_sin2(eta, c));
}

double bravais_eta_double_prime(double eta, double theta_d) {
  require_greater("eta", eta, 1.0, "must be a finite number > 1");
  theta_d = checked_inclination("theta_d", theta_d);
  const double c = std::cos(theta_d);
  return eta * eta * c / std::sqrt(eta_squared_minus_sin2(eta, c));
}

}  // namespace hairlut
